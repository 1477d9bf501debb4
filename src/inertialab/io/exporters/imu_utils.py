"""VINS-Mono / imu_utils noise parameters (``acc_n acc_w gyr_n gyr_w``).

Two documented shapes:

* :func:`vins_imu_yaml`: the IMU block of a VINS-Mono / VINS-Fusion config (OpenCV
  FileStorage YAML, first line ``%YAML:1.0``): ``acc_n``, ``gyr_n`` (white-noise
  densities), ``acc_w``, ``gyr_w`` (bias random walks), ``g_norm`` (m/s^2);
* :func:`imu_utils_yaml`: the result file imu_utils (gaowenliang/imu_utils) writes,
  ``type: IMU``, ``name``, ``Gyr``/``Acc`` with ``unit`` and ``avg-axis`` holding
  ``gyr_n gyr_w`` / ``acc_n acc_w``, plus ``x-axis`` ... when per-axis values are given.

The numbers are the continuous-time SI values of :mod:`inertialab.io.exporters`.
"""

from __future__ import annotations

import math

from inertialab.errors import InputError
from inertialab.io.exporters import NoiseParams, yaml_number

__all__ = ["imu_utils_yaml", "vins_imu_yaml", "write_imu_utils", "write_vins_imu"]


def vins_imu_yaml(*, gyro_noise_density: float, gyro_random_walk: float,
                  accel_noise_density: float, accel_random_walk: float, rate_hz: float,
                  g_norm: float = 9.80665, imu_topic: str = "/imu0") -> str:
    """The IMU parameter block of a VINS-Mono config (``%YAML:1.0`` first line)."""
    p = NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                    accel_random_walk, rate_hz)
    if not (isinstance(g_norm, (int, float)) and math.isfinite(g_norm) and 1.0 < g_norm < 100.0):
        raise InputError(f"argument 'g_norm' must be a gravity in m/s^2, got {g_norm!r}")
    return "\n".join([
        "%YAML:1.0",
        "# IMU noise for VINS-Mono / VINS-Fusion (continuous time, SI units), by inertialab",
        f"imu_topic: \"{_plain(imu_topic)}\"",
        f"acc_n: {yaml_number(p.accel_noise_density)}   # accelerometer noise density, "
        "m/s^2/sqrt(Hz)",
        f"gyr_n: {yaml_number(p.gyro_noise_density)}   # gyroscope noise density, rad/s/sqrt(Hz)",
        f"acc_w: {yaml_number(p.accel_random_walk)}   # accelerometer bias random walk, "
        "m/s^3/sqrt(Hz)",
        f"gyr_w: {yaml_number(p.gyro_random_walk)}   # gyroscope bias random walk, "
        "rad/s^2/sqrt(Hz)",
        f"g_norm: {yaml_number(float(g_norm))}   # gravity magnitude, m/s^2",
        f"# IMU rate {yaml_number(p.rate_hz)} Hz",
        "",
    ])


def _plain(t: str) -> str:
    t = str(t)
    if any(c in t for c in "\n\r\"\\") or not t:
        raise InputError(f"name must be plain text without quotes or newlines, got {t!r}")
    return t


def imu_utils_yaml(*, gyro_noise_density: float, gyro_random_walk: float,
                   accel_noise_density: float, accel_random_walk: float, rate_hz: float,
                   name: str = "imu", per_axis: dict | None = None) -> str:
    """imu_utils' result file. ``per_axis`` optionally maps ``"x"|"y"|"z"`` to
    ``{"gyr_n", "gyr_w", "acc_n", "acc_w"}`` (same units)."""
    p = NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                    accel_random_walk, rate_hz)
    lines = ["%YAML:1.0", "---", "type: IMU", f"name: \"{_plain(name)}\"",
             f"rate_hz: {yaml_number(p.rate_hz)}"]
    for block, unit, keys, vals in (
            ("Gyr", "rad/s", ("gyr_n", "gyr_w"), (p.gyro_noise_density, p.gyro_random_walk)),
            ("Acc", "m/s^2", ("acc_n", "acc_w"), (p.accel_noise_density, p.accel_random_walk))):
        lines += [f"{block}:", f"   unit: \" {unit}\"", "   avg-axis:"]
        lines += [f"      {k}: {yaml_number(v)}" for k, v in zip(keys, vals)]
        for ax in ("x", "y", "z"):
            if per_axis and ax in per_axis:
                lines.append(f"   {ax}-axis:")
                for k in keys:
                    v = per_axis[ax][k]
                    if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                        raise InputError(f"per-axis {ax} {k} must be finite and positive, "
                                         f"got {v!r}")
                    lines.append(f"      {k}: {yaml_number(float(v))}")
    return "\n".join(lines) + "\n"


def write_vins_imu(path, **params) -> None:
    """Write :func:`vins_imu_yaml` atomically."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, vins_imu_yaml(**params))


def write_imu_utils(path, **params) -> None:
    """Write :func:`imu_utils_yaml` atomically."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, imu_utils_yaml(**params))
