"""How much the drift a log's segments predict on their own differs beyond their own uncertainty.

The drift interval (:func:`inertialab.noise.terms.drift_prediction.predicted_rms_ci`)
needs the part of the next stretch's drift that the fitted stretch's model cannot know:
a noise level that is not the same throughout. It is measured here in the quantity
predicted, the log of the drift variance ``V(t)`` at each horizon ``t``:

* the fitted stretch is cut into ``k`` equal segments (:data:`SEGMENTS`: quarters, the
  finest cut of the stationarity test; one level change at mid-log, the case halves
  would see, gives quarters a spread of ``(3/5) d^2/3`` against the halves'
  ``(1/3) d^2/2``, so halves would add nothing but two more fits);
* each segment is fitted on its own (the caller's ``fit``: the same method as the
  stretch) and predicts its own ``ln V_i(t)``, with a sampling variance read from its
  own 95 % interval (terms and local misfit):
  ``s_i^2 = (ln(high_i^2 / low_i^2) / (2 z))^2`` (infinite, and the segment left out,
  where the interval reaches zero);
* the between-segment variance beyond that sampling is the random-effects estimate of
  :func:`inertialab.noise.terms.pooled.between_var` (``max(0, s^2 - mean s_i^2)``, shrunk
  toward no spread with ``PRIOR_WEIGHT`` pseudo-segments), the largest over the
  segmentations per horizon.

It is read as what the next stretch's ``ln V`` may differ by from the fitted stretch's:
one segment differs from another by it (a level that drifts persists at least that far;
a level that scatters independently from stretch to stretch would differ less between
the means of longer stretches: neither is known from one log, so the segments' own
spread is taken as it is). Unlike the segments' Allan variances
(:func:`inertialab.noise.segments.stationarity.excess_log_var`), it needs no map from tau
to horizon and no test verdict: at 300 s, where a quarter's Allan variance is no longer
tested, the segments' fitted models still predict a drift each.

Hand-written; tested on logs whose second half carries more white noise (the spread's
closed form) and on stationary logs (tests/noise/test_drift_spread.py).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from inertialab.errors import InputError

#: segmentations fitted: quarters (module docstring)
SEGMENTS = (4,)
#: least samples of a segment to be fitted on its own
MIN_SEGMENT_SAMPLES = 1000


def prediction_log_var(ci: dict) -> np.ndarray:
    """Sampling variance of ``ln V`` per horizon read from a drift RMS interval
    (:func:`~inertialab.noise.terms.drift_prediction.predicted_rms_ci`'s ``low``,
    ``high`` and ``confidence``): ``(ln(high^2/low^2) / (2 z))^2``, infinite where
    ``low`` is 0."""
    from scipy.special import ndtri

    z = float(ndtri(0.5 + ci["confidence"] / 2.0))
    lo = np.asarray(ci["low"], dtype=float)
    hi = np.asarray(ci["high"], dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.log(hi * hi / (lo * lo)) / (2.0 * z)
    return np.where(np.isfinite(s) & (lo > 0), s * s, np.inf)


def segment_predictions(y, rate_hz: float, fit, horizons_s, bias_window_s: float, *,
                        segments=SEGMENTS) -> dict:
    """``{k: [(ln V_i, s_i^2) per segment]}``: each of ``k`` equal segments of ``y``
    fitted by ``fit(samples) -> (deviation result, NoiseTerms)`` and its drift predicted
    at ``horizons_s`` after ``bias_window_s`` (module docstring). A segment shorter than
    :data:`MIN_SEGMENT_SAMPLES` or whose fit refuses it (``InputError``) is left out;
    the segment fits' warnings are not the log's and are not shown."""
    from inertialab.noise.terms.drift_prediction import (
        misfit_log_var,
        predict_terms,
        predicted_rms_ci,
    )

    y = np.asarray(y, dtype=float)
    out: dict = {}
    for k in segments:
        n = y.size // k
        if n < MIN_SEGMENT_SAMPLES:
            continue
        rows = []
        for i in range(k):
            seg = y[i * n:(i + 1) * n]
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    dev, terms = fit(seg)
                    pred = predict_terms(terms, horizons_s, bias_window_s, rate_hz)
                    ci = predicted_rms_ci(pred, terms, extra_log_var=misfit_log_var(
                        dev, terms, horizons_s))
            except InputError:
                continue
            with np.errstate(divide="ignore"):
                rows.append((np.log(pred.rms ** 2), prediction_log_var(ci)))
        out[k] = rows
    return out


def spread_log_var(rows) -> np.ndarray:
    """Per horizon, the between-segment variance of ``ln V`` beyond the segments' own
    sampling (:func:`inertialab.noise.terms.pooled.between_var`, prior 0) of ``rows``
    (``[(ln V_i, s_i^2)]``); zeros with fewer than two segments."""
    from inertialab.noise.terms.pooled import between_var

    if len(rows) < 2:
        return np.zeros(len(rows[0][0]) if rows else 0)
    vals = np.array([r[0] for r in rows], dtype=float)
    samp = np.array([r[1] for r in rows], dtype=float)
    out = [between_var(vals[:, i], samp[:, i], 0.0) for i in range(vals.shape[1])]
    return np.asarray([v if math.isfinite(v) else 0.0 for v in out])


def segment_log_var(y, rate_hz: float, fit, horizons_s, bias_window_s: float, *,
                    segments=SEGMENTS) -> np.ndarray:
    """Variance of ``ln V`` per horizon that the log's non-stationarity adds to a drift
    prediction from ``y``: the larger over ``segments`` of :func:`spread_log_var`
    (module docstring); zeros where no segmentation has two segments fitted."""
    h = np.atleast_1d(np.asarray(horizons_s, dtype=float))
    parts = segment_predictions(y, rate_hz, fit, h, bias_window_s, segments=segments)
    out = np.zeros(h.size)
    for rows in parts.values():
        if len(rows) >= 2:
            out = np.maximum(out, spread_log_var(rows))
    return out


__all__ = ["MIN_SEGMENT_SAMPLES", "SEGMENTS", "prediction_log_var", "segment_log_var",
           "segment_predictions", "spread_log_var"]
