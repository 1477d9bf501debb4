"""VINS-Mono / imu_utils noise parameters (``acc_n acc_w gyr_n gyr_w``).

Two documented shapes:

* :func:`vins_imu_yaml`: the IMU block of a VINS-Mono / VINS-Fusion config (OpenCV
  FileStorage YAML, first line ``%YAML:1.0``): ``acc_n``, ``gyr_n`` (white-noise
  densities), ``acc_w``, ``gyr_w`` (bias random walks), ``g_norm`` (m/s^2);
* :func:`imu_utils_yaml`: the result file imu_utils (gaowenliang/imu_utils) writes,
  ``type: IMU``, ``name``, ``Gyr``/``Acc`` with ``unit`` and ``avg-axis`` holding
  ``gyr_n gyr_w`` / ``acc_n acc_w``, plus ``x-axis`` ... when per-axis values are given.

The numbers are the continuous-time SI values of :mod:`inertialab.export.noise_params`.
"""

from __future__ import annotations

import math

from inertialab.errors import InputError
from inertialab.export.noise_params import NoiseParams, units_comments
from inertialab.export.yaml_text import check_topic, dump_yaml

__all__ = ["imu_utils_yaml", "vins_imu_yaml", "write_imu_utils", "write_vins_imu"]


def _g_norm(g_norm) -> float:
    if not (isinstance(g_norm, (int, float)) and math.isfinite(g_norm) and 1.0 < g_norm < 100.0):
        raise InputError(f"argument 'g_norm' must be a gravity in m/s^2, got {g_norm!r}")
    return float(g_norm)


def vins_text(p: NoiseParams, *, g_norm: float = 9.80665, imu_topic: str = "/imu0",
              note=()) -> str:
    """The IMU block of a VINS-Mono config for ``p``."""
    p.require_all("VINS")
    doc = {"imu_topic": check_topic(imu_topic, "imu_topic"),
           "acc_n": p.accel_noise_density, "gyr_n": p.gyro_noise_density,
           "acc_w": p.accel_random_walk, "gyr_w": p.gyro_random_walk, "g_norm": _g_norm(g_norm)}
    return dump_yaml(doc, directive="%YAML:1.0", comments=[
        "IMU noise for VINS-Mono / VINS-Fusion, by inertialab: acc_n, gyr_n noise densities",
        "(m/s^2/sqrt(Hz), rad/s/sqrt(Hz)); acc_w, gyr_w bias random walks (m/s^3/sqrt(Hz),",
        "rad/s^2/sqrt(Hz)); g_norm gravity magnitude, m/s^2.", *units_comments(),
        f"IMU rate {p.rate_hz!r} Hz", *note, *p.bound_comments()])


def vins_imu_yaml(*, gyro_noise_density: float, gyro_random_walk: float,
                  accel_noise_density: float, accel_random_walk: float, rate_hz: float,
                  g_norm: float = 9.80665, imu_topic: str = "/imu0") -> str:
    """The IMU parameter block of a VINS-Mono config (``%YAML:1.0`` first line)."""
    return vins_text(NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                                 accel_random_walk, rate_hz), g_norm=g_norm, imu_topic=imu_topic)


def _axis_value(ax, k, v) -> float:
    if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
        raise InputError(f"per-axis {ax} {k} must be finite and positive, got {v!r}")
    return float(v)


def imu_utils_text(p: NoiseParams, *, name: str = "imu", per_axis: dict | None = None,
                   note=()) -> str:
    """imu_utils' result file for ``p`` (``per_axis``: see :func:`imu_utils_yaml`)."""
    p.require_all("imu_utils")
    if not str(name) or len(str(name)) > 256:
        raise InputError("argument 'name' must be a non-empty name of at most 256 characters")
    doc = {"type": "IMU", "name": str(name), "rate_hz": p.rate_hz}
    for block, unit, keys, vals in (
            ("Gyr", "rad/s", ("gyr_n", "gyr_w"), (p.gyro_noise_density, p.gyro_random_walk)),
            ("Acc", "m/s^2", ("acc_n", "acc_w"), (p.accel_noise_density, p.accel_random_walk))):
        b = {"unit": f" {unit}", "avg-axis": dict(zip(keys, vals))}
        for ax in ("x", "y", "z"):
            if per_axis and ax in per_axis:
                b[f"{ax}-axis"] = {k: _axis_value(ax, k, per_axis[ax][k]) for k in keys}
        doc[block] = b
    text = dump_yaml(doc, comments=["imu_utils result format, by inertialab", *units_comments(),
                                    *note, *p.bound_comments()])
    return "%YAML:1.0\n---\n" + text


def imu_utils_yaml(*, gyro_noise_density: float, gyro_random_walk: float,
                   accel_noise_density: float, accel_random_walk: float, rate_hz: float,
                   name: str = "imu", per_axis: dict | None = None) -> str:
    """imu_utils' result file. ``per_axis`` optionally maps ``"x"|"y"|"z"`` to
    ``{"gyr_n", "gyr_w", "acc_n", "acc_w"}`` (same units)."""
    return imu_utils_text(NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                                      accel_random_walk, rate_hz), name=name, per_axis=per_axis)


def write_vins_imu(path, **params) -> None:
    """Write :func:`vins_imu_yaml` atomically."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, vins_imu_yaml(**params))


def write_imu_utils(path, **params) -> None:
    """Write :func:`imu_utils_yaml` atomically."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, imu_utils_yaml(**params))

