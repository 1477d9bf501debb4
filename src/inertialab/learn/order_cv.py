"""Lag-order selection by kernel cross-validation and the Nadaraya-Watson estimator.

Spec 004 §3.1 (seed eqs. (2)-(4), reconstructed after Cheng & Tong 1992): the order p of
a nonlinear autoregression is the argmin over p = 1..H of the leave-one-out
Nadaraya-Watson prediction error on standardised lag vectors, all candidates scored
on the same target set {H+1..T}.

Hand-written because no maintained library offers this criterion: statsmodels'
``KernelReg`` chooses bandwidths by CV but not lag orders on a common index set, and
it has neither the log-sum-exp-shifted weights nor the gap masking the spec asks for.
The cost is O(H m^2) with m the number of targets; everything is vectorised.

References
----------
Spec 004 §3.1 [R-1], §2.2 (gaps), §4.5 (kernel NAR baseline). Cheng, B. & Tong, H.
(1992), "On consistent nonparametric order determination and chaos", JRSS-B 54(2).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from inertialab.errors import DataQualityWarning, InputError, NotFittedError
from inertialab.estimator import Estimator
from inertialab.limits import bounded_int

__all__ = ["CV_GRID", "NadarayaWatson", "OrderSelection", "lag_targets", "select_order_cv"]

#: Bandwidth constants searched by ``bandwidth="cv"`` (spec 004 §3.1).
CV_GRID = (0.25, 0.35, 0.5, 0.7, 1.0, 1.4)


@dataclass(frozen=True)
class OrderSelection:
    """Result of :func:`select_order_cv`.

    Attributes
    ----------
    order : selected lag order p-hat
    scores : CV(p) for p = 1..H (standardised units squared)
    bandwidths : h_p used for each p (standardised units)
    constants : the c of each h_p (all ``c`` for ``bandwidth="rule"``)
    H : upper bound actually used (may be lower than asked, see ``warnings``)
    m : number of CV targets
    targets : time indices of the CV targets
    """

    order: int
    scores: tuple
    bandwidths: tuple
    constants: tuple
    H: int
    m: int
    targets: tuple

    def to_dict(self) -> dict:
        return {"order": self.order, "scores": list(self.scores),
                "bandwidths": list(self.bandwidths), "constants": list(self.constants),
                "H": self.H, "m": self.m}


def _nw_weights(D: np.ndarray) -> np.ndarray:
    """exp(-(D - rowmin D)) with +inf entries -> 0 (log-sum-exp shift, spec §3.1)."""
    mn = np.min(D, axis=1, keepdims=True)
    mn = np.where(np.isfinite(mn), mn, 0.0)
    return np.exp(-(D - mn))


def lag_targets(usable: np.ndarray, H: int) -> np.ndarray:
    """Indices t >= H whose value and H previous values are all usable."""
    usable = np.asarray(usable, dtype=bool)
    n = usable.size
    if n <= H:
        return np.zeros(0, dtype=int)
    ok = np.ones(n - H, dtype=bool)
    for k in range(H + 1):
        ok &= usable[H - k: n - k]
    return np.flatnonzero(ok) + H


def _cv_score(z, t_idx, p, h, exclude, trim_q):
    U = np.column_stack([z[t_idx - k] for k in range(1, p + 1)])
    zt = z[t_idx]
    sq = np.sum(U * U, axis=1)
    D2 = np.maximum(sq[:, None] + sq[None, :] - 2.0 * U @ U.T, 0.0)
    D = D2 / (2.0 * h * h)
    mask = np.abs(t_idx[:, None] - t_idx[None, :]) <= exclude
    D[mask] = np.inf
    W = _nw_weights(D)
    den = W.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        f = (W @ zt) / den
    err2 = (zt - f) ** 2
    w = np.ones_like(zt)
    if trim_q:
        lo = np.quantile(U, trim_q, axis=0)
        hi = np.quantile(U, 1.0 - trim_q, axis=0)
        w = np.all((U >= lo) & (U <= hi), axis=1).astype(float)
    good = np.isfinite(err2)
    return float(np.sum(err2[good] * w[good]) / t_idx.size)


def select_order_cv(y, *, H: int = 6, c: float = 0.5, bandwidth: str = "rule",
                    exclude: int = 0, trim_q: float | None = None, difference: bool = False,
                    usable=None) -> OrderSelection:
    """Choose the NAR lag order by kernel cross-validation (spec 004 §3.1).

    Parameters
    ----------
    y : (n,) array
        Series on a regular grid; NaN marks a missing day (a gap).
    H : int, default=6
        Largest order tried [R-2]. Reduced, with a :class:`DataQualityWarning`, until
        the number of CV targets m >= 10 H.
    c : float, default=0.5
        Bandwidth constant: ``h_p = c m^(-1/(p+4))`` in standardised units.
    bandwidth : {"rule", "cv"}, default="rule"
        ``"cv"`` scores each p with the best c of :data:`CV_GRID`.
    exclude : int, default=0
        Leave-block-out half width l: neighbours with |s - t| <= l are left out.
    trim_q : float, optional
        Trimming weight: w = 0 where a lag lies outside its [q, 1-q] sample quantiles.
    difference : bool, default=False
        Run the criterion on the first differences (a documented deviation for
        trend-dominated series).
    usable : (n,) bool array, optional
        Days that may serve as targets or lags (observed, not imputed, not screened);
        default: the finite values of ``y``. Imputed days must be marked unusable.

    Returns
    -------
    OrderSelection
    """
    y = np.asarray(y, dtype=float).ravel()
    ok = np.isfinite(y) if usable is None else (np.asarray(usable, dtype=bool) & np.isfinite(y))
    if ok.size != y.size:
        raise InputError(f"usable has {ok.size} entries, y has {y.size}")
    if difference:
        y = np.diff(y)
        ok = ok[1:] & ok[:-1]
    if bandwidth not in ("rule", "cv"):
        raise InputError(f"bandwidth must be 'rule' or 'cv', got {bandwidth!r}")
    if int(H) < 1:
        raise InputError(f"H must be >= 1, got {H}")
    H_req = bounded_int("H", H, 1, 1000)  # each order is a kernel CV over all targets
    H = H_req
    while H >= 1 and lag_targets(ok, H).size < 10 * H:
        H -= 1
    if H < 1:
        raise InputError(
            f"too few usable days for order selection: {int(ok.sum())} usable values, "
            "need at least 11 consecutive ones for H = 1")
    if H < H_req:
        warnings.warn(f"order bound H reduced from {H_req} to {H}: only "
                      f"{lag_targets(ok, H_req).size} CV targets for H = {H_req} "
                      f"(need m >= 10 H)", DataQualityWarning, stacklevel=2)
    t_idx = lag_targets(ok, H)
    m = t_idx.size
    vals = y[ok]
    sd = float(np.std(vals, ddof=1))
    if not np.isfinite(sd) or sd <= 1e-12 * max(1.0, float(np.max(np.abs(vals)))):
        warnings.warn("constant series: order selection is meaningless, using p = 1",
                      DataQualityWarning, stacklevel=2)
        nan = tuple([float("nan")] * H)
        return OrderSelection(1, nan, nan, tuple([c] * H), H, m, tuple(t_idx.tolist()))
    z = np.where(ok, (y - float(np.mean(vals))) / sd, 0.0)
    consts = CV_GRID if bandwidth == "cv" else (float(c),)
    scores, hs, cs = [], [], []
    for p in range(1, H + 1):
        best = (np.inf, np.nan, np.nan)
        for cc in consts:
            h = cc * m ** (-1.0 / (p + 4))
            s = _cv_score(z, t_idx, p, h, int(exclude), trim_q)
            if s < best[0]:
                best = (s, h, cc)
        scores.append(best[0])
        hs.append(best[1])
        cs.append(best[2])
    sc = np.asarray(scores)
    smin = np.min(sc)
    order = int(np.flatnonzero(sc <= smin + 1e-9 * abs(smin))[0]) + 1
    return OrderSelection(order, tuple(scores), tuple(hs), tuple(cs), H, m,
                          tuple(t_idx.tolist()))


class NadarayaWatson(Estimator):
    """Nadaraya-Watson regression with an isotropic Gaussian kernel (spec 004 §3.1 eq. (2)).

    Parameters
    ----------
    bandwidth : float
        h in the units of ``X`` (the NAR baseline passes standardised lags).

    Notes
    -----
    Weights are computed as exp(-(D - min D)) with D = ||x - x_s||^2 / (2 h^2), so the
    denominator never underflows: far from the data the estimate falls back to the
    nearest sample's target instead of 0/0.
    """

    def __init__(self, *, bandwidth: float = 1.0):
        self.bandwidth = bandwidth

    def fit(self, X, y) -> NadarayaWatson:
        X = np.asarray(X, dtype=float)
        if X.ndim == 1:
            X = X[:, None]
        y = np.asarray(y, dtype=float).ravel()
        if X.shape[0] != y.size or y.size == 0:
            raise InputError(f"X has {X.shape[0]} rows, y has {y.size}")
        if not self.bandwidth > 0:
            raise InputError(f"bandwidth must be > 0, got {self.bandwidth}")
        self.X_, self.y_ = X, y
        return self

    def predict(self, X) -> np.ndarray:
        if not hasattr(self, "X_"):
            raise NotFittedError("NadarayaWatson.predict called before fit")
        X = np.asarray(X, dtype=float)
        if X.ndim == 1:
            X = X[:, None] if self.X_.shape[1] == 1 else X[None, :]
        D = np.sum((X[:, None, :] - self.X_[None, :, :]) ** 2, axis=2)
        W = _nw_weights(D / (2.0 * self.bandwidth ** 2))
        return (W @ self.y_) / W.sum(axis=1)
