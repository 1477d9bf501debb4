"""Shared machinery of the population optimisers: bounds, counted objective, stop rules,
and the one result type.

Stopping and counting follow spec 002 §3.9 so that CS, ACS, PSO, AFSA and IAFSA are
compared fairly: ``nit`` counts generations (one complete population update; for
CS/ACS a Lévy phase plus an abandonment phase), ``nfev`` counts objective
evaluations actually computed (memoised repeats are not counted). A run converges at
the first generation whose best value satisfies ``J_best <= J* + tol_abs +
tol_rel*|J*|`` (:class:`Target`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from inertialab.errors import InputError


@dataclass(frozen=True)
class Target:
    """Convergence target of spec 002 §3.9: ``J* + tol_abs + tol_rel*|J*|``.

    Defaults ``tol_abs = 1e-10`` and ``tol_rel = 1e-6`` are spec 002 §3.9's.

    Examples
    --------
    >>> t = Target(2.0)
    >>> t.threshold == 2.0 + 1e-10 + 1e-6 * 2.0
    True
    >>> t.reached(2.000001), t.reached(2.00001)
    (True, False)
    """

    value: float
    tol_abs: float = 1e-10
    tol_rel: float = 1e-6

    @property
    def threshold(self) -> float:
        return self.value + self.tol_abs + self.tol_rel * abs(self.value)

    def reached(self, fbest: float) -> bool:
        return bool(fbest <= self.threshold)


@dataclass(frozen=True)
class OptimResult:
    """Result of every inertialab optimiser (SciPy-style).

    Attributes
    ----------
    x : ndarray (d,)
        Best position found.
    fun : float
        Objective value at ``x``.
    nit : int
        Generations run (spec 002 §3.9 counting).
    nfev : int
        Objective evaluations actually computed.
    success : bool
        True when ``target`` was reached (or, without a target, when the run ended by
        its own convergence rule rather than by exhausting ``max_generations``).
    message : str
        Why the run stopped.
    history : ndarray (nit + 1,)
        Best objective value after each generation (index 0 = initial population).
    converged_at : int or None
        First generation whose best value reached the target (None when not reached
        or no target).
    extra : dict
        Method-specific diagnostics (e.g. adaptive step sizes).

    Examples
    --------
    Particle swarm on a sphere centred at (0.3, 0.3), asked to get within 1e-8 of its
    minimum 0:

    >>> import numpy as np
    >>> from inertialab.optim.pso import pso
    >>> res = pso(lambda x: float(np.sum((x - 0.3) ** 2)), [(-1.0, 1.0)] * 2, rng=0,
    ...           target=Target(0.0, tol_abs=1e-8))
    >>> res.success, res.converged_at == res.nit, bool(res.fun <= 1e-8)
    (True, True, True)
    >>> bool(np.allclose(res.x, 0.3, atol=1e-3)), bool(np.all(np.diff(res.history) <= 0))
    (True, True)
    """

    x: np.ndarray
    fun: float
    nit: int
    nfev: int
    success: bool
    message: str
    history: np.ndarray
    converged_at: int | None = None
    extra: dict = field(default_factory=dict)


def as_bounds(bounds) -> tuple[np.ndarray, np.ndarray]:
    """Normalise ``bounds`` given as ``[(lo, hi), ...]`` or ``(lo_array, hi_array)``.

    Returns ``(lo, hi)`` float arrays of shape (d,). Raises InputError for lo >= hi or
    non-finite values.
    """
    b = np.asarray(bounds, dtype=float)
    if b.ndim == 2 and b.shape[1] == 2 and not (b.shape[0] == 2 and b.shape[1] != 2):
        lo, hi = b[:, 0], b[:, 1]
    elif b.ndim == 2 and b.shape[0] == 2:
        lo, hi = b[0], b[1]
    else:
        raise InputError(f"bounds must be [(lo, hi), ...] or (lo, hi) arrays, got shape {b.shape}")
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise InputError("bounds must be finite")
    if np.any(lo >= hi):
        bad = int(np.argmax(lo >= hi))
        raise InputError(f"bounds: lower >= upper for parameter {bad}")
    return lo.copy(), hi.copy()


class CountedObjective:
    """Wraps ``fun`` to count evaluations, optionally memoising exact repeats.

    ``memoize`` (int or None): keep up to that many recent results keyed by the bytes
    of ``x``; a hit is not counted in ``nfev`` (spec 002 §3.9: evaluations actually
    computed). ``fun`` takes a 1-D array and returns a float; :meth:`many` evaluates
    rows of a 2-D array.
    """

    def __init__(self, fun: Callable[[np.ndarray], float], memoize: int | None = None):
        self.fun = fun
        self.memoize = memoize
        self.nfev = 0
        self._cache: dict[bytes, float] = {}

    def __call__(self, x: np.ndarray) -> float:
        x = np.ascontiguousarray(x, dtype=float)
        if self.memoize:
            key = x.tobytes()
            if key in self._cache:
                return self._cache[key]
        val = float(self.fun(x))
        if not np.isfinite(val):
            val = np.inf
        self.nfev += 1
        if self.memoize:
            if len(self._cache) >= self.memoize:
                self._cache.pop(next(iter(self._cache)))
            self._cache[key] = val
        return val

    def many(self, X: np.ndarray) -> np.ndarray:
        return np.array([self(x) for x in np.atleast_2d(X)])


def initial_population(lo, hi, pop_size: int, rng: np.random.Generator, x_init=None) -> np.ndarray:
    """Uniform population in the box, or ``x_init`` (validated) when given.

    ``x_init`` of shape (pop_size, d) lets CS, ACS and PSO start from one shared
    population (spec 002 §3.2); one row (d,) is used as the first member, the rest
    drawn uniformly.
    """
    d = lo.size
    if pop_size < 2:
        raise InputError(f"pop_size must be >= 2, got {pop_size}")
    pop = lo + (hi - lo) * rng.random((pop_size, d))
    if x_init is not None:
        xi = np.asarray(x_init, dtype=float)
        if xi.ndim == 1:
            if xi.size != d:
                raise InputError(f"x_init has {xi.size} values, bounds have {d}")
            pop[0] = np.clip(xi, lo, hi)
        elif xi.shape == (pop_size, d):
            pop = np.clip(xi, lo, hi).copy()
        else:
            raise InputError(f"x_init must have shape ({d},) or ({pop_size}, {d}), got {xi.shape}")
    return pop


class StopRule:
    """Generation-level stopping: target reached, stall, or generation budget.

    ``stall`` = number of generations without improvement of the best value larger
    than ``stall_tol`` (relative) after which the run stops (None = never).
    """

    def __init__(self, max_generations: int, target: float | Target | None = None,
                 stall: int | None = None, stall_tol: float = 1e-12):
        if max_generations < 1:
            raise InputError(f"max_generations must be >= 1, got {max_generations}")
        self.max_generations = int(max_generations)
        if target is not None and not isinstance(target, Target):
            target = Target(float(target))
        self.target = target
        self.stall = stall
        self.stall_tol = stall_tol
        self.history: list[float] = []
        self.converged_at: int | None = None
        self._since_improve = 0

    def record(self, generation: int, fbest: float) -> str | None:
        """Record the best value after ``generation``; return a stop message or None."""
        if self.history and fbest < self.history[-1] - self.stall_tol * max(1.0, abs(self.history[-1])):
            self._since_improve = 0
        elif self.history:
            self._since_improve += 1
        self.history.append(float(fbest))
        if self.target is not None and self.converged_at is None and self.target.reached(fbest):
            self.converged_at = generation
            return f"target reached at generation {generation}"
        if self.stall is not None and self._since_improve >= self.stall:
            return f"no improvement for {self.stall} generations"
        if generation >= self.max_generations:
            return "maximum number of generations reached"
        return None

    def result(self, x, fun, nit, nfev, message, extra=None) -> OptimResult:
        if self.target is not None:
            success = self.converged_at is not None
        else:
            success = not message.startswith("maximum")
        return OptimResult(
            x=np.asarray(x, dtype=float).copy(), fun=float(fun), nit=int(nit), nfev=int(nfev),
            success=bool(success), message=message, history=np.asarray(self.history),
            converged_at=self.converged_at, extra=dict(extra or {}),
        )


class Evaluator:
    """Population evaluator shared by every swarm optimiser: counts evaluations (``count``);
    ``vectorized`` objectives take (P, d) and return (P,); non-finite values become inf."""

    def __init__(self, fun, vectorized: bool, memoize):
        self.vectorized = vectorized
        if vectorized:
            self.fun = fun
            self.nfev = 0
        else:
            self.counted = CountedObjective(fun, memoize=memoize)

    def __call__(self, X: np.ndarray) -> np.ndarray:
        if self.vectorized:
            f = np.asarray(self.fun(X), dtype=float).reshape(-1)
            if f.size != X.shape[0]:
                raise InputError(f"vectorized objective returned {f.size} values for {X.shape[0]} rows")
            self.nfev += X.shape[0]
            return np.where(np.isfinite(f), f, np.inf)
        return self.counted.many(X)

    @property
    def count(self) -> int:
        return self.nfev if self.vectorized else self.counted.nfev
