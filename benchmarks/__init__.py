"""Reproductions of each paper's comparison and speed comparisons against peers.

``python -m benchmarks [NAME ...] [--quick]`` runs them, stores
``benchmarks/results/<name>.json`` and rewrites ``docs/results.md``.
"""
