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
from inertialab.export.noise_params import NoiseParams, units_comments
from inertialab.export.yaml_text import check_topic, dump_yaml

__all__ = ["openvins_doc", "openvins_imu_chain_yaml", "write_openvins_imu_chain"]


def _matrix(name: str, m, shape) -> np.ndarray:
    a = np.asarray(np.eye(shape[0]) if m is None else m, dtype=float)
    if a.shape != shape:
        raise InputError(f"argument '{name}' must be {shape[0]}x{shape[1]}, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"argument '{name}' holds NaN or infinite values")
    return a


def openvins_doc(p: NoiseParams, *, rostopic: str = "/imu0", time_offset_s: float = 0.0,
                 model: str = "kalibr", Tw=None, R_IMUtoGYRO=None, Ta=None, R_IMUtoACC=None,
                 Tg=None, T_i_b=None) -> dict:
    """The ``imu0`` mapping (see the module docstring)."""
    p.require_all("OpenVINS")
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
    imu = {"T_i_b": tib.tolist(),
           "accelerometer_noise_density": p.accel_noise_density,
           "accelerometer_random_walk": p.accel_random_walk,
           "gyroscope_noise_density": p.gyro_noise_density,
           "gyroscope_random_walk": p.gyro_random_walk,
           "rostopic": check_topic(rostopic), "time_offset": float(time_offset_s),
           "update_rate": p.rate_hz, "model": model}
    imu.update({k: v.tolist() for k, v in mats.items()})
    return {"imu0": imu}


def noise_text(p: NoiseParams, *, note=(), **opts) -> str:
    """The file text for ``p`` (``opts``: :func:`openvins_doc`)."""
    return dump_yaml(openvins_doc(p, **opts), directive="%YAML:1.0",
                     comments=["OpenVINS IMU chain (Kalibr format + intrinsics), by inertialab",
                               *units_comments(), *note, *p.bound_comments()])


def openvins_imu_chain_yaml(*, gyro_noise_density: float, gyro_random_walk: float,
                            accel_noise_density: float, accel_random_walk: float,
                            rate_hz: float, **opts) -> str:
    """The text of an OpenVINS ``kalibr_imu_chain.yaml`` (see the module docstring)."""
    return noise_text(NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                                  accel_random_walk, rate_hz), **opts)


def write_openvins_imu_chain(path, **params) -> None:
    """Write :func:`openvins_imu_chain_yaml` atomically."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, openvins_imu_chain_yaml(**params))
