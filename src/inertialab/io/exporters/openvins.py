"""OpenVINS ``kalibr_imu_chain.yaml`` with IMU intrinsics.

Grammar (OpenVINS config/*/kalibr_imu_chain.yaml, "IMU intrinsics" in its docs): an
``%YAML:1.0`` OpenCV header, then ``imu0:`` holding ``T_i_b`` (4x4), the four noise
numbers (continuous time, SI), ``rostopic``, ``time_offset`` (s), ``update_rate`` (Hz),
``model`` (``kalibr`` or ``rpng``) and the intrinsics as lists of rows:

* ``Tw``: gyroscope scale/misalignment (3x3, Kalibr's ``imu.gyroscopes.M``),
* ``R_IMUtoGYRO``: rotation IMU -> gyro frame (3x3),
* ``Ta``: accelerometer scale/misalignment (3x3, Kalibr's ``imu.accelerometers.M``),
* ``R_IMUtoACC``: rotation IMU -> accelerometer frame (3x3),
* ``Tg``: gyroscope g-sensitivity (3x3, rad/s per m/s^2; Kalibr's ``imu.gyroscopes.A``).

Defaults are the identity (and zero g-sensitivity): a calibrated IMU.
"""

from __future__ import annotations

import numpy as np

from inertialab.errors import InputError
from inertialab.io.exporters import NoiseParams, yaml_number
from inertialab.io.exporters.kalibr import _topic

__all__ = ["openvins_imu_chain_yaml", "write_openvins_imu_chain"]


def _matrix(name: str, m, shape) -> np.ndarray:
    a = np.asarray(np.eye(shape[0]) if m is None else m, dtype=float)
    if a.shape != shape:
        raise InputError(f"argument '{name}' must be {shape[0]}x{shape[1]}, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"argument '{name}' holds NaN or infinite values")
    return a


def _rows(a: np.ndarray, indent: str) -> list[str]:
    return [f"{indent}- [ {', '.join(yaml_number(v) for v in row)} ]" for row in a]


def openvins_imu_chain_yaml(*, gyro_noise_density: float, gyro_random_walk: float,
                            accel_noise_density: float, accel_random_walk: float,
                            rate_hz: float, rostopic: str = "/imu0", time_offset_s: float = 0.0,
                            model: str = "kalibr", Tw=None, R_IMUtoGYRO=None, Ta=None,
                            R_IMUtoACC=None, Tg=None, T_i_b=None) -> str:
    """The text of an OpenVINS ``kalibr_imu_chain.yaml`` (see the module docstring)."""
    p = NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                    accel_random_walk, rate_hz)
    if model not in ("kalibr", "rpng", "calibrated"):
        raise InputError(f"argument 'model' must be 'kalibr', 'rpng' or 'calibrated', got "
                         f"{model!r}")
    if not np.isfinite(float(time_offset_s)):
        raise InputError("argument 'time_offset_s' must be finite")
    mats = {"Tw": _matrix("Tw", Tw, (3, 3)), "R_IMUtoGYRO": _matrix("R_IMUtoGYRO", R_IMUtoGYRO, (3, 3)),
            "Ta": _matrix("Ta", Ta, (3, 3)), "R_IMUtoACC": _matrix("R_IMUtoACC", R_IMUtoACC, (3, 3)),
            "Tg": _matrix("Tg", np.zeros((3, 3)) if Tg is None else Tg, (3, 3))}
    for name in ("R_IMUtoGYRO", "R_IMUtoACC"):
        r = mats[name]
        if not np.allclose(r @ r.T, np.eye(3), atol=1e-6) or np.linalg.det(r) < 0:
            raise InputError(f"argument '{name}' must be a rotation matrix")
    tib = _matrix("T_i_b", T_i_b if T_i_b is not None else np.eye(4), (4, 4))
    lines = ["%YAML:1.0", "", "# OpenVINS IMU chain (Kalibr format + intrinsics), by inertialab",
             "imu0:", "  T_i_b:", *_rows(tib, "    "),
             f"  accelerometer_noise_density: {yaml_number(p.accel_noise_density)}  # m/s^2/sqrt(Hz)",
             f"  accelerometer_random_walk: {yaml_number(p.accel_random_walk)}  # m/s^3/sqrt(Hz)",
             f"  gyroscope_noise_density: {yaml_number(p.gyro_noise_density)}  # rad/s/sqrt(Hz)",
             f"  gyroscope_random_walk: {yaml_number(p.gyro_random_walk)}  # rad/s^2/sqrt(Hz)",
             f"  rostopic: {_topic(rostopic)}",
             f"  time_offset: {yaml_number(float(time_offset_s))}",
             f"  update_rate: {yaml_number(p.rate_hz)}",
             f"  model: \"{model}\""]
    for name, a in mats.items():
        lines += [f"  {name}:", *_rows(a, "    ")]
    return "\n".join(lines) + "\n"


def write_openvins_imu_chain(path, **params) -> None:
    """Write :func:`openvins_imu_chain_yaml` atomically."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, openvins_imu_chain_yaml(**params))
