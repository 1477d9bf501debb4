"""Triaxial accelerometer error model, its objectives, residuals and Jacobians.

Spec 002 §1.2 (model) and §3.1 (objectives). The forward (sensor) model is

    a_s = S·K·R(phi)·a_r + B          S = diag(kx, ky, kz), B = (bx, by, bz)

with K lower-triangular with a unit diagonal (three non-orthogonality angles
``theta_yz, theta_zy, theta_zx`` in rad, named after Skog & Händel / Tedaldi et al.)
and R(phi) = expm([phi]x) an optional mount rotation (turntable, objective S12). The
correction (inverse) model is ``a_hat = K^-1·S^-1·(a_s - B)``; the calibration
contract of the CLI is ``calibrated = correction_matrix @ (raw - offset)`` with
``correction_matrix = K^-1·S^-1`` and ``offset = B``.

The parameter vector ``x = (bx, by, bz, kx, ky, kz, theta_yz, theta_zy, theta_zx)``
(order fixed by spec 002 §1.2) is used by every file and API; S12 appends
``phi = (phi_x, phi_y, phi_z)``.

Everything here is vectorised over records and, for the metaheuristics, over a
population of parameter vectors (``*_many`` functions take ``X`` of shape (P, 9) or
(P, 12)). Analytic Jacobians follow spec 002 §3.6; the S12 columns use the exact
left Jacobian of SO(3), so LM converges quadratically to the noise-free optimum.

References
----------
Spec 002 §1.2, §3.1, §3.6. Skog & Händel, IMEKO 2006. Tedaldi, Pretto & Menegatti,
ICRA 2014.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from inertialab.errors import InputError

PARAM_NAMES: tuple[str, ...] = (
    "bx", "by", "bz", "kx", "ky", "kz", "theta_yz", "theta_zy", "theta_zx")
PHI_NAMES: tuple[str, ...] = ("phi_x", "phi_y", "phi_z")
X0 = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
"""Nominal parameter vector (spec 002 §1.2)."""

G_PAPER = 9.8
"""The paper's gravity magnitude in m/s^2 (spec 002 §1.1); use a local value for rigs."""

OBJECTIVES = ("norm", "norm2", "scalar", "scalar12")
"""Objective names: J_H, J_H2, S9 and S12 of spec 002 §3.1."""


# --------------------------------------------------------------------------- matrices

def skew(v) -> np.ndarray:
    """Cross-product matrix [v]x of shape (..., 3, 3) for v of shape (..., 3)."""
    v = np.asarray(v, dtype=float)
    z = np.zeros(v.shape[:-1])
    return np.stack([
        np.stack([z, -v[..., 2], v[..., 1]], axis=-1),
        np.stack([v[..., 2], z, -v[..., 0]], axis=-1),
        np.stack([-v[..., 1], v[..., 0], z], axis=-1),
    ], axis=-2)


def rotation(phi) -> np.ndarray:
    """R(phi) = expm([phi]x) (Rodrigues), for phi of shape (..., 3) in rad."""
    phi = np.asarray(phi, dtype=float)
    th = np.linalg.norm(phi, axis=-1)[..., None, None]
    W = skew(phi)
    small = th < 1e-8
    ths = np.where(small, 1.0, th)
    a = np.where(small, 1.0 - th**2 / 6.0, np.sin(ths) / ths)
    b = np.where(small, 0.5 - th**2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    eye = np.broadcast_to(np.eye(3), W.shape)
    return eye + a * W + b * (W @ W)


def left_jacobian(phi) -> np.ndarray:
    """Left Jacobian of SO(3): d/d(phi) of R(phi)·r equals -[R(phi) r]x · J_l(phi)."""
    phi = np.asarray(phi, dtype=float)
    th = np.linalg.norm(phi, axis=-1)[..., None, None]
    W = skew(phi)
    small = th < 1e-6
    ths = np.where(small, 1.0, th)
    a = np.where(small, 0.5 - th**2 / 24.0, (1.0 - np.cos(ths)) / ths**2)
    b = np.where(small, 1.0 / 6.0 - th**2 / 120.0, (ths - np.sin(ths)) / ths**3)
    eye = np.broadcast_to(np.eye(3), W.shape)
    return eye + a * W + b * (W @ W)


def _split(x):
    x = np.asarray(x, dtype=float)
    if x.shape[-1] not in (9, 12):
        raise InputError(f"parameter vector must have 9 (or 12 with phi) values, got {x.shape[-1]}")
    return x[..., 0:3], x[..., 3:6], x[..., 6:9]


def k_matrix(theta) -> np.ndarray:
    """K (lower-triangular, unit diagonal) from (theta_yz, theta_zy, theta_zx), shape (..., 3, 3)."""
    t = np.asarray(theta, dtype=float)
    K = np.zeros(t.shape[:-1] + (3, 3))
    K[..., 0, 0] = K[..., 1, 1] = K[..., 2, 2] = 1.0
    K[..., 1, 0] = -t[..., 0]
    K[..., 2, 0] = t[..., 1]
    K[..., 2, 1] = -t[..., 2]
    return K


def k_inverse(theta) -> np.ndarray:
    """K^-1 in closed form (spec 002 §1.2), shape (..., 3, 3)."""
    t = np.asarray(theta, dtype=float)
    Ki = np.zeros(t.shape[:-1] + (3, 3))
    Ki[..., 0, 0] = Ki[..., 1, 1] = Ki[..., 2, 2] = 1.0
    Ki[..., 1, 0] = t[..., 0]
    Ki[..., 2, 0] = t[..., 0] * t[..., 2] - t[..., 1]
    Ki[..., 2, 1] = t[..., 2]
    return Ki


def gain_matrix(x) -> np.ndarray:
    """L = S·K (the forward gain, lower-triangular with diag k), shape (..., 3, 3)."""
    _, k, th = _split(x)
    return k[..., :, None] * k_matrix(th)


def correction_matrix(x) -> np.ndarray:
    """K^-1·S^-1: maps ``raw - offset`` to the corrected vector (spec 002 §1.2)."""
    _, k, th = _split(x)
    return k_inverse(th) / k[..., None, :]


# --------------------------------------------------------------------------- model

def forward(x, a_true, phi=None) -> np.ndarray:
    """Sensor output a_s = S·K·R(phi)·a_true + B for records ``a_true`` of shape (n, 3)."""
    b, _, _ = _split(x)
    a = np.asarray(a_true, dtype=float)
    if phi is not None:
        a = a @ rotation(phi).T
    return a @ gain_matrix(x).T + b


def correct(x, a_s) -> np.ndarray:
    """Corrected vectors a_hat = K^-1·S^-1·(a_s - B), shape (n, 3) (spec 002 eq. 8-9)."""
    b, _, _ = _split(x)
    return (np.asarray(a_s, dtype=float) - b) @ correction_matrix(x).T


def correct_many(X, a_s) -> np.ndarray:
    """Corrected vectors for a population ``X`` (P, 9|12): shape (P, n, 3)."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    b, k, th = X[:, 0:3], X[:, 3:6], X[:, 6:9]
    u = (np.asarray(a_s, dtype=float)[None, :, :] - b[:, None, :]) / k[:, None, :]
    ux, uy, uz = u[..., 0], u[..., 1], u[..., 2]
    tyz, tzy, tzx = th[:, 0:1], th[:, 1:2], th[:, 2:3]
    out = np.empty_like(u)
    out[..., 0] = ux
    out[..., 1] = tyz * ux + uy
    out[..., 2] = (tyz * tzx - tzy) * ux + tzx * uy + uz
    return out


@dataclass(frozen=True)
class LQParams:
    """Result of :func:`lq_to_params`: ``C = S·K·Q``.

    Attributes
    ----------
    x_tail : ndarray (6,)
        ``(kx, ky, kz, theta_yz, theta_zy, theta_zx)``.
    rotation : ndarray (3, 3)
        The orthogonal factor Q (frame rotation; identity when C is lower-triangular).
    """

    x_tail: np.ndarray
    rotation: np.ndarray


def lq_to_params(C) -> LQParams:
    """Map a general 3x3 gain matrix C to (k, theta) and a rotation Q (spec 002 §1.2).

    C = L·Q is the LQ factorisation (the QR of C^T) with diag(L) > 0; then
    k_i = L_ii, K = S^-1·L, theta_yz = -K21, theta_zy = K31, theta_zx = -K32.

    Raises
    ------
    InputError
        When C is singular or has a negative determinant (a reflection: not a sensor).
    """
    C = np.asarray(C, dtype=float)
    if C.shape != (3, 3) or not np.all(np.isfinite(C)):
        raise InputError("gain matrix must be a finite 3x3 matrix")
    Qt, Rt = np.linalg.qr(C.T)
    L, Q = Rt.T, Qt.T
    sgn = np.sign(np.diag(L))
    if np.any(sgn == 0):
        raise InputError("gain matrix is singular; the positions do not span three axes")
    L = L * sgn[None, :]
    Q = sgn[:, None] * Q
    k = np.diag(L).copy()
    K = L / k[:, None]
    tail = np.array([k[0], k[1], k[2], -K[1, 0], K[2, 0], -K[2, 1]])
    if np.linalg.det(Q) < 0:
        raise InputError("gain matrix has a negative determinant (axes form a left-handed set)")
    return LQParams(x_tail=tail, rotation=Q)


# --------------------------------------------------------------------------- residuals

def _check_objective(objective):
    if objective not in OBJECTIVES:
        raise InputError(f"unknown objective '{objective}' (use one of {', '.join(OBJECTIVES)})")


def _check_data(a, ref=None):
    a = np.asarray(a, dtype=float)
    if a.ndim != 2 or a.shape[1] != 3:
        raise InputError(f"records must have shape (n, 3), got {a.shape}")
    if ref is not None:
        ref = np.asarray(ref, dtype=float)
        if ref.shape != a.shape:
            raise InputError(f"references must have shape {a.shape}, got {ref.shape}")
    return a, ref


def residuals(x, a_s, *, objective="norm", g=G_PAPER, ref=None) -> np.ndarray:
    """LM residual vector of spec 002 §3.1.

    Parameters
    ----------
    x : array (9,) or (12,) for ``scalar12``
    a_s : array (n, 3), record means in the raw unit
    objective : {"norm", "norm2", "scalar", "scalar12"}
        ``norm``: n residuals ``||a_hat|| - g``; ``norm2``: ``(||a_hat||^2 - g^2)/(2g)``;
        ``scalar``: 3n residuals ``a_hat - ref`` (row-major); ``scalar12``: ``a_hat - R(phi) ref``.
    g : float, default 9.8
        Gravity magnitude in m/s^2 (the paper's value, spec 002 §1.1).
    ref : array (n, 3), optional
        Reference vectors in m/s^2 (``|ref| = g``), needed by the scalar objectives.
    """
    _check_objective(objective)
    a, ref = _check_data(a_s, ref)
    x = np.asarray(x, dtype=float)
    ah = correct(x[:9], a)
    if objective == "norm":
        return np.linalg.norm(ah, axis=1) - g
    if objective == "norm2":
        return (np.sum(ah * ah, axis=1) - g * g) / (2.0 * g)
    if ref is None:
        raise InputError(f"objective '{objective}' needs reference directions")
    if objective == "scalar":
        return (ah - ref).ravel()
    if objective == "scalar12":
        if x.size != 12:
            raise InputError("objective 'scalar12' needs 12 parameters (x and phi)")
        return (ah - ref @ rotation(x[9:12]).T).ravel()
    raise InputError(f"unknown objective '{objective}' (use one of {', '.join(OBJECTIVES)})")


def _d_correct(x, a):
    """d a_hat / d x for the 9 model parameters: array (n, 3, 9)."""
    b, k, th = _split(x[:9])
    u = (a - b) / k
    Ki = k_inverse(th)
    n = a.shape[0]
    J = np.zeros((n, 3, 9))
    for j in range(3):
        J[:, :, j] = -Ki[:, j][None, :] / k[j]
        J[:, :, 3 + j] = -Ki[:, j][None, :] * (u[:, j] / k[j])[:, None]
    ux, uy = u[:, 0], u[:, 1]
    J[:, 1, 6] = ux
    J[:, 2, 6] = th[2] * ux
    J[:, 2, 7] = -ux
    J[:, 2, 8] = th[0] * ux + uy
    return J


def jacobian(x, a_s, *, objective="norm", g=G_PAPER, ref=None) -> np.ndarray:
    """Analytic Jacobian of :func:`residuals` (spec 002 §3.6), shape (m, 9|12)."""
    _check_objective(objective)
    a, ref = _check_data(a_s, ref)
    x = np.asarray(x, dtype=float)
    D = _d_correct(x, a)
    if objective in ("norm", "norm2"):
        ah = correct(x[:9], a)
        if objective == "norm":
            w = ah / np.linalg.norm(ah, axis=1)[:, None]
        else:
            w = ah / g
        return np.einsum("nc,ncp->np", w, D)
    if objective == "scalar":
        return D.reshape(-1, 9)
    if objective == "scalar12":
        if ref is None:
            raise InputError("objective 'scalar12' needs reference directions")
        rr = ref @ rotation(x[9:12]).T
        Jp = skew(rr) @ left_jacobian(x[9:12])
        return np.concatenate([D, Jp], axis=2).reshape(-1, 12)
    raise InputError(f"unknown objective '{objective}' (use one of {', '.join(OBJECTIVES)})")


# --------------------------------------------------------------------------- objectives

def objective_value(x, a_s, *, objective="norm", g=G_PAPER, ref=None) -> float:
    """J = sum(residual^2) / n with n the number of records (spec 002 §3.1)."""
    r = residuals(x, a_s, objective=objective, g=g, ref=ref)
    return float(np.dot(r, r) / np.asarray(a_s).shape[0])


def objective_many(X, a_s, *, objective="norm", g=G_PAPER, ref=None) -> np.ndarray:
    """J for each row of a population ``X`` (P, 9|12): array (P,). Vectorised."""
    _check_objective(objective)
    X = np.atleast_2d(np.asarray(X, dtype=float))
    a, ref = _check_data(a_s, ref)
    ah = correct_many(X, a)
    n = a.shape[0]
    if objective == "norm":
        r = np.sqrt(np.sum(ah * ah, axis=2)) - g
        return np.sum(r * r, axis=1) / n
    if objective == "norm2":
        r = (np.sum(ah * ah, axis=2) - g * g) / (2.0 * g)
        return np.sum(r * r, axis=1) / n
    if ref is None:
        raise InputError(f"objective '{objective}' needs reference directions")
    if objective == "scalar":
        d = ah - ref[None]
    elif objective == "scalar12":
        if X.shape[1] != 12:
            raise InputError("objective 'scalar12' needs 12 parameters (x and phi)")
        rr = np.einsum("pij,nj->pni", rotation(X[:, 9:12]), ref)
        d = ah - rr
    else:
        raise InputError(f"unknown objective '{objective}' (use one of {', '.join(OBJECTIVES)})")
    return np.sum(d * d, axis=(1, 2)) / n


def j_h(x, a_s, g=G_PAPER) -> float:
    """Hamid's vector-norm objective J_H = mean (||a_hat|| - g)^2 (spec 002 §3.1)."""
    return objective_value(x, a_s, objective="norm", g=g)


def j_h2(x, a_s, g=G_PAPER) -> float:
    """Algebraic variant J_H2 = mean (||a_hat||^2 - g^2)^2 / (4 g^2) (spec 002 §3.1)."""
    return objective_value(x, a_s, objective="norm2", g=g)


def s9(x, a_s, ref) -> float:
    """Scalar-constraint objective J_S = J_1 + J_2 + J_3 (spec 002 §3.1, S9)."""
    return objective_value(x, a_s, objective="scalar", ref=ref)


def s12(xp, a_s, ref) -> float:
    """S9 with the mount rotation phi as three more unknowns (spec 002 §3.1, S12)."""
    return objective_value(xp, a_s, objective="scalar12", ref=ref)


def n_params(objective: str) -> int:
    """Number of unknowns of an objective: 12 for ``scalar12``, else 9."""
    return 12 if objective == "scalar12" else 9


def search_box(objective="scalar", *, center=None) -> np.ndarray:
    """Search box of spec 002 §3.2 as an array (d, 2).

    b in [-1, 1] m/s^2, k in [0.9, 1.1], theta and phi in [-0.05, 0.05] rad. With
    ``center`` (an initial estimate x_e in counts mode) the box is
    b_e ± 0.1·g·k_e, k_e·[0.9, 1.1] (spec 002 §3.2 rev); g is taken as 9.8 there.
    """
    d = n_params(objective)
    box = np.empty((d, 2))
    if center is None:
        box[0:3] = (-1.0, 1.0)
        box[3:6] = (0.9, 1.1)
    else:
        c = np.asarray(center, dtype=float)
        box[0:3, 0] = c[0:3] - 0.1 * G_PAPER * np.abs(c[3:6])
        box[0:3, 1] = c[0:3] + 0.1 * G_PAPER * np.abs(c[3:6])
        box[3:6, 0] = 0.9 * c[3:6]
        box[3:6, 1] = 1.1 * c[3:6]
    box[6:] = (-0.05, 0.05)
    return box
