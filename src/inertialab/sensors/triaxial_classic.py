"""Classic closed-form calibrations of a triaxial accelerometer.

* :func:`six_position`: the six-position (six-face) method of spec 002 §3.7, in its
  6-parameter form (per-axis bias and scale, no cross-coupling) and its
  12-parameter least-squares form (full gain matrix C and bias B, reduced to the
  9-parameter model by :func:`inertialab.sensors.triaxial.lq_to_params`).
* :func:`ellipsoid_fit`: the field-mode initialiser of spec 002 §3.8 (quadric fit by
  the smallest singular vector of the 10-column design matrix, after normalising
  the data), which also works on raw counts.

Both are a few lines of linear algebra that no library offers in this form, hence
hand-written on numpy.

References
----------
Spec 002 §3.7, §3.8. Frosio, Pedersini & Borghese, IEEE TIM 58(6), 2009.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from inertialab.errors import InputError, UnderdeterminedError
from inertialab.sensors.triaxial import G_PAPER, X0, lq_to_params

FACES = ("+x", "-x", "+y", "-y", "+z", "-z")
"""Face order of the six-position input (sensor axis pointing up)."""


@dataclass(frozen=True)
class SixPositionResult:
    """Result of the six-position method.

    Attributes
    ----------
    x : ndarray (9,)
        Parameters (bx, by, bz, kx, ky, kz, theta_yz, theta_zy, theta_zx).
    gain : ndarray (3, 3)
        The gain matrix C (diagonal for the 6-parameter form).
    bias : ndarray (3,)
    rotation : ndarray (3, 3)
        Frame rotation Q of the LQ step (identity for the 6-parameter form).
    form : int
        6 or 12.
    """

    x: np.ndarray
    gain: np.ndarray
    bias: np.ndarray
    rotation: np.ndarray
    form: int


def six_position(means, *, g: float = G_PAPER, form: int = 12) -> SixPositionResult:
    """Six-position calibration (spec 002 §3.7).

    Parameters
    ----------
    means : array (6, 3)
        Mean outputs with the sensor axis up in the order ``+x, -x, +y, -y, +z, -z``.
    g : float, default 9.8
        Gravity magnitude, m/s^2 (paper's value).
    form : {6, 12}, default 12
        6: b_a = (m_a+ + m_a-)/2, k_a = (m_a+ - m_a-)/(2g), theta = 0.
        12: column a of C is (m_a+ - m_a-)/(2g), B the mean of the six vectors, then LQ.
    """
    m = np.asarray(means, dtype=float)
    if m.shape != (6, 3):
        raise UnderdeterminedError(
            f"six-position method needs exactly the six faces {', '.join(FACES)}; got shape {m.shape}")
    if form not in (6, 12):
        raise InputError(f"form must be 6 or 12, got {form}")
    plus, minus = m[0::2], m[1::2]  # rows: axis x, y, z
    if form == 6:
        b = np.array([(plus[a, a] + minus[a, a]) / 2.0 for a in range(3)])
        k = np.array([(plus[a, a] - minus[a, a]) / (2.0 * g) for a in range(3)])
        if np.any(k <= 0):
            raise InputError("six-position: a face pair gives a non-positive scale; check face labels")
        x = np.concatenate([b, k, np.zeros(3)])
        return SixPositionResult(x=x, gain=np.diag(k), bias=b, rotation=np.eye(3), form=6)
    C = ((plus - minus) / (2.0 * g)).T  # column a from the a-axis pair
    B = m.mean(axis=0)
    lq = lq_to_params(C)
    x = np.concatenate([B, lq.x_tail])
    return SixPositionResult(x=x, gain=C, bias=B, rotation=lq.rotation, form=12)


@dataclass(frozen=True)
class EllipsoidFit:
    """Result of :func:`ellipsoid_fit`.

    Attributes
    ----------
    x : ndarray (9,)
        Parameters from B and L = S·K (k in raw units per m/s^2 for counts data).
    success : bool
        False when the quadric was not an ellipsoid (x is then the nominal x0).
    message : str
    """

    x: np.ndarray
    success: bool
    message: str


def ellipsoid_fit(a, *, g: float = G_PAPER, strict: bool = False) -> EllipsoidFit:
    """Ellipsoid-fit initialiser of spec 002 §3.8 (field mode, no references).

    The records are normalised ``y = (a - mean)/s`` with ``s = max |a - mean|``; the
    quadric ``y^T M y + n^T y + c = 0`` is the right singular vector of the smallest
    singular value of the design matrix; the sign is fixed so that M is positive
    definite. Then ``B = -M^-1 n / 2``, ``rho = B^T M B - c``, ``A = g^2 M / rho`` and
    ``L = chol(A^-1) = S·K``; B and L are mapped back to raw units.

    Parameters
    ----------
    a : array (n, 3)
        Static record means (any raw unit; counts allowed). Needs n >= 10 records,
        well spread over the sphere.
    g : float, default 9.8
        Gravity magnitude in m/s^2.
    strict : bool, default False
        Raise :class:`InputError` on failure (counts mode, spec 002 §3.8) instead of
        returning x0 with ``success=False``.
    """
    a = np.asarray(a, dtype=float)
    if a.ndim != 2 or a.shape[1] != 3:
        raise InputError(f"records must have shape (n, 3), got {a.shape}")

    def fail(msg):
        if strict:
            raise InputError(f"ellipsoid fit failed: {msg}")
        return EllipsoidFit(x=X0.copy(), success=False, message=msg)

    if a.shape[0] < 10:
        return fail(f"needs at least 10 records, got {a.shape[0]}")
    mean = a.mean(axis=0)
    s = float(np.max(np.abs(a - mean)))
    if not np.isfinite(s) or s == 0:
        return fail("records do not vary")
    y = (a - mean) / s
    X, Y, Z = y[:, 0], y[:, 1], y[:, 2]
    D = np.column_stack([X * X, Y * Y, Z * Z, 2 * X * Y, 2 * X * Z, 2 * Y * Z,
                         X, Y, Z, np.ones_like(X)])
    _, sv, vt = np.linalg.svd(D, full_matrices=False)
    v = vt[-1]
    M = np.array([[v[0], v[3], v[4]], [v[3], v[1], v[5]], [v[4], v[5], v[2]]])
    nvec, c = v[6:9], v[9]
    ev = np.linalg.eigvalsh(M)
    if np.all(ev < 0):
        M, nvec, c = -M, -nvec, -c
        ev = -ev[::-1]
    if np.any(ev <= 0):
        return fail("the quadric is not an ellipsoid (records too few or badly spread)")
    By = -0.5 * np.linalg.solve(M, nvec)
    rho = float(By @ M @ By - c)
    if rho <= 0:
        return fail("the quadric is not an ellipsoid (rho <= 0)")
    A = (g * g) * M / rho
    try:
        Ly = np.linalg.cholesky(np.linalg.inv(A))
    except np.linalg.LinAlgError:
        return fail("A^-1 is not positive definite")
    B = mean + s * By
    L = s * Ly
    k = np.diag(L).copy()
    K = L / k[:, None]
    x = np.array([B[0], B[1], B[2], k[0], k[1], k[2], -K[1, 0], K[2, 0], -K[2, 1]])
    return EllipsoidFit(x=x, success=True, message="ok")


# --------------------------------------------------------------------------- faces + norm

PLACEMENT_RAD = float(np.deg2rad(2.0))
"""Default standard deviation of a hand-placed face's tilt (2 deg) in :func:`face_fit`."""


@dataclass(frozen=True)
class FaceFit:
    """Result of :func:`face_fit`: ``raw = T @ a + b`` (the 12-parameter model).

    Attributes
    ----------
    T : ndarray (3, 3)
        Gain/misalignment matrix, raw unit per m/s^2 (imucal's ``K_a @ R_a``).
    b : ndarray (3,)
        Bias, raw unit.
    M : ndarray (3, 3)
        ``inv(T)``: calibrated = M @ (raw - b).
    x : ndarray (9,)
        The 9-parameter reduction (b, k, theta) by LQ; ``rotation`` is the rest.
    rotation : ndarray (3, 3)
    cov : ndarray (12, 12) or None
        Covariance of ``(M.ravel(), b)`` from the weighted fit.
    norm_residual : ndarray (n,)
        ``|calibrated| - g`` per face, m/s^2.
    tilt_rad : ndarray (n,)
        Angle between each calibrated face vector and its nominal direction.
    refined : bool
    """

    T: np.ndarray
    b: np.ndarray
    M: np.ndarray
    x: np.ndarray
    rotation: np.ndarray
    cov: np.ndarray | None
    norm_residual: np.ndarray
    tilt_rad: np.ndarray
    refined: bool


def face_fit(means, dirs=None, *, g: float = G_PAPER, placement_rad: float = PLACEMENT_RAD,
             norm_sigma: float | None = None, refine: bool = True) -> FaceFit:
    """Hand-placed faces: the 12-parameter six-position solution refined so that every
    calibrated face has the magnitude of gravity.

    The closed form (column a of T = (m_a+ - m_a-)/(2g), b = mean; spec 002 §3.7, the
    Ferraris accelerometer step) treats the nominal face directions as exact; faces
    placed by hand are tilted by a few degrees each, which leaves |a| errors of
    ~tilt^2 (1e-3 g at 3 deg). The refinement is the weighted least squares of
    ``|M (m_f - b)| = g`` (sigma ``norm_sigma``, default 1e-6 g: in effect a
    constraint) and ``M (m_f - b) = g d_f`` (sigma ``g * placement_rad``: the nominal
    directions as uncertain references), over the 12 unknowns (M, b).

    Parameters
    ----------
    means : array (n, 3)
        Face means in the raw unit; without ``dirs`` the six faces in the order
        ``+x, -x, +y, -y, +z, -z``.
    dirs : array (n, 3), optional
        Nominal up directions of the faces (unit vectors); n >= 6.
    g : float
        Local gravity, m/s^2.
    placement_rad : float, default 2 deg
        Standard deviation of a face's tilt.
    refine : bool, default True
        False gives the closed form (the classic six-position method).
    """
    from inertialab.regress.nlls import levenberg_marquardt

    m = np.asarray(means, dtype=float)
    if dirs is None:
        if m.shape != (6, 3):
            raise UnderdeterminedError(
                f"the face fit needs the six faces {', '.join(FACES)}; got shape {m.shape}")
        d = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, -1.0, 0], [0, 0, 1.0],
                      [0, 0, -1.0]])
    else:
        d = np.asarray(dirs, dtype=float)
        d = d / np.linalg.norm(d, axis=1)[:, None]
    if m.ndim != 2 or m.shape[1] != 3 or d.shape != m.shape or m.shape[0] < 6:
        raise UnderdeterminedError(f"the face fit needs at least six faces; got {m.shape[0]}")
    # closed form: least squares raw = T (g d) + b (the six-position columns for six faces)
    D = np.column_stack([g * d, np.ones(len(d))])
    sol, *_ = np.linalg.lstsq(D, m, rcond=None)
    T0, b0 = sol[:3].T, sol[3]
    M0 = np.linalg.inv(T0)
    sn = float(norm_sigma) if norm_sigma is not None else 1e-6 * g
    sp = g * float(placement_rad)
    n = len(m)

    def unpack(p):
        return p[:9].reshape(3, 3), p[9:12]

    def fun(p):
        M, b = unpack(p)
        a = (m - b) @ M.T
        r_n = (np.linalg.norm(a, axis=1) - g) / sn
        r_v = ((a - g * d) / sp).ravel()
        return np.r_[r_n, r_v]

    def jac(p):
        M, b = unpack(p)
        u = m - b
        a = u @ M.T
        na = np.linalg.norm(a, axis=1)
        J = np.zeros((n + 3 * n, 12))
        e = a / na[:, None]
        # d|a|/dM_ij = e_i u_j ; d|a|/db = -M^T e
        J[:n, :9] = (e[:, :, None] * u[:, None, :]).reshape(n, 9) / sn
        J[:n, 9:] = -(e @ M) / sn
        for f in range(n):
            for i in range(3):
                row = n + 3 * f + i
                J[row, 3 * i:3 * i + 3] = u[f] / sp
                J[row, 9:] = -M[i] / sp
        return J

    p0 = np.r_[M0.ravel(), b0]
    cov = None
    if refine:
        res = levenberg_marquardt(fun, p0, jac=jac, tol=1e-14)
        p = res.x
        # residuals are in units of their sigmas: the covariance is (J^T J)^-1
        Jw = jac(p)
        try:
            cov = np.linalg.inv(Jw.T @ Jw)
        except np.linalg.LinAlgError:
            cov = None
    else:
        p = p0
    M, b = unpack(p)
    T = np.linalg.inv(M)
    lq = lq_to_params(T)
    a = (m - b) @ M.T
    na = np.linalg.norm(a, axis=1)
    tilt = np.arccos(np.clip(np.sum(a * d, axis=1) / na, -1.0, 1.0))
    return FaceFit(T=T, b=np.asarray(b, dtype=float), M=M, x=np.concatenate([b, lq.x_tail]),
                   rotation=lq.rotation, cov=cov, norm_residual=na - g, tilt_rad=tilt,
                   refined=bool(refine))
