"""Direct multi-step NAR: one network per forecast step (spec 004 §3.8, the ablation the
paper's comparison needs beside the recursive closed loop of :mod:`inertialab.learn.nar`).

For step k = 1..K a tapped-delay-line tanh network f_k maps the p values before t to
y_{t+k-1}; the forecast of step k from origin T is f_k(y_T, ..., y_{T-p+1}), so no
prediction is fed back. Each f_k is trained open loop like the recursive NAR (the series
mapped to [-1, 1] with its in-sample min/max, Nguyen-Widrow, trainlm, 90/10 split,
validation early stopping, R restarts; "best" = the member with the lowest validation
MSE, "median"/"mean" = the pointwise combination of the ceil(R/2) best). The 95 %
interval of step k adds the 2.5 % / 97.5 % quantiles of f_k's in-sample residuals
(normalised units) to its forecast.

Random streams: ``SeedSequence(seed).spawn(K)``, one per step, each ``spawn(R)`` over
restarts. Cost: K x R network fits (20 x 10 for the spec's defaults).
"""

from __future__ import annotations

import math

import numpy as np

from inertialab.errors import InputError, NotFittedError
from inertialab.estimator import Estimator
from inertialab.learn.forecast_baselines import Forecast
from inertialab.learn.mlp_lm import MLPRegressorLM, forward
from inertialab.learn.nar import PRESETS, _seed_sequence
from inertialab.learn.order_cv import select_order_cv

__all__ = ["DirectNARForecaster"]


class DirectNARForecaster(Estimator):
    """Direct strategy NAR (one net per step); scikit-learn-style forecaster.

    Parameters
    ----------
    horizon : int, default=20
        Steps K (one network each); :meth:`forecast` serves h <= K.
    order : int, optional
        Lag order p; None = kernel CV (§3.1) with ``H``.
    H : int, default=6
    hidden : int, default=10
    restarts : int, default=10
    preset : {"paper", "strict"}, default="paper"
        ("best", "random") or ("median", "block") as for the recursive NAR.
    val_fraction : float, default=0.1
    lm : dict, optional
        Extra :class:`MLPRegressorLM` settings.
    rng : int | SeedSequence | Generator | None (= seed 0)

    Examples
    --------
    An AR(2) series ``y_k = 0.9 y_(k-1) - 0.2 y_(k-2) + 0.1 + e_k`` (noise sd 0.01): the
    forecast follows the series' exact conditional mean, which its 95 % band holds:

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> y, e = np.zeros(80), rng.normal(0.0, 0.01, 80)
    >>> for k in range(2, 80):
    ...     y[k] = 0.9 * y[k - 1] - 0.2 * y[k - 2] + 0.1 + e[k]
    >>> exact, (a, b) = [], (y[-1], y[-2])
    >>> for _ in range(3):
    ...     a, b = 0.9 * a - 0.2 * b + 0.1, a
    ...     exact.append(a)
    >>> direct = DirectNARForecaster(horizon=3, order=2, hidden=2, restarts=1, rng=0).fit(y)
    >>> fc = direct.forecast(3)
    >>> bool(np.all(np.abs(fc.values - exact) < 0.04))
    True
    >>> bool(np.all((fc.lo95 < exact) & (exact < fc.hi95)))
    True
    """

    name = "nar_direct"

    def __init__(self, *, horizon=20, order=None, H=6, hidden=10, restarts=10, preset="paper",
                 val_fraction=0.1, lm=None, rng=None):
        self.horizon = horizon
        self.order = order
        self.H = H
        self.hidden = hidden
        self.restarts = restarts
        self.preset = preset
        self.val_fraction = val_fraction
        self.lm = lm
        self.rng = rng

    def fit(self, y, *, usable=None) -> DirectNARForecaster:
        """Fit the K networks on the in-sample series ``y`` (NaN = missing)."""
        if self.preset not in PRESETS:
            raise InputError(f"preset must be one of {', '.join(PRESETS)}, got {self.preset!r}")
        comb, split = PRESETS[self.preset]
        y = np.asarray(y, dtype=float).ravel()
        fin = np.isfinite(y)
        if not fin[-1]:
            raise InputError("the last in-sample value (the forecast origin) is missing")
        K, R, S = int(self.horizon), int(self.restarts), int(self.hidden)
        if K < 1 or R < 1 or S < 1:
            raise InputError("horizon, restarts and hidden must be >= 1")
        ok = fin if usable is None else (np.asarray(usable, dtype=bool) & fin)
        lo, hi = float(np.min(y[fin])), float(np.max(y[fin]))
        span = hi - lo
        self.constant_ = bool(span < 1e-12 * max(1.0, abs(hi)))
        self.lo_, self.span_ = lo, (1.0 if self.constant_ else span)
        self.y_ = y
        if self.constant_:
            self.order_, self.nets_, self.resid_q_ = 1, [], []
            return self
        if self.order is None:
            p = select_order_cv(y, H=self.H, usable=ok).order
        else:
            p = int(self.order)
            if p < 1:
                raise InputError(f"order must be >= 1, got {self.order}")
        z = 2.0 * (np.where(fin, y, 0.0) - lo) / self.span_ - 1.0
        n = y.size
        nets, qs = [], []
        lm = dict(self.lm or {})
        for k, step_seed in zip(range(1, K + 1), _seed_sequence(self.rng).spawn(K)):
            t = np.arange(p, n - k + 1)
            keep = np.ones(t.size, dtype=bool)  # lags and every step to the target in one
            for j in range(-p, k):              # segment (spec §2.2 item 4)
                keep &= fin[t + j]
            t = t[keep]
            if t.size < 4:
                raise InputError(f"too few samples ({t.size}) for the step-{k} network of "
                                 f"order {p}; shorten the horizon")
            U = np.column_stack([z[t - j] for j in range(1, p + 1)])
            tgt = z[t + k - 1]
            members = []
            for child in step_seed.spawn(R):
                net = MLPRegressorLM(hidden=S, scale=False, split=split,
                                     val_fraction=float(self.val_fraction),
                                     rng=np.random.Generator(np.random.PCG64(child)), **lm)
                net.fit(U, tgt)
                rep = net.report_
                vm = min(rep.val_mse) if rep.val_mse else rep.train_mse[-1]
                members.append((float(vm), net.theta_))
            members.sort(key=lambda m: m[0])
            chosen = members[:1] if comb == "best" else members[: int(math.ceil(R / 2))]
            thetas = [m[1] for m in chosen]
            fits = np.array([forward(th, U, S) for th in thetas])
            f = fits[0] if comb == "best" else (np.median(fits, axis=0) if comb == "median"
                                                else np.mean(fits, axis=0))
            nets.append(thetas)
            qs.append(np.quantile(tgt - f, [0.025, 0.975]))
        self.order_, self.nets_, self.resid_q_, self.combine_ = p, nets, qs, comb
        return self

    def forecast(self, h: int) -> Forecast:
        """Forecast steps 1..h (h <= horizon) from the last p in-sample values."""
        if not hasattr(self, "order_"):
            raise NotFittedError("DirectNARForecaster.forecast called before fit")
        h = int(h)
        if not 1 <= h <= int(self.horizon):
            raise InputError(f"horizon must be from 1 to the fitted {self.horizon}, got {h}")
        if self.constant_:
            v = np.full(h, self.y_[-1])
            return Forecast(v, v.copy(), v.copy(), v.copy())
        p = self.order_
        tail = self.y_[-p:]
        if not np.all(np.isfinite(tail)):
            raise InputError(f"the last {p} in-sample values must be present to forecast")
        u = (2.0 * (tail[::-1] - self.lo_) / self.span_ - 1.0)[None, :]
        S = int(self.hidden)
        vals, lo, hi = np.empty(h), np.empty(h), np.empty(h)
        for k in range(h):
            preds = np.array([forward(th, u, S)[0] for th in self.nets_[k]])
            c = preds[0] if self.combine_ == "best" else (
                np.median(preds) if self.combine_ == "median" else np.mean(preds))
            vals[k], lo[k], hi[k] = c, c + self.resid_q_[k][0], c + self.resid_q_[k][1]
        back = lambda v: (v + 1.0) * self.span_ / 2.0 + self.lo_  # noqa: E731
        return Forecast(back(vals), back(lo), back(hi), back(vals))
