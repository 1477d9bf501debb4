"""Kalibr's files, one writer: the IMU noise configuration ``imu.yaml`` and the
``scale-misalignment`` IMU intrinsics.

**Noise** (:func:`kalibr_imu_yaml`; Kalibr wiki, "YAML formats", IMU configuration): a
flat mapping ``accelerometer_noise_density``, ``accelerometer_random_walk``,
``gyroscope_noise_density``, ``gyroscope_random_walk`` (continuous time, SI),
``rostopic`` and ``update_rate`` (Hz).

**Intrinsics** (:func:`to_kalibr`, :func:`write_kalibr`): the ``imu0`` block that
``kalibr_calibrate_imu_camera --imu-models scale-misalignment`` writes::

    accel:  alpha = M_a a_i + b_a               (M_a lower-triangular)
    gyro:   omega_m = M_g C_gyro_i w_i + A C_gyro_i a_i + b_g   (M_g lower-triangular)

in m/s^2 and rad/s, in Kalibr's IMU frame i (the accelerometer's: x along its x axis,
y in its x-y plane). Kalibr estimates the biases online, so they are not in the block
(they are written as comments). Ours, raw in physical units u = alpha/s_a:
``a = M (u - b)`` -> ``alpha = s_a T a + s_a b``, T = M^-1 = L Q (LQ): ``M_a = s_a L`` and
``a_i = Q a``; the gyro ``s_g T_g Q^T = L_g Q_g``: ``M_g = L_g``, ``C_gyro_i = Q_g``,
``A = s_g K_ga Q^T Q_g^T``.
"""

from __future__ import annotations

import numpy as np

from inertialab.export.noise_params import NoiseParams, units_comments
from inertialab.export.triad import accel_T, gyro_T, refuse_flagged, si_factor
from inertialab.export.yaml_text import check_topic, dump_yaml

__all__ = ["kalibr_imu_yaml", "kalibr_noise_doc", "to_kalibr", "write_kalibr",
           "write_kalibr_imu"]


def kalibr_noise_doc(p: NoiseParams, *, rostopic: str = "/imu0") -> dict:
    """The ``imu.yaml`` mapping of ``p``."""
    return {"accelerometer_noise_density": p.accel_noise_density,
            "accelerometer_random_walk": p.accel_random_walk,
            "gyroscope_noise_density": p.gyro_noise_density,
            "gyroscope_random_walk": p.gyro_random_walk,
            "rostopic": check_topic(rostopic),
            "update_rate": p.rate_hz}


def noise_text(p: NoiseParams, *, rostopic: str = "/imu0", note=()) -> str:
    """The text of ``imu.yaml`` for ``p`` (head comments: convention, ``note``, bounds)."""
    return dump_yaml(kalibr_noise_doc(p, rostopic=rostopic),
                     comments=["Kalibr IMU noise model, written by inertialab", *units_comments(),
                               *note, *p.bound_comments()])


def kalibr_imu_yaml(*, gyro_noise_density: float, gyro_random_walk: float,
                    accel_noise_density: float, accel_random_walk: float, rate_hz: float,
                    rostopic: str = "/imu0", gyro_random_walk_bound: bool = False,
                    accel_random_walk_bound: bool = False) -> str:
    """The text of a Kalibr ``imu.yaml`` (units: :mod:`inertialab.export.noise_params`)."""
    return noise_text(NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                                  accel_random_walk, rate_hz, gyro_random_walk_bound,
                                  accel_random_walk_bound), rostopic=rostopic)


def write_kalibr_imu(path, **params) -> None:
    """Write :func:`kalibr_imu_yaml` to ``path`` atomically."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, kalibr_imu_yaml(**params))


# ----------------------------------------------------------------- intrinsics

def _lq(T):
    q, r = np.linalg.qr(T.T)
    L, Q = r.T, q.T
    s = np.sign(np.diag(L))
    return L * s[None, :], s[:, None] * Q


def to_kalibr(model, *, force: bool = False) -> dict:
    """The ``imu0`` dict of a triaxial calibration (plus the biases, for the comments)."""
    refuse_flagged(model, force)
    g = float(model.g_local)
    T_a, b_a = accel_T(model)
    s_a = si_factor(model.raw_unit, g=g)
    L, Q = _lq(s_a * T_a)
    out = {"model": "scale-misalignment", "accelerometers": {"M": L.tolist()}}
    biases = {"accelerometer_bias_mps2": (s_a * b_a).tolist()}
    if model.gyro is not None:
        T_g, b_g, K_ga = gyro_T(model)
        s_g = si_factor(model.gyro["raw_unit"], g=g)
        Lg, Qg = _lq(s_g * T_g @ Q.T)
        out["gyroscopes"] = {"M": Lg.tolist(), "A": (s_g * K_ga @ Q.T @ Qg.T).tolist(),
                             "C_gyro_i": Qg.tolist()}
        biases["gyroscope_bias_rps"] = (s_g * b_g).tolist()
    return {"imu0": out, "biases": biases, "C_i_ours": Q.tolist()}


def write_kalibr(model, path, **kw) -> dict:
    """Write the intrinsics YAML; returns :func:`to_kalibr`'s dict."""
    from inertialab.io.writers import atomic_write_text

    d = to_kalibr(model, **kw)
    head = [f"Kalibr scale-misalignment IMU intrinsics, written by inertialab "
            f"(triaxial-calibration, method {model.method})",
            "biases (Kalibr estimates them online; here for reference):",
            *(f"  {k}: {v}" for k, v in d["biases"].items()),
            f"  C_i_ours (our output frame -> Kalibr's imu frame): {d['C_i_ours']}"]
    atomic_write_text(path, dump_yaml({"imu0": d["imu0"]}, comments=head))
    return d
