"""The parts of one IMU log that ``allan --imu`` fits: its warm-up left out, and whether
what remains is the same noise throughout.

* :func:`apply_warmup`: one warm-up span per log (:func:`inertialab.noise.segments.warmup.log_warmup`:
  the latest end over its axes and its temperature column where it has one; or the
  seconds given; or none), cut from the start of every axis before anything is fitted.
* :func:`axis_stationarity`: the segments test of one axis
  (:func:`inertialab.noise.segments.stationarity.check_stationarity`), on the samples the terms are
  fitted on; its measured between-segment spread widens the drift interval
  (:func:`inertialab.workflows.imu_drift.axis_drift`); a warning names an axis that is
  not stationary.
* :func:`stationarity_text`: the table's column (:mod:`inertialab.noise.terms.imu_result`, with
  the table it fills).
"""

from __future__ import annotations

import warnings

import numpy as np

from inertialab.errors import InputError
from inertialab.noise.terms.imu_result import stationarity_text

#: the settings' default: the warm-up found in the data
WARMUP_DEFAULT = "auto"


def apply_warmup(columns: dict, rate_hz: float, setting=WARMUP_DEFAULT, temperature=None):
    """``(columns, info)``: the axis columns (``{axis: (name, samples, unit)}``) with the
    log's warm-up span cut from their start, and the span with its evidence
    (:func:`inertialab.noise.segments.warmup.log_warmup`; ``temperature``: the log's temperature
    samples, judged like an axis)."""
    from inertialab.noise.segments.warmup import log_warmup

    series = {k: v[1] for k, v in columns.items()}
    if temperature is not None:
        series["temperature"] = np.asarray(temperature, dtype=float)
    setting = WARMUP_DEFAULT if setting is None else setting
    if not _is_zero(setting):
        info = log_warmup(series, rate_hz, setting=setting)
    else:
        info = {"setting": 0.0, "span_s": 0.0, "n_samples": 0, "by": {}, "from": []}
    n0 = info["n_samples"]
    if n0 > 0:
        columns = {k: (c, np.asarray(y)[n0:], u) for k, (c, y, u) in columns.items()}
    return columns, info


def _is_zero(setting) -> bool:
    try:
        return float(setting) == 0.0
    except (TypeError, ValueError):
        return False


def axis_warmup(info: dict | None, axis: str) -> dict | None:
    """The axis's own evidence from a log's warm-up ``info`` with the span the log cut
    (``excluded_s``), or None where no warm-up was judged."""
    if not info:
        return None
    own = dict(info["by"].get(axis) or {"detected": False, "warmup_s": 0.0})
    return own | {"excluded_s": info["span_s"]}


def axis_stationarity(y, rate_hz: float, column: str | None = None, path=None):
    """The segments test of one axis's fitted samples (None where they hold NaN: lost
    samples, no equal segments), with a warning naming the column (and the log
    ``path``, where several logs are analysed) when the verdict is "not stationary"."""
    where = f"{path}: " if path is not None else ""
    from inertialab.noise.segments.stationarity import check_stationarity

    y = np.asarray(y, dtype=float)
    if not np.isfinite(y).all():
        return None
    try:
        st = check_stationarity(y, rate_hz)
    except InputError as exc:  # a constant segment (a coarse quantiser that never
        # toggles there): the test cannot be read, the axis's terms still can
        from inertialab.errors import DataQualityWarning

        warnings.warn(f"{where}column '{column}': stationarity not tested ({exc})",
                      DataQualityWarning, stacklevel=3)
        return None
    if st.verdict == "not stationary":
        from inertialab.errors import DataQualityWarning

        warnings.warn(f"{where}column '{column}': not stationary (segments' Allan variances differ "
                      f"beyond their intervals at tau = {st.worst_tau_s:g} s, p = "
                      f"{st.p_value:.2g}); its drift interval is widened by the measured "
                      f"spread", DataQualityWarning, stacklevel=3)
    return st


__all__ = ["WARMUP_DEFAULT", "apply_warmup", "axis_stationarity", "axis_warmup",
           "stationarity_text"]
