"""inertialab.regress: linear and nonlinear regression methods.

Rank-aware least squares, ridge (HKB, GCV), empirical Bayes ridge, nonlinear least
squares and design of experiments. Method modules only: no file I/O, no printing.
"""
