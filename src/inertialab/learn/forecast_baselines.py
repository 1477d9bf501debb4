"""Forecast baselines of spec 004 §4, all with one shape: ``fit(y) -> self``, ``forecast(h) -> Forecast``.

``y`` is a series on a regular (daily) grid; NaN marks a day that is missing (a gap
longer than the interpolation limit). ``usable`` (optional) marks the days that may
serve as regression targets (observed, not imputed); lags may use imputed values,
as in the NAR's open-loop data set (spec 004 §2.2 item 4).

- :class:`Persistence` (§4.1) and :class:`WindowMean` (§4.1b);
- :class:`ARLeastSquares` (§4.2): y_t = c + sum phi_i y_{t-i}, least squares, order
  given, by kernel CV or by AIC over 1..H; recursive forecasts;
- :class:`ARIMAByAIC` (§4.3): ``statsmodels.tsa.arima.model.ARIMA`` over a (p, d, q)
  grid, lowest AIC among converged fits;
- :class:`PolyTrend` (§4.4a): polynomial in t/T, degree 1..3 by BIC, via
  :class:`~inertialab.learn.poly.PolynomialRegressor`;
- :class:`ExpSaturation` (§4.4b/c): a + b (1 - exp(-t/tau)) by
  ``scipy.optimize.least_squares``, optionally with an AR(1) model of the residuals;
- :class:`KernelNAR` (§4.5): the Nadaraya-Watson estimator of §3.1 used recursively.

The AR least squares is written here (a few lines of ``numpy.linalg.lstsq``) rather
than taken from statsmodels ``AutoReg`` because it must skip samples that touch a gap;
the tests check it against ``AutoReg`` on gap-free data (acceptance A12).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from inertialab.errors import InputError, NotFittedError
from inertialab.estimator import Estimator
from inertialab.learn.order_cv import NadarayaWatson, lag_targets, select_order_cv
from inertialab.learn.poly import PolynomialRegressor

__all__ = [
    "BASELINES",
    "ARIMAByAIC",
    "ARLeastSquares",
    "ExpSaturation",
    "Forecast",
    "KernelNAR",
    "Persistence",
    "PolyTrend",
    "WindowMean",
    "make_baseline",
]


@dataclass(frozen=True)
class Forecast:
    """A forecast over steps 1..K after the origin.

    Attributes
    ----------
    values : (K,) central forecast, units of the series
    lo95, hi95 : (K,) bounds of the 95 % prediction interval, or None
    median : (K,) median of the simulated paths, or None
    """

    values: np.ndarray
    lo95: np.ndarray | None = None
    hi95: np.ndarray | None = None
    median: np.ndarray | None = None

    @property
    def steps(self) -> np.ndarray:
        return np.arange(1, self.values.size + 1)


def _series(y, usable=None):
    y = np.asarray(y, dtype=float).ravel()
    if y.size < 2:
        raise InputError(f"need at least 2 values to fit a forecaster, got {y.size}")
    if not np.isfinite(y[-1]):
        raise InputError("the last in-sample value (the forecast origin) is missing")
    ok = np.isfinite(y)
    if usable is not None:
        usable = np.asarray(usable, dtype=bool).ravel()
        if usable.size != y.size:
            raise InputError(f"usable has {usable.size} entries, y has {y.size}")
        ok = ok & usable
    return y, ok


def _check_h(h):
    if int(h) != h or h < 1:
        raise InputError(f"horizon must be a positive integer, got {h}")
    return int(h)


class _Base(Estimator):
    def _fitted(self):
        if not hasattr(self, "y_"):
            raise NotFittedError(f"{type(self).__name__}.forecast called before fit")


class Persistence(_Base):
    """y_{T+k} = y_T (spec 004 §4.1)."""

    name = "persistence"

    def fit(self, y, *, usable=None) -> Persistence:
        self.y_, _ = _series(y, usable)
        return self

    def forecast(self, h: int) -> Forecast:
        self._fitted()
        return Forecast(np.full(_check_h(h), self.y_[-1]))


class WindowMean(_Base):
    """Mean of the last ``window`` days (spec 004 §4.1b, default 7); missing days skipped."""

    name = "window_mean"

    def __init__(self, *, window: int = 7):
        self.window = window

    def fit(self, y, *, usable=None) -> WindowMean:
        self.y_, _ = _series(y, usable)
        tail = self.y_[-int(self.window):]
        self.level_ = float(np.mean(tail[np.isfinite(tail)]))
        return self

    def forecast(self, h: int) -> Forecast:
        self._fitted()
        return Forecast(np.full(_check_h(h), self.level_))


def _ar_design(y, ok_target, p, start=None):
    """Rows t (target usable, all p lags finite) of [1, y_{t-1} .. y_{t-p}]."""
    fin = np.isfinite(y)
    n = y.size
    first = p if start is None else start
    t = np.arange(first, n)
    keep = ok_target[t].copy()
    for k in range(1, p + 1):
        keep &= fin[t - k]
    t = t[keep]
    X = np.column_stack([np.ones(t.size)] + [y[t - k] for k in range(1, p + 1)])
    return X, y[t], t


class ARLeastSquares(_Base):
    """Linear AR(p) with intercept by least squares (spec 004 §4.2).

    Parameters
    ----------
    order : int or {"cv", "aic"}, default="cv"
        The lag order, or how to choose it: ``"cv"`` = kernel CV of §3.1 (p-hat of the
        NAR), ``"aic"`` = lowest AIC over 1..H on the common sample set t >= H.
    H : int, default=6
        Upper bound for ``"cv"`` and ``"aic"``.

    Attributes
    ----------
    order_ : p used; ``coef_`` : (c, phi_1 .. phi_p); ``sigma2_`` : residual variance (ML).
    """

    name = "ar_ls"

    def __init__(self, *, order="cv", H: int = 6):
        self.order = order
        self.H = H

    def fit(self, y, *, usable=None) -> ARLeastSquares:
        y, ok = _series(y, usable)
        if self.order == "cv":
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                p = select_order_cv(y, H=self.H, usable=ok).order
        elif self.order == "aic":
            best = (np.inf, 1)
            for p_ in range(1, int(self.H) + 1):
                X, z, _ = _ar_design(y, ok, p_, start=int(self.H))
                if z.size <= p_ + 1:
                    break
                coef, *_ = np.linalg.lstsq(X, z, rcond=None)
                s2 = float(np.mean((z - X @ coef) ** 2))
                aic = z.size * np.log(max(s2, 1e-300)) + 2 * (p_ + 1)
                if aic < best[0]:
                    best = (aic, p_)
            p = best[1]
        else:
            p = int(self.order)
            if p < 1:
                raise InputError(f"AR order must be >= 1, got {self.order}")
        X, z, _ = _ar_design(y, ok, p)
        if z.size < p + 1:
            raise InputError(f"too few complete samples ({z.size}) for an AR({p}) fit")
        coef, *_ = np.linalg.lstsq(X, z, rcond=None)
        self.order_ = p
        self.coef_ = coef
        self.sigma2_ = float(np.mean((z - X @ coef) ** 2))
        self.y_ = y
        return self

    def one_step(self, lags) -> np.ndarray:
        """One-step predictions for rows of lags (y_{t-1}, .., y_{t-p})."""
        lags = np.atleast_2d(np.asarray(lags, dtype=float))
        return self.coef_[0] + lags @ self.coef_[1:]

    def forecast(self, h: int) -> Forecast:
        self._fitted()
        h = _check_h(h)
        p = self.order_
        hist = list(self.y_[-p:])
        if not np.all(np.isfinite(hist)):
            raise InputError(f"the last {p} in-sample values must be present to forecast")
        out = np.empty(h)
        for k in range(h):
            v = float(self.coef_[0] + np.dot(self.coef_[1:], hist[::-1][:p]))
            out[k] = v
            hist.append(v)
            hist = hist[-p:]
        return Forecast(out)


class ARIMAByAIC(_Base):
    """ARIMA by AIC over a grid (spec 004 §4.3), via ``statsmodels.tsa.arima.model.ARIMA``.

    Parameters
    ----------
    p_max, q_max : int, default=3, 2
    d_values : tuple, default=(0, 1)
        Grid (p, d, q) in {0..p_max} x d_values x {0..q_max}; trend ``"c"`` for d = 0,
        ``"t"`` for d = 1. Missing days enter as NaN (the state-space likelihood skips
        them). Fits that do not converge are dropped.

    Attributes
    ----------
    order_ : (p, d, q) chosen; ``aic_`` : its AIC.
    """

    name = "arima"

    def __init__(self, *, p_max: int = 3, q_max: int = 2, d_values=(0, 1)):
        self.p_max = p_max
        self.q_max = q_max
        self.d_values = d_values

    def fit(self, y, *, usable=None) -> ARIMAByAIC:
        from statsmodels.tsa.arima.model import ARIMA

        y, ok = _series(y, usable)
        yy = np.where(ok, y, np.nan)
        yy[-1] = y[-1]
        best = None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for d in self.d_values:
                for p in range(int(self.p_max) + 1):
                    for q in range(int(self.q_max) + 1):
                        try:
                            res = ARIMA(yy, order=(p, d, q), trend="c" if d == 0 else "t").fit()
                        except (ValueError, np.linalg.LinAlgError):
                            continue
                        conv = res.mle_retvals.get("converged", True) if res.mle_retvals else True
                        if not conv or not np.isfinite(res.aic):
                            continue
                        if best is None or res.aic < best[0]:
                            best = (float(res.aic), (p, d, q), res)
        if best is None:
            raise InputError("no ARIMA model of the grid converged")
        self.aic_, self.order_, self.result_ = best
        self.y_ = y
        return self

    def forecast(self, h: int) -> Forecast:
        self._fitted()
        h = _check_h(h)
        fc = self.result_.get_forecast(h)
        ci = np.asarray(fc.conf_int(alpha=0.05))
        return Forecast(np.asarray(fc.predicted_mean, dtype=float), ci[:, 0], ci[:, 1])


class PolyTrend(_Base):
    """Polynomial trend in t/T, degree 1..3 by BIC (spec 004 §4.4a); extrapolated."""

    name = "poly_trend"

    def __init__(self, *, degrees=(1, 2, 3)):
        self.degrees = degrees

    def fit(self, y, *, usable=None) -> PolyTrend:
        y, ok = _series(y, usable)
        T = y.size
        t = np.flatnonzero(ok)
        x = (t + 1) / T
        best = None
        for q in self.degrees:
            if t.size <= q + 1:
                continue
            m = PolynomialRegressor(degree=int(q), warn_extrapolation=False).fit(x, y[t])
            s2 = float(np.mean((y[t] - m.predict(x)) ** 2))
            bic = t.size * np.log(max(s2, 1e-300)) + (q + 1) * np.log(t.size)
            if best is None or bic < best[0]:
                best = (bic, int(q), m)
        if best is None:
            raise InputError("too few values for a polynomial trend")
        _, self.degree_, self.model_ = best
        self.T_ = T
        self.y_ = y
        return self

    def forecast(self, h: int) -> Forecast:
        self._fitted()
        h = _check_h(h)
        x = (self.T_ + np.arange(1, h + 1)) / self.T_
        return Forecast(self.model_.predict(x))


class ExpSaturation(_Base):
    """Exponential saturation y = a + b (1 - exp(-t/tau)) (spec 004 §4.4b; §4.4c with ``ar1=True``).

    t is the day index 0..T-1. ``scipy.optimize.least_squares`` with tau in [1, 5T],
    start a = y_1, b = y_T - y_1, tau = T/4. With ``ar1=True`` an AR(1) (no intercept)
    of the residuals is fitted and its forecast added.

    Attributes
    ----------
    a_, b_, tau_ : fitted parameters; ``phi_`` : residual AR(1) coefficient (0 without ``ar1``).
    """

    name = "exp_saturation"

    def __init__(self, *, ar1: bool = False):
        self.ar1 = ar1

    @staticmethod
    def curve(t, a, b, tau):
        return a + b * (1.0 - np.exp(-np.asarray(t, dtype=float) / tau))

    def fit(self, y, *, usable=None) -> ExpSaturation:
        y, ok = _series(y, usable)
        T = y.size
        t = np.flatnonzero(ok).astype(float)
        z = y[ok]
        if z.size < 4:
            raise InputError("too few values for an exponential-saturation fit")
        a0 = float(z[0])
        b0 = float(z[-1] - z[0])
        tau0 = min(max(T / 4.0, 1.0), 5.0 * T)
        scale = max(float(np.std(z)), 1e-12)
        res = least_squares(lambda th: (self.curve(t, *th) - z) / scale, [a0, b0, tau0],
                            bounds=([-np.inf, -np.inf, 1.0], [np.inf, np.inf, 5.0 * T]),
                            x_scale=[scale, scale, T / 4.0])
        self.a_, self.b_, self.tau_ = (float(v) for v in res.x)
        self.T_ = T
        self.y_ = y
        self.phi_ = 0.0
        self.last_resid_ = 0.0
        if self.ar1:
            r = np.full(T, np.nan)
            r[ok] = z - self.curve(t, self.a_, self.b_, self.tau_)
            pair = np.isfinite(r[1:]) & np.isfinite(r[:-1])
            den = float(np.sum(r[:-1][pair] ** 2))
            self.phi_ = float(np.sum(r[1:][pair] * r[:-1][pair]) / den) if den > 0 else 0.0
            self.last_resid_ = float(r[-1]) if np.isfinite(r[-1]) else 0.0
        return self

    def forecast(self, h: int) -> Forecast:
        self._fitted()
        h = _check_h(h)
        k = np.arange(1, h + 1)
        v = self.curve(self.T_ - 1 + k, self.a_, self.b_, self.tau_)
        return Forecast(v + self.last_resid_ * self.phi_ ** k)


class KernelNAR(_Base):
    """Recursive Nadaraya-Watson autoregression (spec 004 §4.5).

    Order p-hat and bandwidth h_p of :func:`~inertialab.learn.order_cv.select_order_cv`
    (or ``order`` given), on lags standardised with the in-sample mean and SD.
    """

    name = "kernel_nar"

    def __init__(self, *, order=None, H: int = 6, c: float = 0.5):
        self.order = order
        self.H = H
        self.c = c

    def fit(self, y, *, usable=None) -> KernelNAR:
        y, ok = _series(y, usable)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sel = select_order_cv(y, H=self.H, c=self.c, usable=ok)
        p = sel.order if self.order is None else int(self.order)
        vals = y[np.isfinite(y)]
        self.mean_ = float(np.mean(vals))
        sd = float(np.std(vals, ddof=1))
        self.sd_ = sd if sd > 0 else 1.0
        z = (y - self.mean_) / self.sd_
        t = lag_targets(np.isfinite(y), p)
        t = t[ok[t]]
        X = np.column_stack([z[t - k] for k in range(1, p + 1)])
        h = self.c * max(sel.m, 1) ** (-1.0 / (p + 4))
        self.nw_ = NadarayaWatson(bandwidth=h).fit(X, z[t])
        self.order_ = p
        self.y_ = y
        self.z_ = z
        return self

    def forecast(self, h: int) -> Forecast:
        self._fitted()
        h = _check_h(h)
        p = self.order_
        hist = list(self.z_[-p:])
        out = np.empty(h)
        for k in range(h):
            v = float(self.nw_.predict(np.asarray(hist[::-1][:p])[None, :])[0])
            out[k] = v
            hist = (hist + [v])[-p:]
        return Forecast(out * self.sd_ + self.mean_)


#: name -> factory of the default-configured baseline (spec 004 §4)
BASELINES = {
    "persistence": Persistence,
    "window_mean": WindowMean,
    "ar_ls": lambda: ARLeastSquares(order="cv"),
    "ar_aic": lambda: ARLeastSquares(order="aic"),
    "arima": ARIMAByAIC,
    "poly_trend": PolyTrend,
    "exp_saturation": ExpSaturation,
    "exp_ar1": lambda: ExpSaturation(ar1=True),
    "kernel_nar": KernelNAR,
}


def make_baseline(name: str):
    """A fresh baseline by name (keys of :data:`BASELINES`)."""
    if name not in BASELINES:
        raise InputError(f"unknown baseline {name!r} (known: {', '.join(BASELINES)})")
    return BASELINES[name]()
