"""imu_tk ``.calib`` text files (one per triad), as ``CalibratedTriad_::load`` reads
them: 21 whitespace-separated numbers, the misalignment matrix T (3x3, row-major), the scale matrix K (3x3) and the bias B (3), with the calibrated reading
``X' = T K (X - B)``.

Ours is ``a = M (u - b)``; so ``K = diag(M)``, ``T = M K^-1`` (unit diagonal, as imu_tk
writes it) and ``B = b``; the gyro likewise (rad/s). imu_tk has no g-sensitivity term: a
gyro block with a non-zero one is refused unless ``drop_g_sensitivity``.
"""

from __future__ import annotations

import numpy as np

from inertialab.errors import InputError
from inertialab.export.triad import refuse_flagged
from inertialab.io.writers import atomic_write_text


def _triad_text(M, b) -> str:
    M = np.asarray(M, dtype=float)
    K = np.diag(np.diag(M))
    T = M @ np.linalg.inv(K)

    def mat(A):
        return "\n".join(" ".join(f"{v:.17g}" for v in row) for row in A)

    return mat(T) + "\n\n" + mat(K) + "\n\n" + "\n".join(f"{v:.17g}" for v in b) + "\n\n"


def to_imu_tk(model, *, drop_g_sensitivity: bool = False, force: bool = False) -> dict:
    """``{"acc": text, "gyro": text or None}`` of a triaxial calibration."""
    refuse_flagged(model, force)
    out = {"acc": _triad_text(model.correction_matrix, model.offset), "gyro": None}
    if model.gyro is not None:
        kga = model.gyro.get("g_sensitivity")
        if kga is not None and np.any(np.asarray(kga) != 0) and not drop_g_sensitivity:
            raise InputError("imu_tk has no gyro g-sensitivity term and this calibration has one; "
                             "set argument 'drop_g_sensitivity' to export without it")
        out["gyro"] = _triad_text(model.gyro["correction_matrix"], model.gyro["offset"])
    return out


def write_imu_tk(model, stem, **kw) -> list[str]:
    """Write ``<stem>_acc.calib`` (and ``<stem>_gyro.calib``); returns the paths."""
    texts = to_imu_tk(model, **kw)
    paths = []
    for k in ("acc", "gyro"):
        if texts[k] is not None:
            p = f"{stem}_{k}.calib"
            atomic_write_text(p, texts[k])
            paths.append(p)
    return paths


def read_imu_tk(text: str):
    """Parse an imu_tk ``.calib`` text by its grammar: ``(T, K, B)``."""
    v = np.array([float(x) for x in text.split()])
    if v.size != 21:
        raise InputError(f"an imu_tk .calib file holds 21 numbers, got {v.size}")
    return v[:9].reshape(3, 3), v[9:18].reshape(3, 3), v[18:21]
