"""Monitoring of a series and its forecasts (spec 004 §2.2 item 5, §9): a Hampel outlier
screen, first-passage re-calibration from simulated forecast paths, and two-sided CUSUM
alarms on one-step residuals. Plain arrays in and out; general, not tied to a sensor.
"""

from __future__ import annotations

import numpy as np

__all__ = ["cusum_alarms", "first_passage", "hampel_flags"]


def hampel_flags(values, observed, segment, half=3, k=5.0) -> np.ndarray:
    """Spec 004 §2.2 item 5: flag step d where |y_d - median(y_{d-3..d+3})| > k * sigma,
    sigma = 1.4826 * MAD of these deviations over the segment.

    Parameters
    ----------
    values : (n,) series (NaN where missing)
    observed : (n,) bool, steps that carry a measurement
    segment : (n,) int, segment number per step (-1: missing); windows and the MAD are
        taken within one segment, over its observed steps
    half : window half-width in steps, default=3
    k : threshold in robust SDs, default=5

    Returns
    -------
    (n,) bool, True where flagged.
    """
    flag = np.zeros(values.size, dtype=bool)
    for s in np.unique(segment[segment >= 0]):
        idx = np.flatnonzero((segment == s) & observed)
        if idx.size < 2 * half + 1:
            continue
        y = values[idx]
        dev = np.empty(idx.size)
        for j, i in enumerate(idx):
            win = (idx >= i - half) & (idx <= i + half)
            dev[j] = y[j] - np.median(y[win])
        sig = 1.4826 * np.median(np.abs(dev - np.median(dev)))
        if sig > 0:
            flag[idx[np.abs(dev) > k * sig]] = True
    return flag


def first_passage(paths: np.ndarray, y_cal: float, tol: float, *, quantile: float = 0.1):
    """First-passage re-calibration step (spec 004 §9).

    t* = min{k : |path_k - y_cal| > tol} per path (inf when never within the horizon);
    returns ``(k, t_star)`` with ``k`` the ``quantile`` of t* (an int step, or None when
    that quantile lies beyond the horizon) and the per-path t* array.
    """
    paths = np.atleast_2d(np.asarray(paths, dtype=float))
    out = np.abs(paths - y_cal) > tol
    any_ = out.any(axis=1)
    t_star = np.where(any_, np.argmax(out, axis=1) + 1, np.inf).astype(float)
    q = float(np.quantile(t_star, quantile, method="inverted_cdf"))
    return (None if not np.isfinite(q) else int(q)), t_star


def cusum_alarms(resid, *, k: float = 0.5, h: float = 5.0) -> np.ndarray:
    """Two-sided tabular CUSUM on robustly standardised one-step residuals (spec 004 §9).

    z = (e - median e) / (1.4826 MAD e); S+ = max(0, S+ + z - k), S- = max(0, S- - z - k);
    an alarm is raised where either exceeds ``h`` and both sums restart from 0.
    Returns the indices (into ``resid``) of the alarms. Defaults k = 0.5, h = 5
    (in-control average run length of the two-sided scheme ≈ 465 samples).
    """
    e = np.asarray(resid, dtype=float)
    if e.size == 0:
        return np.zeros(0, dtype=int)
    med = float(np.median(e))
    sig = 1.4826 * float(np.median(np.abs(e - med)))
    if not sig > 0:
        return np.zeros(0, dtype=int)
    z = (e - med) / sig
    sp = sm = 0.0
    out = []
    for i, v in enumerate(z):
        sp = max(0.0, sp + v - k)
        sm = max(0.0, sm - v - k)
        if sp > h or sm > h:
            out.append(i)
            sp = sm = 0.0
    return np.asarray(out, dtype=int)
