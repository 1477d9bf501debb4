"""Kalibr's ``scale-misalignment`` IMU intrinsics (issue 17 item 6), the ``imu0`` block
that ``kalibr_calibrate_imu_camera --imu-models scale-misalignment`` writes:

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

from inertialab.io.exporters._triad import accel_T, gyro_T, refuse_flagged, si_factor
from inertialab.io.writers import atomic_write_text


def _lq(T):
    q, r = np.linalg.qr(T.T)
    L, Q = r.T, q.T
    s = np.sign(np.diag(L))
    return L * s[None, :], s[:, None] * Q


def to_kalibr(model, *, force: bool = False) -> dict:
    """The ``imu0`` dict (plus the biases, for the comments)."""
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
    import yaml

    d = to_kalibr(model, **kw)
    head = ("# Kalibr scale-misalignment IMU intrinsics, written by inertialab "
            f"(triaxial-calibration, method {model.method})\n"
            "# biases (Kalibr estimates them online; here for reference):\n"
            + "".join(f"#   {k}: {v}\n" for k, v in d["biases"].items())
            + f"#   C_i_ours (our output frame -> Kalibr's imu frame): {d['C_i_ours']}\n")
    atomic_write_text(path, head + yaml.safe_dump({"imu0": d["imu0"]}, sort_keys=False))
    return d
