"""Rank-aware ordinary least squares.

``lstsq(A, y)`` solves ``min ||y - A b||`` through the SVD, decides the numerical rank
with a relative tolerance (spec 003 §3.2(b): singular values below ``rtol * s_max``
count as zero, default ``rtol = 1e-10``), and reports what a rank-deficient design can
and cannot tell: the minimum-norm solution, the null directions, which coefficients
are estimable on their own, and the value and standard deviation of any estimable
linear combination ``c^T b`` (``c`` in the row space of ``A``).

``numpy.linalg.lstsq`` gives the minimum-norm solution and the rank but neither the
null space nor the estimability bookkeeping, so this module wraps ``numpy.linalg.svd``
directly; nothing here is iterative.

References
----------
Spec 003 §3.1–3.2 and §3.5 (what to report for a rank-deficient design).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from inertialab.errors import InputError, UnderdeterminedError

__all__ = [
    "Combination",
    "LstsqResult",
    "lstsq",
    "naive_normal_equations",
    "null_space_text",
    "sparse_null_basis",
]


@dataclass(frozen=True)
class Combination:
    """An estimable linear combination ``weights @ coef`` with its standard deviation."""

    name: str
    weights: np.ndarray
    value: float
    sd: float


@dataclass(frozen=True)
class LstsqResult:
    """Result of :func:`lstsq`.

    Attributes
    ----------
    coef : (m,) minimum-norm solution ``A^+ y`` (its components along the null
        directions are zero by construction, i.e. arbitrary).
    rank : numerical rank r.
    singular_values : (min(N, m),) singular values of ``A``, descending.
    cond : ``s_max / s_min`` over all singular values (inf when one is 0).
    null_space : (m, m - r) orthonormal basis of the null space of ``A``.
    residual_ss : ``||y - A coef||^2``.
    dof : residual degrees of freedom ``N - r``.
    sigma2 : ``residual_ss / dof`` (nan when dof is 0).
    cov_minnorm : ``sigma2 * A^+ A^+T``, the "min-norm" covariance (spec §3.2(b)).
    estimable : (m,) bool, coefficient j estimable on its own (``e_j`` orthogonal
        to the null space).
    sd : (m,) standard deviations; ``inf`` for non-estimable coefficients.
    names : coefficient names.
    """

    coef: np.ndarray
    rank: int
    singular_values: np.ndarray
    cond: float
    null_space: np.ndarray
    residual_ss: float
    dof: int
    sigma2: float
    cov_minnorm: np.ndarray
    estimable: np.ndarray
    sd: np.ndarray
    names: tuple[str, ...]
    pinv: np.ndarray

    @property
    def residual(self) -> float:
        """``sqrt(residual_ss / dof)`` (spec 003 §4 "R"); nan when dof is 0."""
        return float(np.sqrt(self.sigma2))

    @property
    def min_norm_sd(self) -> np.ndarray:
        """``sqrt(sigma2 * diag(A^+ A^+T))`` for every coefficient (spec §3.2(b))."""
        return np.sqrt(np.diag(self.cov_minnorm))

    def is_estimable(self, weights, *, tol: float = 1e-8) -> bool:
        """Whether ``weights @ coef`` is estimable (orthogonal to every null direction)."""
        c = np.asarray(weights, dtype=float)
        if self.null_space.shape[1] == 0:
            return True
        nc = np.linalg.norm(c)
        if nc == 0:
            return True
        return bool(np.linalg.norm(self.null_space.T @ c) <= tol * nc)

    def combination(self, weights, name: str = "") -> Combination:
        """Value and SD of the combination ``weights @ coef``.

        Raises
        ------
        InputError
            If the combination is not estimable (it has a component along a null
            direction, so the data say nothing about its value).
        """
        c = np.asarray(weights, dtype=float)
        if c.shape != self.coef.shape:
            raise InputError(f"combination needs {self.coef.size} weights, got {c.size}")
        if not self.is_estimable(c):
            raise InputError(f"combination {name or c.tolist()} is not estimable: it has a "
                             "component along a null direction of the design")
        value = float(c @ self.coef)
        sd = float(np.sqrt(max(c @ self.cov_minnorm @ c, 0.0)))
        return Combination(name, c, value, sd)


def lstsq(A, y, *, rtol: float = 1e-10, names=None) -> LstsqResult:
    """Rank-aware least squares through the SVD.

    Parameters
    ----------
    A : (N, m) array_like
        Design matrix.
    y : (N,) array_like
        Response.
    rtol : float, default=1e-10
        Singular values ``<= rtol * s_max`` count as zero (spec 003 §3.2(b)).
    names : sequence of str, optional
        Coefficient names (default ``b0, b1, ...``).

    Returns
    -------
    LstsqResult

    Raises
    ------
    InputError
        Shapes that do not match or non-finite values.
    UnderdeterminedError
        A design of rank 0.
    """
    A = np.asarray(A, dtype=float)
    y = np.asarray(y, dtype=float).ravel()
    if A.ndim != 2 or A.shape[0] != y.size:
        raise InputError(f"design of shape {A.shape} does not match response of length {y.size}")
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(y))):
        raise InputError("design or response contains NaN or infinity")
    N, m = A.shape
    names = tuple(names) if names is not None else tuple(f"b{j}" for j in range(m))
    if len(names) != m:
        raise InputError(f"{len(names)} names for {m} coefficients")
    U, s, Vt = np.linalg.svd(A, full_matrices=True)
    if s.size == 0 or s[0] == 0.0:
        raise UnderdeterminedError("the design matrix is zero")
    r = int(np.sum(s > rtol * s[0]))
    Ur, sr, Vr = U[:, :r], s[:r], Vt[:r].T
    pinv = Vr @ (Ur.T / sr[:, None])
    coef = pinv @ y
    resid = y - A @ coef
    rss = float(resid @ resid)
    dof = N - r
    sigma2 = rss / dof if dof > 0 else float("nan")
    cov = sigma2 * (pinv @ pinv.T)
    null = Vt[r:].T if r < m else np.zeros((m, 0))
    est = np.linalg.norm(null, axis=1) <= 1e-8 if null.shape[1] else np.ones(m, bool)
    sd = np.where(est, np.sqrt(np.clip(np.diag(cov), 0, None)), np.inf)
    full_s = np.concatenate([s, np.zeros(max(0, min(N, m) - s.size))])
    cond = float(s[0] / full_s[-1]) if full_s[-1] > 0 else float("inf")
    if min(N, m) < m:
        cond = float("inf")
    return LstsqResult(coef=coef, rank=r, singular_values=s, cond=cond, null_space=null,
                       residual_ss=rss, dof=dof, sigma2=sigma2, cov_minnorm=cov,
                       estimable=est, sd=sd, names=names, pinv=pinv)


def naive_normal_equations(A, y) -> np.ndarray:
    """``solve(A^T A, A^T y)``: what a textbook least-squares code does (spec 003 §3.2(c)).

    Only a diagnostic of ill-conditioning: for a rank-deficient ``A`` the result is
    huge and sample-sensitive, or NaN when LAPACK reports an exactly singular matrix.
    """
    A = np.asarray(A, dtype=float)
    y = np.asarray(y, dtype=float).ravel()
    try:
        return np.linalg.solve(A.T @ A, A.T @ y)
    except np.linalg.LinAlgError:
        return np.full(A.shape[1], np.nan)


def sparse_null_basis(null_space: np.ndarray, *, tol: float = 1e-9) -> np.ndarray:
    """A readable basis of the same null space: reduced row-echelon form of its transpose.

    Each returned column has a leading 1 at its pivot coefficient, so a coupling like
    ``(KA0, KA2, KBx) = (1, -1, 1)`` reads off directly. Columns are scaled so their
    largest entry is +1 in absolute value is kept at the pivot.
    """
    B = np.array(null_space, dtype=float).T  # (m - r, m)
    rows, cols = B.shape
    piv_row = 0
    for j in range(cols):
        if piv_row >= rows:
            break
        p = piv_row + int(np.argmax(np.abs(B[piv_row:, j])))
        if abs(B[p, j]) <= tol:
            continue
        B[[piv_row, p]] = B[[p, piv_row]]
        B[piv_row] /= B[piv_row, j]
        for i in range(rows):
            if i != piv_row:
                B[i] -= B[i, j] * B[piv_row]
        piv_row += 1
    B[np.abs(B) < tol] = 0.0
    return B.T


def null_space_text(null_space: np.ndarray, names, *, tol: float = 1e-9) -> list[str]:
    """One string per null direction, e.g. ``"n1 = +1*KA0 -1*KA2 +1*KBx"``."""
    basis = sparse_null_basis(null_space, tol=tol)
    out = []
    for i in range(basis.shape[1]):
        v = basis[:, i]
        terms = [f"{v[j]:+.3g}*{names[j]}" for j in range(v.size) if abs(v[j]) > tol]
        out.append(f"n{i + 1} = " + " ".join(terms))
    return out
