"""IAFSA search of the subtractive-clustering parameters of an SCM-ANFIS (spec 000 §3.5).

The decision vector is ``(r_a, eta, eps_up, eps_down)`` (``radii="per_dim"``: one radius
per column of ``[X, y]``, 6-D for two inputs), searched in the box
:data:`SEARCH_BOUNDS` by :func:`inertialab.optim.fish_swarm.iafsa`. The objective
("food concentration", minimised) is the best validation RMSE of an ANFIS trained
``search_epochs`` epochs from the genfis2 FIS of the clustering, converted to mg with
the output's scale ``k1`` (output units per g); a clustering with fewer than 2 or more
than ``r_max`` rules costs :data:`PENALTY_MG`. Fish 0 starts at the default SCM
parameters (0.5, 1.25, 0.5, 0.15), so the result is never worse than the default
(spec 000 §8.2.3).

Everything here works on arrays with plain parameters; the thermal calibration
(:mod:`inertialab.calib.thermal`) passes its configuration's values and the optimiser
(:func:`inertialab.optim.fish_swarm.iafsa`, any optimiser of the shared signature of
:mod:`inertialab.optim.base` fits): the method packages ``learn`` and ``optim`` do not
import each other (docs/architecture.md).
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass

import numpy as np

from inertialab.learn.anfis import ANFIS
from inertialab.learn.subclust import SubtractiveClustering

#: IAFSA search box of spec 000 §3.5: r_a, eta, eps_up, eps_down.
SEARCH_BOUNDS = ((0.05, 1.0), (1.0, 2.5), (0.2, 0.9), (0.01, 0.5))
#: Objective value of an unusable rule count (mg), spec 000 §3.5 step 1.
PENALTY_MG = 1e3
#: Fish-swarm parameters of spec 000 §3.5 (the seed's Table 1 is lost; these are the
#: spec's): visual and step at the start and their floors (unit-cube coordinates), prey
#: attempts, crowd factor, exponent of the adaptive schedule.
FISH_DEFAULTS = {"visual": 0.30, "step": 0.10, "visual_min": 0.02, "step_min": 0.005,
                 "try_number": 5, "crowd": 0.618, "s": 3.0}


def decode(v, radii: str = "scalar") -> dict:
    """SCM parameters from a decision vector, with the repair ``eps_down >= eps_up ->
    eps_down = 0.5 eps_up`` (spec 000 §3.5)."""
    v = np.asarray(v)
    if radii == "per_dim":
        r = [float(x) for x in v[:3]]
        squash, acc, rej = (float(x) for x in v[3:])
    else:
        r = float(v[0])
        squash, acc, rej = (float(x) for x in v[1:])
    if rej >= acc:
        rej = 0.5 * acc
    return {"radius": r, "squash": squash, "accept": acc, "reject": rej}


def search_space(radii: str = "scalar") -> tuple[list, list]:
    """(box, start): the search box and the default SCM parameters as a start point."""
    if radii == "per_dim":
        return [SEARCH_BOUNDS[0]] * 3 + list(SEARCH_BOUNDS[1:]), [0.5, 0.5, 0.5, 1.25, 0.5, 0.15]
    return list(SEARCH_BOUNDS), [0.5, 1.25, 0.5, 0.15]


@dataclass(frozen=True)
class SearchResult:
    """IAFSA search over the SCM parameters (spec 000 §3.5): ``params`` found, ``fun`` =
    F* (validation RMSE, mg), ``f_default`` = F at the default parameters, ``n_rules``,
    ``nfev``, ``nit``, ``history`` (best F per generation), ``wall_s``, ``message``."""

    params: dict
    fun: float
    f_default: float
    n_rules: int
    nfev: int
    nit: int
    history: list
    wall_s: float
    message: str

    def to_dict(self) -> dict:
        return asdict(self)


def search_scm(Xf, yf, Xv, yv, *, k1: float, bounds_x, bounds_y, optimizer,
               radii: str = "scalar", fish: int = 10, generations: int = 30,
               search_epochs: int = 20, r_max: int = 40, fish_params: dict | None = None,
               rng=None, progress=None) -> SearchResult:
    """IAFSA over the SCM parameters minimising the validation RMSE (mg) of a short
    SCM-ANFIS (spec 000 §3.5).

    Parameters
    ----------
    Xf, yf : fit subset, inputs (n, d) and output (n,) in physical units
    Xv, yv : validation subset (best-epoch selection and the objective)
    k1 : output units per g (mV/g): converts the RMSE to acceleration
    bounds_x, bounds_y : scaling bounds of inputs ((2, d): min row, max row) and output
    optimizer : ``optimizer(fun, bounds, *, pop_size, max_generations, rng, x_init,
        memoize, callback, **fish_params) -> OptimResult`` (spec 000: ``iafsa``)
    radii : "scalar" (4-D search) or "per_dim" (one radius per column, 6-D for d = 2)
    fish, generations : N_fish (10) and G_max (30), spec 000 §3.5
    search_epochs : ANFIS epochs inside the objective (20)
    r_max : rule cap (40); fewer than 2 or more rules cost :data:`PENALTY_MG`
    fish_params : overrides of :data:`FISH_DEFAULTS` (visual, step, visual_min,
        step_min, try_number, crowd, s), passed to ``optimizer``
    rng : seed or Generator of the swarm
    progress : object with ``update(done, total, note)`` (or None)
    """
    box, start = search_space(radii)
    fp = dict(FISH_DEFAULTS)
    fp.update(fish_params or {})
    y_span = bounds_y[1] - bounds_y[0] if bounds_y[1] > bounds_y[0] else 1.0
    Xf, yf = np.asarray(Xf, float), np.asarray(yf, float)

    zb = np.zeros((2, 3))
    zb[1] = 1.0

    def n_clusters(m: ANFIS, p: dict) -> int:
        Z = np.column_stack([m._sx(Xf), m._sy(yf)])
        return SubtractiveClustering(bounds=zb, **p).fit(Z).n_clusters_

    def F(v):
        p = decode(np.asarray(v), radii)
        m = ANFIS(epochs=search_epochs, input_bounds=bounds_x, output_bounds=bounds_y, **p)
        m._set_scaling(Xf, yf)
        # count the rules before any least squares: R > R_max would cost O(R^3)
        R = n_clusters(m, p)
        if R < 2 or R > r_max:
            return PENALTY_MG
        m.fit(Xf, yf, validation=(Xv, yv))
        best = m.trace_.val_rmse[m.best_epoch_]
        return float(best * y_span / k1 * 1e3)

    t0 = time.perf_counter()
    f_default = F(np.asarray(start, float))
    gens = max(int(generations), 1)

    def cb(t, x, f):
        if progress is not None:
            progress.update(t, gens, f"IAFSA generation {t}: F* = {f * 1e3:.2f} µg")

    res = optimizer(F, box, pop_size=fish, max_generations=gens, rng=rng, x_init=start,
                memoize=1_000_000, callback=cb, **fp)
    p = decode(res.x, radii)
    m = ANFIS(input_bounds=bounds_x, output_bounds=bounds_y, **p)
    m._set_scaling(Xf, yf)
    R = n_clusters(m, p)
    return SearchResult(params=p, fun=float(res.fun), f_default=float(f_default), n_rules=int(R),
                        nfev=int(res.nfev), nit=int(res.nit), history=res.history.tolist(),
                        wall_s=time.perf_counter() - t0, message=res.message)


__all__ = ["FISH_DEFAULTS", "PENALTY_MG", "SEARCH_BOUNDS", "SearchResult", "decode",
           "search_scm", "search_space"]
