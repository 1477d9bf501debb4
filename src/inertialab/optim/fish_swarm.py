"""Artificial fish swarm (AFSA) and its improved form (IAFSA) on the shared optimiser
signature of :mod:`inertialab.optim.base`.

Fish swim in the unit cube ``u in [0, 1]^D``, mapped linearly to ``bounds``. Each
generation every fish, in order and updated in place, tries the *swarm* behaviour
(move toward the centre of its neighbours when that centre is better and not crowded)
and the *follow* behaviour (move toward its best neighbour under the same
conditions); a behaviour whose condition fails falls back to *prey* (up to
``try_number`` random looks within ``visual``, moving toward the first better one,
else a random step). The fish takes the better of the two results. A bulletin board
keeps the best position seen (spec 000 §3.5).

:func:`iafsa` adds the adaptive visual and step of Wang, Zhou & Ma (2005),
``alpha_t = exp(-30 (t/G)^s)``, ``Visual_t = Visual_min + alpha_t (Visual_0 -
Visual_min)`` (same for Step), and elitism: the worst fish is replaced by the board's
best at the end of each generation. It stops at ``max_generations`` or when the best
value improved by less than 1 % over 10 generations. :func:`afsa` is Li's original
with fixed visual and step and no elitism.

Hand-written: SciPy has no fish-swarm optimiser, and the comparison with CS, ACS
and PSO needs the shared signature and evaluation counting (spec 002 §3.9).

References
----------
Li Xiaolei, Shao Zhijiang, Qian Jixin, "An optimizing method based on autonomous
animats: fish-swarm algorithm", Systems Engineering - Theory & Practice 22 (2002)
32-38. Wang Cuiru, Zhou Chunlei, Ma Jianwei, "An improved artificial fish-swarm
algorithm and its application in feed-forward neural networks", ICMLC 2005.
Spec 000 §3.5.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from inertialab.errors import InputError
from inertialab.optim.base import (
    CountedObjective,
    OptimResult,
    StopRule,
    as_bounds,
    initial_population,
)
from inertialab.seeding import as_generator

#: Memoisation grid of spec 000 §3.5 (u rounded to 1e-4).
MEMO_DECIMALS = 4


def _unit_vec(d: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(d)
    return d / n if n > 0 else d


def _fish_swarm(fun, bounds, *, pop_size, max_generations, rng, x_init, target, stall, memoize,
                callback, try_number, crowd, visual, step, visual_min, step_min, s, adaptive,
                elitism, improve_window, improve_tol, repair) -> OptimResult:
    lo, hi = as_bounds(bounds)
    d = lo.size
    if try_number < 1:
        raise InputError(f"try_number must be >= 1, got {try_number}")
    if not 0 < crowd <= 1:
        raise InputError(f"crowd factor must be in (0, 1], got {crowd}")
    gen = as_generator(rng)

    def decode(u: np.ndarray) -> np.ndarray:
        x = lo + (hi - lo) * u
        return repair(x) if repair is not None else x

    memo = memoize if memoize else None
    counted = CountedObjective(lambda u: fun(decode(u)), memoize=memo)

    def F(u: np.ndarray) -> float:
        if memo:
            u = np.round(u, MEMO_DECIMALS)
        return counted(u)

    x0 = initial_population(lo, hi, pop_size, gen, x_init)
    U = np.clip((x0 - lo) / (hi - lo), 0.0, 1.0)
    fit = np.array([F(u) for u in U])
    ib = int(np.argmin(fit))
    best_u, best_f = U[ib].copy(), float(fit[ib])
    stop = StopRule(max_generations, target=target, stall=stall)
    msg = stop.record(0, best_f)
    vis_hist, step_hist = [], []
    t = 0
    while msg is None:
        t += 1
        if adaptive:
            a = np.exp(-30.0 * (t / max_generations) ** s)
            vis = visual_min + a * (visual - visual_min)
            stp = step_min + a * (step - step_min)
        else:
            vis, stp = visual, step
        vis_hist.append(vis)
        step_hist.append(stp)

        def prey(i: int, vis: float = vis, stp: float = stp) -> np.ndarray:
            ui = U[i]
            for _ in range(try_number):
                uj = np.clip(ui + vis * gen.uniform(-1.0, 1.0, d), 0.0, 1.0)
                if F(uj) < fit[i]:
                    return np.clip(ui + gen.random() * stp * _unit_vec(uj - ui), 0.0, 1.0)
            return np.clip(ui + stp * gen.uniform(-1.0, 1.0, d), 0.0, 1.0)

        for i in range(pop_size):
            ui = U[i]
            dist = np.linalg.norm(U - ui, axis=1)
            nb = np.flatnonzero(dist < vis)
            nb = nb[nb != i]
            nf = nb.size
            not_crowded = nf / pop_size < crowd
            # swarm
            u_s = None
            if nf > 0 and not_crowded:
                uc = U[nb].mean(axis=0)
                if F(uc) < fit[i]:
                    u_s = np.clip(ui + gen.random() * stp * _unit_vec(uc - ui), 0.0, 1.0)
            if u_s is None:
                u_s = prey(i)
            # follow
            u_f = None
            if nf > 0 and not_crowded:
                jb = nb[int(np.argmin(fit[nb]))]
                if fit[jb] < fit[i]:
                    u_f = np.clip(ui + gen.random() * stp * _unit_vec(U[jb] - ui), 0.0, 1.0)
            if u_f is None:
                u_f = prey(i)
            fs, ff = F(u_s), F(u_f)
            if fs <= ff:
                U[i], fit[i] = u_s, fs
            else:
                U[i], fit[i] = u_f, ff
            if fit[i] < best_f:
                best_u, best_f = U[i].copy(), float(fit[i])
        if elitism:
            iw = int(np.argmax(fit))
            U[iw], fit[iw] = best_u.copy(), best_f
        if callback is not None:
            callback(t, decode(best_u), best_f)
        msg = stop.record(t, best_f)
        h = stop.history
        if msg is None and improve_window and len(h) > improve_window:
            old = h[-1 - improve_window]
            if np.isfinite(old) and old - best_f < improve_tol * abs(old):
                msg = f"best value improved by less than {improve_tol:.0%} over {improve_window} generations"
    u_best = np.round(best_u, MEMO_DECIMALS) if memo else best_u
    extra = {"visual": np.asarray(vis_hist), "step": np.asarray(step_hist),
             "u": u_best.copy(), "population_u": U.copy()}
    return stop.result(decode(u_best), best_f, t, counted.nfev, msg, extra)


def afsa(fun: Callable[[np.ndarray], float], bounds, *, pop_size: int = 10,
         max_generations: int = 30, rng=None, x_init=None, target=None, stall=None,
         memoize=None, callback=None, try_number: int = 5, crowd: float = 0.618,
         visual: float = 0.30, step: float = 0.10, repair=None) -> OptimResult:
    """Artificial fish swarm of Li (2002): fixed visual and step, no elitism.

    Parameters
    ----------
    fun : callable
        Objective ``fun(x) -> float`` to minimise, ``x`` of shape (d,).
    bounds : [(lo, hi), ...]
        Search box; fish move in the unit cube mapped linearly onto it.
    pop_size : int, default=10
        Number of fish (spec 000 §3.5 N_fish).
    max_generations : int, default=30
        Generation budget (spec 000 §3.5 G_max).
    rng : int, Generator or None
        Random source (one stream, drawn in fish order).
    x_init : array-like (d,) or (pop_size, d), optional
        Starting position(s) in the units of ``bounds``.
    target, stall, memoize, callback
        As in :mod:`inertialab.optim.base`; ``memoize`` (cache size) also rounds ``u``
        to 1e-4 before evaluating (spec 000 §3.5). ``callback(generation, x_best,
        f_best)`` after each generation.
    try_number : int, default=5
        Prey attempts.
    crowd : float, default=0.618
        Crowd factor: a neighbourhood is crowded when ``n_f/pop_size >= crowd``.
    visual, step : float, default=0.30, 0.10
        Visual range and step in unit-cube coordinates.
    repair : callable, optional
        ``repair(x) -> x`` applied to every decoded position before ``fun``.
    """
    return _fish_swarm(fun, bounds, pop_size=pop_size, max_generations=max_generations, rng=rng,
                       x_init=x_init, target=target, stall=stall, memoize=memoize,
                       callback=callback, try_number=try_number, crowd=crowd, visual=visual,
                       step=step, visual_min=visual, step_min=step, s=3.0, adaptive=False,
                       elitism=False, improve_window=None, improve_tol=0.0, repair=repair)


def iafsa(fun: Callable[[np.ndarray], float], bounds, *, pop_size: int = 10,
          max_generations: int = 30, rng=None, x_init=None, target=None, stall=None,
          memoize=None, callback=None, try_number: int = 5, crowd: float = 0.618,
          visual: float = 0.30, step: float = 0.10, visual_min: float = 0.02,
          step_min: float = 0.005, s: float = 3.0, improve_window: int | None = 10,
          improve_tol: float = 0.01, repair=None) -> OptimResult:
    """Improved artificial fish swarm (spec 000 §3.5): adaptive visual/step and elitism.

    Parameters are those of :func:`afsa` plus ``visual_min = 0.02``, ``step_min =
    0.005`` and the exponent ``s = 3`` of ``alpha_t = exp(-30 (t/G)^s)``; the run stops
    early when the best value improved by less than ``improve_tol`` (1 %) over
    ``improve_window`` (10) generations (None disables). The defaults are spec 000
    §3.5's (the seed's Table 1 is lost). ``result.extra`` holds the visual and step
    per generation and the best position in unit-cube coordinates.
    """
    return _fish_swarm(fun, bounds, pop_size=pop_size, max_generations=max_generations, rng=rng,
                       x_init=x_init, target=target, stall=stall, memoize=memoize,
                       callback=callback, try_number=try_number, crowd=crowd, visual=visual,
                       step=step, visual_min=visual_min, step_min=step_min, s=s, adaptive=True,
                       elitism=True, improve_window=improve_window, improve_tol=improve_tol,
                       repair=repair)
