"""The initial-rest requirement of a raw accelerometer log, in one place.

A raw log calibrated by its static intervals (Tedaldi, Pretto & Menegatti, "A robust and
easy to implement method for IMU calibration without external equipments", ICRA 2014;
the detector of :mod:`inertialab.noise.segments.static_intervals`) takes its noise floor from
the first ``t_init_s`` seconds, so the log must start with the sensor at rest. The
statistic is the centred moving variance over ``window_s`` summed over the three axes,
``s(t) = var_x + var_y + var_z`` (any unit, raw counts too: the test is a ratio); its
floor ``s0`` is the median of ``s`` over the initial rest, and more than 5 % of the
initial samples above ``3 s0`` means the log does not start at rest.

The detector and ``inertialab validate FILE --kind triaxial``
(:mod:`inertialab.workflows.preflight`) both call :func:`initial_rest`, so they cannot
disagree and give the same one-line error.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.io.timestamps import stamps_rate_hz

__all__ = ["InitialRest", "initial_rest", "moving_variance"]

#: Share of the initial samples allowed above ``3 s0`` (more: the log does not start at rest).
MOVING_SHARE = 0.05


def moving_variance(x, window: int) -> np.ndarray:
    """Centred moving variance (ddof=0) of each column of ``x`` (N, c) over ``window``
    samples; windows are truncated at the ends of the record. Pandas' rolling window is a
    numerically stable online algorithm: raw counts with a 32 768 offset would lose
    digits in a naive sum of squares."""
    x = np.asarray(x, dtype=float)
    if x.ndim == 1:
        x = x[:, None]
    w = max(int(window), 1)
    df = pd.DataFrame(x - np.median(x, axis=0))
    return df.rolling(w, center=True, min_periods=1).var(ddof=0).to_numpy()


@dataclass(frozen=True)
class InitialRest:
    """The moving-variance statistic ``s`` (N,) in the data unit squared, the initial
    rest's samples ``init`` (N,) bool, its floor ``s0`` and the sample rate ``fs`` (Hz)."""

    s: np.ndarray
    init: np.ndarray
    s0: float
    fs: float


def initial_rest(t, acc, *, window_s: float = 1.0, t_init_s: float = 10.0,
                 check: bool = True, path=None, rate_hz: float | None = None) -> InitialRest:
    """The statistic and floor of the initial rest of a raw log (module docstring).

    ``t`` (N,) strictly increasing seconds, ``acc`` (N, 3) any unit. ``rate_hz``: the
    record's sample rate (``record.timebase.rate_hz``), which sizes the window; default
    the rate the stamps give (:func:`inertialab.io.timestamps.stamps_rate_hz`). With
    ``check``, a log that does not start at rest is an :class:`InputError` naming ``path``.
    """
    t = np.asarray(t, dtype=float)
    fs = stamps_rate_hz(t) if rate_hz is None else float(rate_hz)
    w = max(int(round(window_s * fs)), 2)
    s = moving_variance(acc, w).sum(axis=1)
    init = t < t[0] + t_init_s
    s0 = float(np.median(s[init]))
    if check:
        if s0 <= 0:
            s0 = float(np.finfo(float).tiny)
        if np.mean(s[init] > 3.0 * s0) > MOVING_SHARE:
            raise InputError(
                f"no initial rest: more than 5 % of the first {t_init_s:g} s move; the log must "
                "start with the sensor at rest (or shorten argument 't_init_s')", path=path)
    return InitialRest(s=s, init=init, s0=s0, fs=fs)
