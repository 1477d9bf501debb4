"""Noise parameters of a six-axis analysis to the file of each tool: one function,
:func:`export_noise`, for every target of :data:`inertialab.io.exporters.EXPORTERS`
of kind ``noise``.

The analysis (:class:`inertialab.workflows.imu_noise.IMUNoise`, a floor above) is read
through its attributes only: ``rate_hz`` and ``axes``, each with ``axis``, ``kind``
(``gyro``/``accel``), ``noise_density``, ``random_walk``, ``random_walk_bound`` and
``random_walk_t_s`` (continuous time, SI). Each sensor's value is the largest of its
three axes, the conservative choice for an estimator that takes one number; a random
walk that is an upper bound on any axis is marked so in the file's comments, and so is
one held by a Gauss–Markov correlation time (the value is then its random-walk density
below that time, with the time in the comment).
"""

from __future__ import annotations

import math

from inertialab.errors import InputError
from inertialab.io.exporters._common import NoiseParams

__all__ = ["noise_params", "per_axis", "span_notes"]

_PER_SENSOR_NOTE = "Each value is the largest of the sensor's three axes."


def _worst(axes, kind: str, what: str) -> float:
    vals = [float(getattr(a, what)) for a in axes if a.kind == kind]
    vals = [v for v in vals if math.isfinite(v)]
    return max(vals) if vals else math.nan


def noise_params(noise) -> NoiseParams:
    """The :class:`NoiseParams` of a six-axis analysis (module docstring); an absent
    sensor's numbers are NaN (written as null where the tool allows it)."""
    axes = tuple(getattr(noise, "axes", ()))
    if not axes:
        raise InputError("no IMU axes to export")
    return NoiseParams(
        _worst(axes, "gyro", "noise_density"), _worst(axes, "gyro", "random_walk"),
        _worst(axes, "accel", "noise_density"), _worst(axes, "accel", "random_walk"),
        float(noise.rate_hz),
        gyro_random_walk_bound=any(a.random_walk_bound for a in axes if a.kind == "gyro"),
        accel_random_walk_bound=any(a.random_walk_bound for a in axes if a.kind == "accel"),
        gyro_random_walk_t_s=_held(axes, "gyro"), accel_random_walk_t_s=_held(axes, "accel"),
        allow_missing=True)


def _held(axes, kind: str) -> tuple:
    """``((axis, t_s), ...)`` of the sensor's axes whose random walk is held by a
    Gauss–Markov correlation time ``t_s``."""
    return tuple((a.axis, float(t)) for a in axes if a.kind == kind
                 and (t := getattr(a, "random_walk_t_s", None)) is not None)


def per_axis(noise) -> list[tuple]:
    """``(axis, noise_density, random_walk, random_walk_bound)`` per analysed axis."""
    return [(a.axis, a.noise_density, a.random_walk, bool(a.random_walk_bound))
            for a in noise.axes]


def imu_utils_axes(noise) -> dict:
    """imu_utils' per-axis mapping ``{"x": {"gyr_n", "gyr_w", "acc_n", "acc_w"}}`` of the
    axes whose gyro and accelerometer were both analysed."""
    by = {a.axis: a for a in noise.axes}
    out = {}
    for ax in "xyz":
        g, a = by.get(f"g{ax}"), by.get(f"a{ax}")
        if g is not None and a is not None:
            out[ax] = {"gyr_n": g.noise_density, "gyr_w": g.random_walk,
                       "acc_n": a.noise_density, "acc_w": a.random_walk}
    return out


NOTE = (_PER_SENSOR_NOTE,)

_SENSOR = {"gyro": "gyroscope", "accel": "accelerometer"}


def span_notes(noise) -> tuple[str, ...]:
    """One line per sensor naming the axes its single value is the largest of, and the
    axes left out with their status (an axis that is not static, constant or without
    terms has no value)."""
    out = []
    for kind in ("gyro", "accel"):
        axes = [a for a in noise.axes if a.kind == kind]
        if not axes:
            continue
        used = [a.axis for a in axes if math.isfinite(float(a.noise_density))]
        left = [f"{a.axis} ({getattr(a, 'status', 'no value')})" for a in axes
                if a.axis not in used]
        text = (f"{_SENSOR[kind]} values: the largest of {', '.join(used)}" if used
                else f"{_SENSOR[kind]} values: none (no axis has noise terms)")
        if left:
            text += "; left out: " + ", ".join(left)
        out.append(text + ".")
    return tuple(out)
