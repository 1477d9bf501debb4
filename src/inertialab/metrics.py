"""Error metrics shared by every study, with one meaning per name (the glossary below).

ME = maximum absolute error, AE = mean absolute error, MBE = mean signed error,
MAXE / MARE = maximum / mean absolute relative error, RMSE = root mean square error,
MaxAE in forecasts = ME. Inputs are in whatever unit the caller uses; results are in
the same unit (relative errors are plain ratios; multiply by 1e6 for ppm).

References: spec 000 §5 (ME, AE, MBE, MAXE, MARE, RMSE); spec 002 §4 eq. 21 (vector
error RMSE and SD); spec 004 §5 (fit and forecast metrics, skill vs persistence).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np


@dataclass(frozen=True)
class ErrorSummary:
    """Summary of residuals ``e = y_pred - y_true`` (units of the inputs).

    Attributes
    ----------
    me : maximum absolute error, ``max |e|``
    ae : mean absolute error, ``mean |e|``
    mbe : mean signed error, ``mean e``
    rmse : ``sqrt(mean e^2)``
    sd : sample standard deviation of ``e`` (ddof=1; nan for one sample)
    n : number of residuals
    """

    me: float
    ae: float
    mbe: float
    rmse: float
    sd: float
    n: int

    def to_dict(self) -> dict:
        return asdict(self)


def _residuals(y_true, y_pred) -> np.ndarray:
    yt = np.asarray(y_true, dtype=float)
    yp = np.asarray(y_pred, dtype=float)
    if yt.shape != yp.shape:
        raise ValueError(f"shapes differ: y_true {yt.shape}, y_pred {yp.shape}")
    if yt.size == 0:
        raise ValueError("no samples to score")
    return (yp - yt).ravel()


def rmse(y_true, y_pred) -> float:
    """Root mean square of ``y_pred - y_true``."""
    e = _residuals(y_true, y_pred)
    return float(np.sqrt(np.mean(e * e)))


def mse(y_true, y_pred) -> float:
    """Mean square of ``y_pred - y_true``."""
    e = _residuals(y_true, y_pred)
    return float(np.mean(e * e))


def max_abs_error(y_true, y_pred) -> float:
    """ME (= forecast MaxAE): ``max |y_pred - y_true|``."""
    return float(np.max(np.abs(_residuals(y_true, y_pred))))


def mean_abs_error(y_true, y_pred) -> float:
    """AE: ``mean |y_pred - y_true|``."""
    return float(np.mean(np.abs(_residuals(y_true, y_pred))))


def error_summary(y_true, y_pred) -> ErrorSummary:
    """ME, AE, MBE, RMSE, SD and n of ``y_pred - y_true``."""
    e = _residuals(y_true, y_pred)
    return ErrorSummary(
        me=float(np.max(np.abs(e))),
        ae=float(np.mean(np.abs(e))),
        mbe=float(np.mean(e)),
        rmse=float(np.sqrt(np.mean(e * e))),
        sd=float(np.std(e, ddof=1)) if e.size > 1 else float("nan"),
        n=int(e.size),
    )


@dataclass(frozen=True)
class RelativeErrorSummary:
    """MAXE and MARE: max / mean of ``|e| / |reference|`` over samples with
    ``|reference| >= min_reference`` (plain ratios; spec 000 §5 uses ppm and 0.25 g)."""

    maxe: float
    mare: float
    n: int


def relative_errors(y_true, y_pred, reference, *, min_reference: float) -> RelativeErrorSummary:
    """MAXE/MARE of ``y_pred - y_true`` relative to ``|reference|`` (spec 000 §5).

    Samples with ``|reference| < min_reference`` are left out (relative errors are
    undefined near zero input). Returns nan and n=0 when none qualifies.
    """
    e = np.abs(_residuals(y_true, y_pred))
    ref = np.abs(np.asarray(reference, dtype=float)).ravel()
    keep = ref >= min_reference
    if not np.any(keep):
        return RelativeErrorSummary(float("nan"), float("nan"), 0)
    r = e[keep] / ref[keep]
    return RelativeErrorSummary(float(np.max(r)), float(np.mean(r)), int(keep.sum()))


@dataclass(frozen=True)
class VectorErrorSummary:
    """Spec 002 §4 eq. 21: per-record vector error ``e_l = ||a_l - a_hat_l||``;
    ``rmse = sqrt(mean e_l^2)``, ``sd`` = sample SD of ``e_l``, ``mean`` = mean e_l."""

    rmse: float
    sd: float
    mean: float
    n: int


def vector_error(reference, estimate) -> VectorErrorSummary:
    """Eq. 21 of spec 002 for arrays of shape (n, 3)."""
    a = np.asarray(reference, dtype=float)
    b = np.asarray(estimate, dtype=float)
    if a.shape != b.shape or a.ndim != 2:
        raise ValueError(f"expected two (n, 3) arrays, got {a.shape} and {b.shape}")
    e = np.sqrt(np.sum((a - b) ** 2, axis=1))
    return VectorErrorSummary(
        rmse=float(np.sqrt(np.mean(e * e))),
        sd=float(np.std(e, ddof=1)) if e.size > 1 else float("nan"),
        mean=float(np.mean(e)),
        n=int(e.size),
    )


def skill_score(rmse_model: float, rmse_reference: float) -> float:
    """Spec 004 §5: ``1 - rmse_model / rmse_reference`` (positive = better than reference)."""
    if rmse_reference == 0:
        return float("nan")
    return float(1.0 - rmse_model / rmse_reference)
