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


CHUNK_UNITS = 2048
"""Units solved at once by :func:`calibrate_batch`: the solver's
working memory (residuals, Jacobians, normal matrices: ~22 KB per unit for 18 poses) is
bounded by the chunk, not by the fleet."""


def solve_units(A: np.ndarray, Rf: np.ndarray, *, max_iter: int = 100):
    """Vectorised S9 Gauss-Newton/LM for units ``A``, ``Rf`` of shape (k, m, 3).

    Returns ``(X (k, 9), stderr (k, 9), converged (k,), nit (k,), rmse (k,))``, the RMSE
    being eq. 21 against the references ``Rf``.
    """
    k_units, m = A.shape[0], A.shape[1]

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

    res = batched_gauss_newton(fun_jac, np.tile(tx.X0, (k_units, 1)), max_iter=max_iter)
    X = res.x
    ah = np.einsum("uij,umj->umi", tx.k_inverse(X[:, 6:9]), (A - X[:, None, 0:3]) / X[:, None, 3:6])
    e = np.linalg.norm(ah - Rf, axis=2)
    return X, res.stderr, res.converged, res.nit, np.sqrt(np.mean(e * e, axis=1))


def _in_range(X: np.ndarray) -> np.ndarray:
    return ((np.abs(X[:, 0:2]) <= DATASHEET["b_xy"]).all(axis=1)
            & (np.abs(X[:, 2]) <= DATASHEET["b_z"])
            & (np.abs(X[:, 3:6] - 1) <= DATASHEET["k_rel"]).all(axis=1)
            & (np.abs(X[:, 6:9]) <= DATASHEET["theta"]).all(axis=1))


def _table(names, X, se, conv, nit, rmse, rmse_limit) -> pd.DataFrame:
    in_range = _in_range(X)
    cols = {"unit_id": names}
    for j, nme in enumerate(tx.PARAM_NAMES):
        cols[nme] = X[:, j]
    for j, nme in enumerate(tx.PARAM_NAMES):
        cols[f"se_{nme}"] = se[:, j]
    cols.update(rmse_mps2=rmse, in_range=in_range,
                **{"pass": in_range & (rmse <= rmse_limit) & conv},
                converged=conv, iterations=nit)
    return pd.DataFrame(cols)


def iter_calibrate_batch(chunks, *, rmse_limit: float = 0.04, max_iter: int = 100,
                         chunk_units: int = CHUNK_UNITS):
    """Stream a fleet: ``chunks`` yields ``(unit_ids (k,), A (k, m, 3), Rf (k, m, 3))`` (record
    means and references in m/s^2, any k); yields one per-unit table (the columns of
    :class:`BatchCalibration`) per solved chunk of at most ``chunk_units`` units, so the
    memory held is that of one input chunk and one solver chunk."""
    for ids, A, Rf in chunks:
        A = np.asarray(A, dtype=float)
        Rf = np.asarray(Rf, dtype=float)
        if A.ndim != 3 or A.shape[2] != 3 or Rf.shape != A.shape or len(ids) != A.shape[0]:
            raise InputError(f"a batch chunk needs unit ids (k,) and arrays (k, m, 3); got "
                             f"{len(ids)}, {A.shape} and {Rf.shape}")
        if 3 * A.shape[1] < 9:
            raise UnderdeterminedError(f"{A.shape[1]} records per unit: at least 3 are needed")
        for c0 in range(0, A.shape[0], chunk_units):
            c1 = min(c0 + chunk_units, A.shape[0])
            X, se, conv, nit, rmse = solve_units(A[c0:c1], Rf[c0:c1], max_iter=max_iter)
            yield _table(np.asarray(ids)[c0:c1], X, se, conv, nit, rmse, rmse_limit)


def calibrate_batch(data: StaticData, *, rmse_limit: float = 0.04, max_iter: int = 100,
                    chunk_units: int = CHUNK_UNITS) -> BatchCalibration:
    """Vectorised Gauss-Newton/LM with objective S9 over all units (spec 002 §3.6, §6.4).

    Every unit must have the same number of records with references. Pass: the post-
    calibration RMSE (eq. 21) against the references is <= ``rmse_limit`` (0.04 m/s^2)
    and every estimate is inside the datasheet range. Units are solved ``chunk_units`` at
    a time (:data:`CHUNK_UNITS`); the result does not depend on the chunking.
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
    if np.array_equal(order, np.arange(order.size)):  # already grouped: views, no copies
        A, Rf = data.a.reshape(U, m, 3), data.ref.reshape(U, m, 3)
    else:
        A, Rf = data.a[order].reshape(U, m, 3), data.ref[order].reshape(U, m, 3)
    t0 = time.perf_counter()
    parts = list(iter_calibrate_batch([(names, A, Rf)], rmse_limit=rmse_limit, max_iter=max_iter,
                                      chunk_units=chunk_units))
    wall = time.perf_counter() - t0
    table = parts[0] if len(parts) == 1 else pd.concat(parts, ignore_index=True)
    X = table[list(tx.PARAM_NAMES)].to_numpy()
    return BatchCalibration(table=table, X=X, wall_s=wall,
                            yield_fraction=float(table["pass"].mean()), rmse_limit=rmse_limit)
