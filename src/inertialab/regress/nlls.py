"""Nonlinear least squares: Levenberg-Marquardt with covariance, and a batched
vectorised Gauss-Newton for many small problems at once.

:func:`levenberg_marquardt` wraps :func:`scipy.optimize.least_squares` (MINPACK
``lm``, or ``trf`` with bounds and robust losses) and adds what a calibration
report needs: the parameter covariance ``s^2 (J^T J)^-1`` with
``s^2 = sum(rho^2)/(m - p)``, the standard errors and the condition number of
``J^T J`` (spec 002 §3.6).

:func:`batched_gauss_newton` solves U independent problems of the same size in
lock step (arrays (U, m) and (U, m, p)) with per-problem Levenberg-Marquardt damping
(lambda0 = 1e-3, x10 on a rejected step, /10 on an accepted one; spec 002 §3.6).
SciPy has no batched solver; looping ``least_squares`` over 5000 units costs
seconds of Python overhead, which is why this one is hand-written on numpy's
batched ``solve``.

References
----------
Spec 002 §3.6, §6.4. Moré, "The Levenberg-Marquardt algorithm: implementation and
theory", 1978.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from inertialab.errors import InputError

COND_LIMIT = 1e12
"""Covariance is reported as None above this condition number (spec 002 §3.6)."""


@dataclass(frozen=True)
class NLLSResult:
    """Result of :func:`levenberg_marquardt`.

    Attributes
    ----------
    x : ndarray (p,)
    residuals : ndarray (m,)
        Residuals at ``x`` (unweighted by any robust loss).
    jac : ndarray (m, p)
    cost : float
        ``0.5 * sum(residuals^2)`` (scipy's ``cost`` for the linear loss).
    cov : ndarray (p, p) or None
        ``s^2 (J^T J)^-1``; None when m <= p or cond(J^T J) > 1e12.
    stderr : ndarray (p,) or None
        Square roots of the diagonal of ``cov``.
    cond : float
        Condition number of the column-scaled ``J^T J`` (inf when singular); see
        :func:`covariance`.
    nfev, njev : int
        Residual and Jacobian evaluations.
    success : bool
    status : int
        scipy's status code.
    message : str
    """

    x: np.ndarray
    residuals: np.ndarray
    jac: np.ndarray
    cost: float
    cov: np.ndarray | None
    stderr: np.ndarray | None
    cond: float
    nfev: int
    njev: int
    success: bool
    status: int
    message: str


def covariance(jac, resid, *, cond_limit: float = COND_LIMIT):
    """Parameter covariance of a least-squares fit at its optimum.

    Returns a :class:`Covariance` with ``cov = s^2 (J^T J)^-1``, ``s^2 = sum(r^2)/(m-p)``;
    ``cov`` and ``stderr`` are None when m <= p or the condition number exceeds
    ``cond_limit``. The condition number is that of ``J^T J`` after scaling its columns
    to unit diagonal (a correlation-type matrix), so that parameters in very different
    units (counts mode: biases ~3e4 counts next to angles ~1e-2 rad) are not mistaken for
    an ill-posed schedule; for parameters of similar scale it equals cond(J^T J) within a
    small factor. The inverse is computed in the same scaling.
    """
    J = np.asarray(jac, dtype=float)
    r = np.asarray(resid, dtype=float)
    m, p = J.shape
    JtJ = J.T @ J
    d = np.sqrt(np.diag(JtJ))
    if np.any(d == 0) or not np.all(np.isfinite(d)):
        return Covariance(cov=None, stderr=None, cond=float("inf"), dof=m - p)
    Cn = JtJ / np.outer(d, d)
    try:
        cond = float(np.linalg.cond(Cn))
    except np.linalg.LinAlgError:
        cond = float("inf")
    if not np.isfinite(cond):
        cond = float("inf")
    if m <= p or cond > cond_limit:
        return Covariance(cov=None, stderr=None, cond=cond, dof=m - p)
    s2 = float(r @ r) / (m - p)
    cov = s2 * np.linalg.inv(Cn) / np.outer(d, d)
    cov = 0.5 * (cov + cov.T)
    return Covariance(cov=cov, stderr=np.sqrt(np.clip(np.diag(cov), 0.0, None)), cond=cond,
                      dof=m - p)


@dataclass(frozen=True)
class Covariance:
    """Parameter covariance of a least-squares fit (see :func:`covariance`)."""

    cov: np.ndarray | None
    stderr: np.ndarray | None
    cond: float
    dof: int


def levenberg_marquardt(fun: Callable, x0, *, jac: Callable | str = "2-point",
                        bounds=None, loss: str = "linear", f_scale: float = 1.0,
                        tol: float = 1e-12, max_nfev: int | None = None) -> NLLSResult:
    """Minimise ``sum(fun(x)^2)`` with scipy's least_squares and report the covariance.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(5.0)
    >>> res = levenberg_marquardt(lambda p: p[0] * t + p[1] - (2 * t + 1), [0.0, 0.0])
    >>> np.round(res.x, 6)
    array([2., 1.])

    Parameters
    ----------
    fun : callable ``x -> residuals (m,)``
    x0 : array (p,)
        Start point.
    jac : callable ``x -> (m, p)`` or ``"2-point"``, default "2-point"
        Analytic Jacobian (preferred) or scipy's finite differences.
    bounds : (lo, hi) arrays, optional
        A box; switches to ``method="trf"`` (spec 002 §3.6 bounded variant).
    loss : {"linear", "soft_l1", "huber", "cauchy", "arctan"}, default "linear"
        Robust loss (needs ``trf``; chosen automatically when not linear).
    f_scale : float, default 1.0
        Residual scale of the robust loss (spec 002 §7.3 suggests 3·sigma_rec).
    tol : float, default 1e-12
        ``xtol = ftol = gtol`` (spec 002 §3.6).
    max_nfev : int, optional
        Evaluation budget (scipy's default when None).
    """
    x0 = np.asarray(x0, dtype=float)
    if x0.ndim != 1 or not np.all(np.isfinite(x0)):
        raise InputError("x0 must be a finite 1-D array")
    r0 = np.asarray(fun(x0), dtype=float)
    if r0.size < x0.size and bounds is None and loss == "linear":
        raise InputError(
            f"{r0.size} residuals for {x0.size} unknowns: the problem is underdetermined")
    kw = dict(xtol=tol, ftol=tol, gtol=tol, max_nfev=max_nfev)
    if bounds is None and loss == "linear" and r0.size >= x0.size:
        res = least_squares(fun, x0, jac=jac, method="lm", **kw)
    else:
        lo, hi = (np.full(x0.size, -np.inf), np.full(x0.size, np.inf)) if bounds is None \
            else (np.asarray(bounds[0], float), np.asarray(bounds[1], float))
        res = least_squares(fun, np.clip(x0, lo, hi), jac=jac, method="trf", bounds=(lo, hi),
                            loss=loss, f_scale=f_scale, **kw)
    r = np.asarray(fun(res.x), dtype=float)
    J = np.asarray(res.jac, dtype=float) if not callable(jac) else np.asarray(jac(res.x), float)
    cv = covariance(J, r)
    return NLLSResult(
        x=res.x.copy(), residuals=r, jac=J, cost=float(0.5 * r @ r), cov=cv.cov,
        stderr=cv.stderr, cond=cv.cond, nfev=int(res.nfev),
        njev=int(res.njev) if res.njev is not None else 0,
        success=bool(res.success), status=int(res.status), message=str(res.message))


@dataclass(frozen=True)
class BatchResult:
    """Result of :func:`batched_gauss_newton`.

    Attributes
    ----------
    x : ndarray (U, p)
    cost : ndarray (U,)
        ``sum(residuals^2)`` per problem at ``x``.
    nit : ndarray (U,) int
        Iterations (accepted or rejected steps) until each problem converged.
    converged : ndarray (U,) bool
    stderr : ndarray (U, p)
        ``sqrt(diag(s^2 (J^T J)^-1))`` with ``s^2 = cost/(m - p)`` (nan when m <= p).
    """

    x: np.ndarray
    cost: np.ndarray
    nit: np.ndarray
    converged: np.ndarray
    stderr: np.ndarray


def batched_gauss_newton(fun_jac: Callable, x0, *, lambda0: float = 1e-3,
                         max_iter: int = 100, xtol: float = 1e-12,
                         ftol: float = 1e-15) -> BatchResult:
    """Levenberg-Marquardt-damped Gauss-Newton over a batch axis (spec 002 §3.6, §6.4).

    Parameters
    ----------
    fun_jac : callable ``(X (k, p), idx (k,)) -> (R (k, m), J (k, m, p))``
        Residuals and Jacobians of the problems ``idx`` (indices into the batch) at
        ``X``, vectorised; converged problems drop out of later calls.
    x0 : array (U, p)
        Start points.
    lambda0 : float, default 1e-3
        Initial damping (multiplies ``diag(J^T J)``); x10 on rejection, /10 on acceptance.
    max_iter : int, default 100
    xtol : float, default 1e-12
        A problem has converged when its accepted step satisfies
        ``|dx| <= xtol (|x| + xtol)`` (max norm) or its relative cost decrease is below ``ftol``.
    ftol : float, default 1e-15
    """
    X = np.array(x0, dtype=float, copy=True)
    if X.ndim != 2:
        raise InputError(f"x0 must have shape (U, p), got {X.shape}")
    U, p = X.shape
    R, J = fun_jac(X, np.arange(U))
    cost = np.einsum("um,um->u", R, R)
    lam = np.full(U, float(lambda0))
    active = np.ones(U, dtype=bool)
    nit = np.zeros(U, dtype=int)
    eye = np.eye(p)
    for _ in range(max_iter):
        if not active.any():
            break
        idx = np.flatnonzero(active)
        Ja, Ra = J[idx], R[idx]
        JtJ = np.einsum("umi,umj->uij", Ja, Ja)
        g = np.einsum("umi,um->ui", Ja, Ra)
        dg = np.einsum("uii->ui", JtJ)
        A = JtJ + lam[idx, None, None] * (dg[:, :, None] * eye[None])
        try:
            step = -np.linalg.solve(A, g[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            A = A + 1e-12 * eye[None]
            step = -np.linalg.lstsq(A.reshape(-1, p), g.reshape(-1), rcond=None)[0].reshape(-1, p)
        Xn = X[idx] + step
        Rn, Jn = fun_jac(Xn, idx)
        cn = np.einsum("um,um->u", Rn, Rn)
        nit[idx] += 1
        ok = cn < cost[idx]
        acc = idx[ok]
        small = np.max(np.abs(step), axis=1) <= xtol * (np.max(np.abs(X[idx]), axis=1) + xtol)
        rel = (cost[idx] - cn) <= ftol * np.maximum(cost[idx], 1e-300)
        X[acc] = Xn[ok]
        R[acc] = Rn[ok]
        J[acc] = Jn[ok]
        done = (ok & (small | rel)) | (~ok & small)
        cost[acc] = cn[ok]
        lam[acc] = np.maximum(lam[acc] / 10.0, 1e-15)
        lam[idx[~ok]] = lam[idx[~ok]] * 10.0
        done |= lam[idx] > 1e16
        active[idx[done]] = False
    m = R.shape[1]
    stderr = np.full((U, p), np.nan)
    if m > p:
        JtJ = np.einsum("umi,umj->uij", J, J)
        try:
            inv = np.linalg.inv(JtJ)
            s2 = cost / (m - p)
            stderr = np.sqrt(np.clip(np.einsum("uii->ui", inv), 0, None) * s2[:, None])
        except np.linalg.LinAlgError:
            pass
    return BatchResult(x=X, cost=cost, nit=nit, converged=~active, stderr=stderr)
