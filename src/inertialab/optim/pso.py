"""Standard inertia-weight particle swarm optimisation (the PSO baseline of spec 002 §3.5).

``v <- w v + c1 r1 (p_i - x) + c2 r2 (g_best - x)`` with r1, r2 ~ U(0, 1) per
component, the inertia w falling linearly from 0.9 to 0.4 over ``max_generations``
(Shi & Eberhart 1998), velocities clipped to ±0.2 (ub - lb), positions clipped to
the box, and greedy personal/global bests. One generation = N evaluations.

Written on numpy rather than taken from a library (pyswarms and friends) because the
comparison needs the shared initial population, counting and result type of
:mod:`inertialab.optim.base`.

Random stream: the initial population (the same first draw as CS/ACS), then per
generation r1, r2.

References
----------
Shi & Eberhart, "A modified particle swarm optimizer", IEEE ICEC 1998. Spec 002 §3.5.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from inertialab.errors import InputError
from inertialab.optim.base import (
    Evaluator,
    OptimResult,
    StopRule,
    as_bounds,
    initial_population,
)
from inertialab.seeding import as_generator

__all__ = ["pso"]


def pso(fun: Callable, bounds, *, pop_size: int = 25, max_generations: int = 1000, rng=None,
        x_init=None, target=None, stall=None, memoize=None, callback=None,
        vectorized: bool = False, w=(0.9, 0.4), c1: float = 2.0, c2: float = 2.0,
        vmax_frac: float = 0.2) -> OptimResult:
    """Particle swarm optimisation on the shared optimiser signature.

    Parameters
    ----------
    fun, bounds, pop_size, max_generations, rng, x_init, target, stall, memoize,
    callback, vectorized :
        As in :func:`inertialab.optim.cuckoo.cuckoo_search` (N = 25, T_max = 1000).
    w : float or (w_start, w_end), default (0.9, 0.4)
        Inertia weight: constant, or linear from ``w_start`` at generation 1 to
        ``w_end`` at ``max_generations`` (spec 002 §3.5).
    c1, c2 : float, default 2.0
        Cognitive and social coefficients.
    vmax_frac : float, default 0.2
        Velocity clip as a fraction of the box width.
    """
    lo, hi = as_bounds(bounds)
    gen = as_generator(rng)
    N, d = int(pop_size), lo.size
    if np.ndim(w) == 0:
        w0 = w1 = float(w)
    else:
        if len(w) != 2:
            raise InputError("w must be a number or a pair (w_start, w_end)")
        w0, w1 = float(w[0]), float(w[1])
    x = initial_population(lo, hi, N, gen, x_init)
    v = np.zeros_like(x)
    vmax = vmax_frac * (hi - lo)
    ev = Evaluator(fun, vectorized, memoize)
    f = ev(x)
    pbest, pf = x.copy(), f.copy()
    ib = int(np.argmin(pf))
    stop = StopRule(max_generations, target=target, stall=stall)
    message = stop.record(0, float(pf[ib]))
    T = max(int(max_generations) - 1, 1)
    t = 0
    while message is None:
        t += 1
        wt = w0 + (w1 - w0) * (t - 1) / T
        r1 = gen.random((N, d))
        r2 = gen.random((N, d))
        v = wt * v + c1 * r1 * (pbest - x) + c2 * r2 * (pbest[ib] - x)
        v = np.clip(v, -vmax, vmax)
        x = np.clip(x + v, lo, hi)
        f = ev(x)
        better = f < pf
        pbest[better] = x[better]
        pf[better] = f[better]
        ib = int(np.argmin(pf))
        message = stop.record(t, float(pf[ib]))
        if callback is not None and callback(t, pbest[ib].copy(), float(pf[ib])):
            message = message or f"stopped by callback at generation {t}"
    return stop.result(pbest[ib], pf[ib], t, ev.count, message, {"method": "pso", "w_final": wt if t else w0})
