"""Population optimisers on one shared signature and result type.

Every optimiser is a function::

    f(fun, bounds, *, pop_size, max_generations, rng, x_init=None, target=None,
      stall=None, memoize=None, callback=None) -> OptimResult

namely cuckoo search and adaptive cuckoo search (spec 002), PSO (spec 002 baseline), the artificial fish swarm and its improved form (spec 000).
The shared pieces live in :mod:`inertialab.optim.base`.
"""

from inertialab.optim.base import OptimResult, Target

__all__ = ["OptimResult", "Target"]
