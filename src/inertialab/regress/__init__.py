"""inertialab.regress: linear and nonlinear regression methods.

Rank-aware least squares, ridge (HKB, GCV), empirical Bayes ridge, nonlinear least
squares and design of experiments. Method modules only: no file I/O, no printing.

The public face, imported on first use::

    EmpiricalBayesRidge (ebr)  levenberg_marquardt (nlls)  d_optimal_design (design)

(``lstsq`` and ``ridge`` are both a module and its function: import them from their
modules, ``from inertialab.regress.ridge import ridge``.)
"""

__all__ = ["EmpiricalBayesRidge", "d_optimal_design", "levenberg_marquardt"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name == "EmpiricalBayesRidge":
        from inertialab.regress import ebr as mod
    elif name == "levenberg_marquardt":
        from inertialab.regress import nlls as mod
    elif name == "d_optimal_design":
        from inertialab.regress import design as mod
    else:
        raise AttributeError(f"module 'inertialab.regress' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
