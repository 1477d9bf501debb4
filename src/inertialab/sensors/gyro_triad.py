"""Gyro-triad calibration by integrating the rate between static intervals (spec 002 §7.3,
after Tedaldi et al.'s imu_tk).

Model: ``omega_hat = M_g (omega_raw - b_g)`` with M_g a general 3x3 matrix (three
scales and six misalignments relative to the calibrated accelerometer frame). The
bias b_g is the mean gyro output over the initial rest (Earth rate ignored),
optionally refined as three more unknowns. For each pair of consecutive static
intervals j, j+1 the body rotation C_j (body j+1 -> body j) is the product of
``Exp(omega_hat dt)`` over the samples from the last sample of interval j to the first
of j+1 (trapezoidal rate per step); the residual is ``C_j^T v_j - v_{j+1}`` with
``v_j`` the unit gravity direction measured by the calibrated accelerometer. The
accelerometer is calibrated first.

The rotation products are batched over all pairs (one loop over the longest motion,
numpy matmuls across pairs) and solved with :func:`inertialab.regress.nlls.levenberg_marquardt`
(finite-difference Jacobian; scipy's MINPACK). No library offers this residual, so
it is written here.

References
----------
Spec 002 §7.3. Tedaldi, Pretto & Menegatti, ICRA 2014.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from inertialab.errors import InputError, NonIdentifiableWarning, UnderdeterminedError
from inertialab.io.timestamps import stamps_rate_hz
from inertialab.regress.nlls import levenberg_marquardt
from inertialab.sensors.triaxial import rotation

COND_WARN = 1e8
"""cond(J^T J) above which the motion schedule is flagged (spec 002 §7.3)."""


@dataclass(frozen=True)
class GyroCalibration:
    """Result of :func:`calibrate_gyro`.

    Attributes
    ----------
    matrix : ndarray (3, 3)
        M_g, maps ``raw - bias`` to rad/s in the calibrated accelerometer frame.
    bias : ndarray (3,)
        b_g in the raw gyro unit.
    stderr_matrix : ndarray (3, 3) or None
    stderr_bias : ndarray (3,) or None
        Standard errors (bias ones only when refined).
    residual_rms : float
        RMS of the direction residuals (dimensionless, ~ rad).
    cond : float
        cond(J^T J) of the fit.
    n_pairs : int
        Motions (pairs of consecutive static intervals) used.
    nfev : int
    refine_bias : bool
    """

    matrix: np.ndarray
    bias: np.ndarray
    stderr_matrix: np.ndarray | None
    stderr_bias: np.ndarray | None
    residual_rms: float
    cond: float
    n_pairs: int
    nfev: int
    refine_bias: bool

    def apply(self, raw) -> np.ndarray:
        """Calibrated rates ``M_g (raw - b_g)`` in rad/s, for raw of shape (n, 3)."""
        return (np.asarray(raw, dtype=float) - self.bias) @ self.matrix.T


def _pairs_rates(gyro, start, stop):
    """Pad the raw gyro samples of each motion into (P, S+1, 3) plus a validity mask."""
    seg = [(int(stop[j] - 1), int(start[j + 1])) for j in range(len(start) - 1)]
    lens = [b - a for a, b in seg]
    S = max(lens)
    P = len(seg)
    W = np.zeros((P, S + 1, 3))
    mask = np.zeros((P, S), dtype=bool)
    for p, (a, b) in enumerate(seg):
        W[p, : b - a + 1] = gyro[a:b + 1]
        mask[p, : b - a] = True
    return W, mask


def integrate_pairs(omega_hat_pad, mask, dt: float) -> np.ndarray:
    """Rotation C_p = prod_k Exp(0.5 (w_k + w_{k+1}) dt) for each padded motion: (P, 3, 3)."""
    mid = 0.5 * (omega_hat_pad[:, :-1] + omega_hat_pad[:, 1:]) * dt
    mid = np.where(mask[:, :, None], mid, 0.0)
    R = rotation(mid)  # (P, S, 3, 3), all steps at once
    # ordered product R_0 R_1 ... R_{S-1} by pairwise reduction (log2 S batched matmuls)
    while R.shape[1] > 1:
        if R.shape[1] % 2:
            R = np.concatenate([R, np.broadcast_to(np.eye(3), (R.shape[0], 1, 3, 3))], axis=1)
        R = R[:, 0::2] @ R[:, 1::2]
    return R[:, 0]


def calibrate_gyro(t, gyro, start, stop, directions, *, bias=None, matrix0=None,
                   refine_bias: bool = False, rest_index: int = 0,
                   dt: float | None = None) -> GyroCalibration:
    """Calibrate a gyro triad from the motions between static intervals (spec 002 §7.3).

    Parameters
    ----------
    t : array (N,)
        Sample times, s (the samples are taken on a uniform grid of step ``dt``).
    gyro : array (N, 3)
        Raw gyro samples (rad/s, or counts).
    start, stop : array (m,) int
        Static intervals as sample ranges ``[start, stop)`` in time order.
    directions : array (m, 3)
        Gravity direction in each interval from the *calibrated* accelerometer
        (normalised here).
    bias : array (3,), optional
        Initial gyro bias; default the mean over interval ``rest_index`` (the initial rest).
    matrix0 : array (3, 3), optional
        Start for M_g: identity for rad/s, ``diag(1/gyro_lsb_per_rps)`` for counts
        (required there).
    refine_bias : bool, default False
        Estimate b_g in the LM as three more unknowns (9 + 3).
    dt : float, optional
        Sample interval, s: the record's (``record.timebase.tau0_s``); default the one
        the stamps give (:func:`inertialab.io.timestamps.stamps_rate_hz`).

    Raises
    ------
    UnderdeterminedError
        Fewer than 5 motions (each gives two independent equations; 9 or 12 unknowns).
    """
    t = np.asarray(t, dtype=float)
    g = np.asarray(gyro, dtype=float)
    start = np.asarray(start, dtype=int)
    stop = np.asarray(stop, dtype=int)
    v = np.asarray(directions, dtype=float)
    if g.shape != (t.size, 3):
        raise InputError(f"gyro samples must have shape ({t.size}, 3), got {g.shape}")
    m = start.size
    if v.shape != (m, 3) or stop.size != m:
        raise InputError("one direction and one [start, stop) range per static interval needed")
    npar = 12 if refine_bias else 9
    if 2 * (m - 1) < npar + 1:
        raise UnderdeterminedError(
            f"gyro calibration needs at least {npar // 2 + 1} motions between static intervals "
            f"(2 equations each, {npar} unknowns); got {max(m - 1, 0)}")
    v = v / np.linalg.norm(v, axis=1)[:, None]
    dt = 1.0 / stamps_rate_hz(t) if dt is None else float(dt)
    b0 = g[start[rest_index]:stop[rest_index]].mean(axis=0) if bias is None else np.asarray(bias, float)
    M0 = np.eye(3) if matrix0 is None else np.asarray(matrix0, dtype=float)
    W, mask = _pairs_rates(g, start, stop)

    def unpack(p):
        M = p[:9].reshape(3, 3)
        b = p[9:12] if refine_bias else b0
        return M, b

    def resid(p):
        M, b = unpack(p)
        C = integrate_pairs((W - b) @ M.T, mask, dt)
        pred = np.einsum("pji,pj->pi", C, v[:-1])  # C^T v_j
        return (pred - v[1:]).ravel()

    # scale-free parameterisation: M = M0-relative so that finite differences are well scaled
    x0 = np.r_[M0.ravel(), b0] if refine_bias else M0.ravel()
    scale = np.r_[np.full(9, np.max(np.abs(M0))),
                  np.full(3, max(np.max(np.abs(b0)), 1e-3 / np.max(np.abs(M0))))] \
        if refine_bias else np.full(9, np.max(np.abs(M0)))

    def resid_scaled(z):
        return resid(z * scale)

    res = levenberg_marquardt(resid_scaled, x0 / scale, jac="2-point", tol=1e-12)
    p = res.x * scale
    M, b = unpack(p)
    cond = res.cond
    if not np.isfinite(cond) or cond > COND_WARN:
        warnings.warn(
            f"gyro calibration is poorly conditioned (cond(J^T J) = {cond:.3g} > 1e8): the motions "
            "do not turn about all three body axes; add turns about the missing axis",
            NonIdentifiableWarning, stacklevel=2)
    se_M = se_b = None
    if res.stderr is not None:
        se = res.stderr * scale
        se_M = se[:9].reshape(3, 3)
        se_b = se[9:12] if refine_bias else None
    r = res.residuals
    return GyroCalibration(matrix=M, bias=np.asarray(b, dtype=float).copy(), stderr_matrix=se_M,
                           stderr_bias=se_b, residual_rms=float(np.sqrt(np.mean(r * r))),
                           cond=float(cond), n_pairs=m - 1, nfev=res.nfev,
                           refine_bias=refine_bias)
