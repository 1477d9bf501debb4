"""Fleet calibration: the vectorised Gauss-Newton over many units at once (spec 002 §6.4)."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from inertialab.calib.triaxial import DATASHEET
from inertialab.calib.triaxial_session import StaticData
from inertialab.errors import InputError, MissingReferenceError, UnderdeterminedError
from inertialab.regress.nlls import batched_gauss_newton
from inertialab.sensors import triaxial as tx


@dataclass(frozen=True)
class BatchCalibration:
    """Result of :func:`calibrate_batch` (``line5000``, spec 002 §6.4).

    ``table`` has one row per unit: ``unit_id``, the 9 parameters, their standard
    errors ``se_*``, ``rmse_mps2`` (eq. 21 against the fixture references),
    ``in_range``, ``pass``, ``converged``, ``iterations``.
    """

    table: pd.DataFrame
    X: np.ndarray
    wall_s: float
    yield_fraction: float
    rmse_limit: float


def calibrate_batch(data: StaticData, *, rmse_limit: float = 0.04, max_iter: int = 100) -> BatchCalibration:
    """Vectorised Gauss-Newton/LM with objective S9 over all units (spec 002 §3.6, §6.4).

    Every unit must have the same number of records with references. Pass: the post-
    calibration RMSE (eq. 21) against the references is <= ``rmse_limit`` (0.04 m/s^2)
    and every estimate is inside the datasheet range.
    """
    if data.unit_id is None:
        raise InputError("batch calibration needs a unit_id column")
    if data.ref is None or not np.all(np.isfinite(data.ref)):
        raise MissingReferenceError("batch calibration (S9) needs references for every record")
    if data.counts:
        raise InputError("batch calibration needs m/s^2 (or counts with lsb_per_g)")
    uid = np.asarray(data.unit_id)
    order = np.argsort(uid, kind="stable")
    names, counts_ = np.unique(uid[order], return_counts=True)
    if np.any(counts_ != counts_[0]):
        raise InputError("every unit needs the same number of records for the batch solver")
    U, m = names.size, int(counts_[0])
    if 3 * m < 9:
        raise UnderdeterminedError(f"{m} records per unit: at least 3 are needed")
    A = data.a[order].reshape(U, m, 3)
    Rf = data.ref[order].reshape(U, m, 3)

    def fun_jac(X, idx):
        a, r = A[idx], Rf[idx]
        b, k, th = X[:, 0:3], X[:, 3:6], X[:, 6:9]
        u = (a - b[:, None, :]) / k[:, None, :]
        Ki = tx.k_inverse(th)
        ah = np.einsum("uij,umj->umi", Ki, u)
        R = (ah - r).reshape(len(idx), -1)
        J = np.zeros((len(idx), m, 3, 9))
        for j in range(3):
            J[:, :, :, j] = -Ki[:, None, :, j] / k[:, None, None, j]
            J[:, :, :, 3 + j] = -Ki[:, None, :, j] * (u[:, :, j] / k[:, None, j])[:, :, None]
        ux, uy = u[:, :, 0], u[:, :, 1]
        J[:, :, 1, 6] = ux
        J[:, :, 2, 6] = th[:, 2:3] * ux
        J[:, :, 2, 7] = -ux
        J[:, :, 2, 8] = th[:, 0:1] * ux + uy
        return R, J.reshape(len(idx), m * 3, 9)

    t0 = time.perf_counter()
    res = batched_gauss_newton(fun_jac, np.tile(tx.X0, (U, 1)), max_iter=max_iter)
    wall = time.perf_counter() - t0
    X = res.x
    ah = np.einsum("uij,umj->umi", tx.k_inverse(X[:, 6:9]),
                   (A - X[:, None, 0:3]) / X[:, None, 3:6])
    e = np.linalg.norm(ah - Rf, axis=2)
    rmse = np.sqrt(np.mean(e * e, axis=1))
    in_range = ((np.abs(X[:, 0:2]) <= DATASHEET["b_xy"]).all(axis=1)
                & (np.abs(X[:, 2]) <= DATASHEET["b_z"])
                & (np.abs(X[:, 3:6] - 1) <= DATASHEET["k_rel"]).all(axis=1)
                & (np.abs(X[:, 6:9]) <= DATASHEET["theta"]).all(axis=1))
    ok = in_range & (rmse <= rmse_limit) & res.converged
    table = pd.DataFrame({"unit_id": names})
    for j, nme in enumerate(tx.PARAM_NAMES):
        table[nme] = X[:, j]
    for j, nme in enumerate(tx.PARAM_NAMES):
        table[f"se_{nme}"] = res.stderr[:, j]
    table["rmse_mps2"] = rmse
    table["in_range"] = in_range
    table["pass"] = ok
    table["converged"] = res.converged
    table["iterations"] = res.nit
    return BatchCalibration(table=table, X=X, wall_s=wall, yield_fraction=float(ok.mean()),
                            rmse_limit=rmse_limit)

