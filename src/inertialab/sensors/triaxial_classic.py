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
