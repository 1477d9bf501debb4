"""Cuckoo search (CS) and adaptive cuckoo search (ACS).

CS follows Yang & Deb (2009) in the form of their reference code (spec 002 §3.3):
a Lévy phase with Mantegna steps scaled by the distance to the best nest, then an
abandonment (biased random-walk) phase with the discovery mask ``r > Pa``, each with
a greedy replacement. ACS (spec 002 §3.4, reconstructed) mixes a random walk into the
Lévy phase with the nonlinear weight ``omega1(tau) = omega_min + (omega_max -
omega_min) cos(pi tau / 2)`` and shrinks the discovery probability with
``delta(tau) = delta_min + (1 - delta_min) exp(-(tau/tau_delta)^2)``.

No maintained library implements CS/ACS with the counting and the common random
numbers the fair comparison of spec 002 §3.9 needs, so both are written here on
numpy, on the shared signature and result of :mod:`inertialab.optim.base`.

Random stream (documented order, one Generator from ``rng``): the initial
population (``initial_population``: one ``random((N, d))`` draw, identical for CS,
ACS and PSO with the same seed), then per generation: Lévy phase (Mantegna u, v,
then zeta; ACS also eps_i, pi3, pi4), abandonment phase (pi1, pi2, eps, r).

References
----------
Yang & Deb, "Cuckoo search via Lévy flights", NaBIC 2009. Mantegna, Phys. Rev. E 49,
4677 (1994). Spec 002 §3.3, §3.4, §3.9.
"""

from __future__ import annotations

import math
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

__all__ = ["adaptive_cuckoo_search", "cuckoo_search", "delta_factor", "mantegna_sigma",
           "mantegna_step", "omega1"]


def mantegna_sigma(beta: float = 1.5) -> float:
    """sigma_u of Mantegna's algorithm (spec 002 §3.3); 0.696575 for beta = 1.5."""
    num = math.gamma(1.0 + beta) * math.sin(math.pi * beta / 2.0)
    den = math.gamma((1.0 + beta) / 2.0) * beta * 2.0 ** ((beta - 1.0) / 2.0)
    return (num / den) ** (1.0 / beta)


def mantegna_step(shape, rng, beta: float = 1.5) -> np.ndarray:
    """Lévy-stable steps L = u / |v|^(1/beta), u ~ N(0, sigma_u^2), v ~ N(0, 1)."""
    rng = as_generator(rng)
    u = rng.standard_normal(shape) * mantegna_sigma(beta)
    v = rng.standard_normal(shape)
    return u / np.abs(v) ** (1.0 / beta)


def omega1(tau, omega_max: float = 1.0, omega_min: float = 0.1):
    """ACS Lévy weight omega1(tau) = omega_min + (omega_max - omega_min) cos(pi tau/2) (§3.4)."""
    return omega_min + (omega_max - omega_min) * np.cos(np.pi * np.asarray(tau) / 2.0)


def delta_factor(tau, delta_min: float = 0.2, tau_delta: float = 0.3):
    """ACS discovery factor delta(tau) = delta_min + (1 - delta_min) exp(-(tau/tau_delta)^2)."""
    return delta_min + (1.0 - delta_min) * np.exp(-(np.asarray(tau) / tau_delta) ** 2)


def _run_cuckoo(fun, bounds, *, adaptive, pop_size, max_generations, rng, x_init, target,
                stall, memoize, callback, vectorized, beta, alpha0, pa, mask, schedule_len,
                omega_max, omega_min, delta_min, tau_delta) -> OptimResult:
    lo, hi = as_bounds(bounds)
    if not 0.0 <= pa <= 1.0:
        raise InputError(f"pa must be in [0, 1], got {pa}")
    if mask not in ("reference", "textbook"):
        raise InputError(f"mask must be 'reference' or 'textbook', got {mask!r}")
    gen = as_generator(rng)
    N, d = int(pop_size), lo.size
    nests = initial_population(lo, hi, N, gen, x_init)
    ev = Evaluator(fun, vectorized, memoize)
    fit = ev(nests)
    stop = StopRule(max_generations, target=target, stall=stall)
    ib = int(np.argmin(fit))
    message = stop.record(0, float(fit[ib]))
    T_s = float(schedule_len if schedule_len is not None else max_generations)
    sig = mantegna_sigma(beta)
    t = 0
    pa_t = pa
    w1 = 1.0
    while message is None:
        t += 1
        tau = (t - 1) / T_s
        # Lévy phase
        xbest = nests[ib]
        u = gen.standard_normal((N, d)) * sig
        v = gen.standard_normal((N, d))
        L = u / np.abs(v) ** (1.0 / beta)
        zeta = gen.standard_normal((N, d))
        step = alpha0 * L * (nests - xbest) * zeta
        if adaptive:
            w1 = float(omega1(tau, omega_max, omega_min))
            eps_i = gen.random((N, 1))
            p3, p4 = gen.permutation(N), gen.permutation(N)
            step = w1 * step + (1.0 - w1) * eps_i * (nests[p3] - nests[p4])
        trial = np.clip(nests + step, lo, hi)
        ft = ev(trial)
        better = ft < fit
        nests[better] = trial[better]
        fit[better] = ft[better]
        # abandonment phase
        pa_t = float(delta_factor(tau, delta_min, tau_delta) * pa) if adaptive else pa
        p1, p2 = gen.permutation(N), gen.permutation(N)
        eps = gen.random()
        r = gen.random((N, d))
        H = (r > pa_t) if mask == "reference" else (r < pa_t)
        trial = np.clip(nests + eps * H * (nests[p1] - nests[p2]), lo, hi)
        ft = ev(trial)
        better = ft < fit
        nests[better] = trial[better]
        fit[better] = ft[better]
        ib = int(np.argmin(fit))
        message = stop.record(t, float(fit[ib]))
        if callback is not None and callback(t, nests[ib].copy(), float(fit[ib])):
            message = message or f"stopped by callback at generation {t}"
    extra = {"method": "acs" if adaptive else "cs", "pa_final": pa_t}
    if adaptive:
        extra["omega1_final"] = w1
    return stop.result(nests[ib], fit[ib], t, ev.count, message, extra)


def cuckoo_search(fun: Callable, bounds, *, pop_size: int = 25, max_generations: int = 1000,
                  rng=None, x_init=None, target=None, stall=None, memoize=None,
                  callback=None, vectorized: bool = False, beta: float = 1.5,
                  alpha0: float = 0.01, pa: float = 0.25,
                  mask: str = "reference") -> OptimResult:
    """Cuckoo search (Yang & Deb 2009, reference-code form; spec 002 §3.3).

    Parameters
    ----------
    fun : callable
        ``x (d,) -> float``, or ``X (P, d) -> (P,)`` with ``vectorized=True``.
    bounds : [(lo, hi), ...] or (lo, hi)
        Search box; positions are clipped to it after every move.
    pop_size : int, default 25
        Number of nests N (spec 002 §3.3).
    max_generations : int, default 1000
        T_max; one generation = Lévy phase + abandonment phase (2N evaluations).
    rng : int, Generator or None
        Seed; the initial population is its first draw (common with ACS and PSO).
    x_init : array (d,) or (N, d), optional
        Shared initial population (spec 002 §3.2).
    target : float or Target, optional
        Convergence target J* (spec 002 §3.9 tolerances); the run stops when reached.
    stall : int, optional
        Stop after this many generations without improvement.
    memoize : int, optional
        Cache size for exact repeats (not counted in ``nfev``).
    callback : callable, optional
        ``callback(generation, x_best, f_best)``; a true return value stops the run.
    vectorized : bool, default False
        ``fun`` evaluates a whole population at once.
    beta : float, default 1.5
        Lévy exponent (Mantegna).
    alpha0 : float, default 0.01
        Step scale.
    pa : float, default 0.25
        Discovery probability.
    mask : {"reference", "textbook"}, default "reference"
        ``reference``: a component moves when r > Pa (probability 1 - Pa, the
        reference code); ``textbook``: when r < Pa.

    Returns
    -------
    OptimResult
        ``nit`` = generations, ``nfev`` = evaluations, ``history[t]`` = best value
        after generation t.
    """
    return _run_cuckoo(fun, bounds, adaptive=False, pop_size=pop_size,
                       max_generations=max_generations, rng=rng, x_init=x_init, target=target,
                       stall=stall, memoize=memoize, callback=callback, vectorized=vectorized,
                       beta=beta, alpha0=alpha0, pa=pa, mask=mask, schedule_len=None,
                       omega_max=1.0, omega_min=1.0, delta_min=1.0, tau_delta=1.0)


def adaptive_cuckoo_search(fun: Callable, bounds, *, pop_size: int = 25,
                           max_generations: int = 1000, rng=None, x_init=None, target=None,
                           stall=None, memoize=None, callback=None, vectorized: bool = False,
                           beta: float = 1.5, alpha0: float = 0.01, pa: float = 0.25,
                           mask: str = "reference", schedule_len: int | None = 1000,
                           omega_max: float = 1.0, omega_min: float = 0.1,
                           delta_min: float = 0.2, tau_delta: float = 0.3) -> OptimResult:
    """Adaptive cuckoo search (spec 002 §3.4, reconstruction of the paper's ACS).

    Same parameters as :func:`cuckoo_search`, plus the schedule constants (all the
    spec's normative defaults): ``tau = (t - 1)/T_s`` with ``schedule_len`` T_s =
    1000 (None: ``max_generations``), Lévy weight ``omega1(tau)`` with
    ``omega_max = 1.0``, ``omega_min = 0.1`` (the random-walk weight is 1 - omega1),
    and the discovery probability ``Pa'(tau) = delta(tau)·Pa`` with
    ``delta_min = 0.2``, ``tau_delta = 0.3``.
    """
    return _run_cuckoo(fun, bounds, adaptive=True, pop_size=pop_size,
                       max_generations=max_generations, rng=rng, x_init=x_init, target=target,
                       stall=stall, memoize=memoize, callback=callback, vectorized=vectorized,
                       beta=beta, alpha0=alpha0, pa=pa, mask=mask, schedule_len=schedule_len,
                       omega_max=omega_max, omega_min=omega_min, delta_min=delta_min,
                       tau_delta=tau_delta)
