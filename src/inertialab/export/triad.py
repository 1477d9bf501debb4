"""Shared pieces of the calibration exporters (imucal, imu_tk, Kalibr intrinsics)."""

from __future__ import annotations

import numpy as np

from inertialab import units
from inertialab.errors import InputError

#: Spelling of our raw units in the exported files.
UNIT_TEXT = {"mps2": "m/s^2", "g": "g", "mg": "mg", "lsb": "a.u.", "rps": "rad/s",
             "dps": "deg/s", "dph": "deg/h"}


def accel_T(model) -> tuple[np.ndarray, np.ndarray]:
    """``(T_a, b_a)`` with raw = T_a a + b_a (a in m/s^2 in the model's output frame)."""
    M = np.asarray(model.correction_matrix, dtype=float)
    return np.linalg.inv(M), np.asarray(model.offset, dtype=float)


def gyro_T(model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(T_g, b_g, K_ga)``: raw_g = T_g omega + K_ga a + b_g (omega in rad/s)."""
    if model.gyro is None:
        raise InputError("the calibration has no gyro block; the format needs one")
    Mg = np.asarray(model.gyro["correction_matrix"], dtype=float)
    kga = model.gyro.get("g_sensitivity")
    kga = np.zeros((3, 3)) if kga is None else np.asarray(kga, dtype=float)
    return np.linalg.inv(Mg), np.asarray(model.gyro["offset"], dtype=float), kga


def si_factor(unit: str, *, g: float) -> float:
    """SI units per raw unit (counts refused: the format expects physical units)."""
    if unit == "lsb":
        raise InputError("the format needs physical raw units (m/s^2, g; rad/s, deg/s), not counts")
    return float(units.to_si(1.0, unit, g_local=g))


def refuse_flagged(model, force: bool) -> None:
    if getattr(model, "flags", None) and not force:
        raise InputError("the calibration is flagged (" + " | ".join(model.flags) + "); set "
                         "argument 'force' to export it anyway")
