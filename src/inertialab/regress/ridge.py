"""Ridge regression in canonical form, with the Hoerl–Kennard–Baldwin and GCV rules for k.

Everything is done in the canonical (SVD) coordinates of spec 003 §3.3 steps 1–4, which
the empirical-Bayes ridge of :mod:`inertialab.regress.ebr` shares:

* centre and scale by a prior ``beta ~ beta0 + W gamma``: ``z = y - A beta0``,
  ``At = A W`` (``W = diag(w)``);
* SVD ``At = U D^{1/2} V^T``; keep the r components with ``s_i > rtol * s_1``;
* canonical least-squares coordinates ``x = D_r^{-1/2} U_r^T z``,
  ``sigma^2 = ||z - U_r U_r^T z||^2 / (N - r)``.

A ridge estimate with ``k = 1/lambda`` shrinks ``x_i`` by ``b_i = d_i/(d_i + k)``;
components in the null space stay at the prior centre. The sandwich covariance, the
conjugate-normal posterior covariance and the exact bias for a known truth follow
spec 003 §3.3 step 8 and §3.4. scikit-learn's ``Ridge`` takes a fixed ``alpha`` and has
neither rule for k, nor the rank-deficient bookkeeping, hence this module.

References
----------
Hoerl, Kennard & Baldwin (1975), Commun. Statist. 4:105–123 (k_HKB = p sigma^2/||b||^2,
with p replaced by the rank r, spec 003 §3.4). Golub, Heath & Wahba (1979),
Technometrics 21:215–223 (GCV).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from inertialab.errors import InputError, UnderdeterminedError

__all__ = ["Canonical", "RidgeResult", "ShrinkageFit", "canonical_form", "gcv_curve",
           "k_gcv", "k_hkb", "ridge", "shrink"]


@dataclass(frozen=True)
class Canonical:
    """The canonical form of a (centred, scaled) linear model (spec 003 §3.3 steps 1–4)."""

    A: np.ndarray
    y: np.ndarray
    beta0: np.ndarray
    w: np.ndarray
    z: np.ndarray
    U_r: np.ndarray
    s: np.ndarray  # kept singular values of At, descending (s_i = sqrt(d_i))
    V_r: np.ndarray  # (m, r)
    V_0: np.ndarray  # (m, m - r)
    x: np.ndarray  # canonical LS coordinates
    uz: np.ndarray  # U_r^T z
    rss: float
    n: int  # N
    rank: int
    singular_values_all: np.ndarray

    @property
    def d(self) -> np.ndarray:
        return self.s**2

    @property
    def dof(self) -> int:
        return self.n - self.rank

    @property
    def sigma2(self) -> float:
        """Unbiased ``S/(N - r)``; nan with no residual degrees of freedom."""
        return self.rss / self.dof if self.dof > 0 else float("nan")

    @property
    def sigma2_stein(self) -> float:
        """Stein form ``S/(N - r + 2)`` (spec 003 §3.3 step 4)."""
        return self.rss / (self.dof + 2)


def canonical_form(A, y, *, prior_mean=None, prior_scale=None, rtol: float = 1e-10) -> Canonical:
    """Centre, scale and rotate ``y = A beta + e`` to canonical coordinates.

    Parameters
    ----------
    A : (N, m) array_like
    y : (N,) array_like
    prior_mean : (m,) array_like, optional
        beta0, default 0 (the paper-faithful prior, spec 003 §3.3 step 0).
    prior_scale : (m,) array_like, optional
        w (positive), default 1.
    rtol : float, default=1e-10
        Keep components with ``s_i > rtol * s_1`` (i.e. ``d_i > 1e-20 d_1``).
    """
    A = np.asarray(A, dtype=float)
    y = np.asarray(y, dtype=float).ravel()
    if A.ndim != 2 or A.shape[0] != y.size:
        raise InputError(f"design of shape {A.shape} does not match response of length {y.size}")
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(y))):
        raise InputError("design or response contains NaN or infinity")
    N, m = A.shape
    beta0 = np.zeros(m) if prior_mean is None else np.asarray(prior_mean, dtype=float).ravel()
    w = np.ones(m) if prior_scale is None else np.asarray(prior_scale, dtype=float).ravel()
    if beta0.size != m or w.size != m:
        raise InputError(f"prior mean and scale need {m} entries each")
    if not (np.all(np.isfinite(w)) and np.all(w > 0)):
        raise InputError("prior scales must be finite and positive")
    z = y - A @ beta0
    At = A * w
    U, s_all, Vt = np.linalg.svd(At, full_matrices=True)
    if s_all.size == 0 or s_all[0] == 0.0:
        raise UnderdeterminedError("the design matrix is zero")
    r = int(np.sum(s_all > rtol * s_all[0]))
    U_r = U[:, :r]
    s = s_all[:r]
    V_r = Vt[:r].T
    V_0 = Vt[r:].T
    uz = U_r.T @ z
    x = uz / s
    res = z - U_r @ uz
    return Canonical(A=A, y=y, beta0=beta0, w=w, z=z, U_r=U_r, s=s, V_r=V_r, V_0=V_0, x=x,
                     uz=uz, rss=float(res @ res), n=N, rank=r, singular_values_all=s_all)


@dataclass(frozen=True)
class ShrinkageFit:
    """A ridge-type estimate with its covariances (spec 003 §3.3 steps 7–8).

    ``lam`` is the prior variance ratio lambda = 1/k (``inf`` = least squares on the
    estimable part, 0 = prior centre only).
    """

    canon: Canonical
    lam: float
    b: np.ndarray
    coef: np.ndarray
    cov_sandwich: np.ndarray
    cov_posterior: np.ndarray

    @property
    def k(self) -> float:
        return 1.0 / self.lam if self.lam > 0 else float("inf")

    @property
    def sd_sandwich(self) -> np.ndarray:
        return np.sqrt(np.clip(np.diag(self.cov_sandwich), 0, None))

    @property
    def sd_posterior(self) -> np.ndarray:
        return np.sqrt(np.clip(np.diag(self.cov_posterior), 0, None))

    def bias(self, beta_true) -> np.ndarray:
        """Exact bias for a known truth: ``-W [V_r diag(1-b) theta + V_0 V_0^T gamma]``."""
        c = self.canon
        gamma = (np.asarray(beta_true, dtype=float) - c.beta0) / c.w
        theta = c.V_r.T @ gamma
        return -c.w * (c.V_r @ ((1.0 - self.b) * theta) + c.V_0 @ (c.V_0.T @ gamma))

    def rmse(self, beta_true) -> np.ndarray:
        """``sqrt(diag C_s + bias^2)`` per coefficient (spec 003 §3.3 step 8)."""
        return np.sqrt(np.diag(self.cov_sandwich) + self.bias(beta_true) ** 2)

    def residual(self) -> float:
        """In-sample ``sqrt(||y - A coef||^2 / (N - r))`` (spec 003 §4 "R")."""
        c = self.canon
        e = c.y - c.A @ self.coef
        return float(np.sqrt(e @ e / c.dof)) if c.dof > 0 else float("nan")


def shrink(canon: Canonical, lam: float) -> ShrinkageFit:
    """Ridge estimate with prior variance ratio ``lam`` (k = 1/lam) in canonical form."""
    c = canon
    d = c.d
    lam = float(lam)
    if lam < 0 or np.isnan(lam):
        raise InputError(f"lambda must be >= 0, got {lam}")
    if np.isinf(lam):
        b = np.ones_like(d)
        post_r = 1.0 / d
        post_0 = np.inf
    else:
        b = lam * d / (1.0 + lam * d)
        post_r = lam / (1.0 + lam * d)
        post_0 = lam
    gamma = c.V_r @ (b * c.x)
    coef = c.beta0 + c.w * gamma
    sig2 = c.sigma2 if c.dof > 0 else 0.0
    Vw = c.V_r * c.w[:, None]
    cov_s = sig2 * (Vw * (b**2 / d)) @ Vw.T
    V0w = c.V_0 * c.w[:, None]
    with np.errstate(invalid="ignore"):
        null_part = (V0w @ V0w.T) * post_0 if V0w.shape[1] else 0.0
        if np.isinf(post_0) and V0w.shape[1]:
            null_part = np.where(np.abs(V0w @ V0w.T) > 1e-12, np.inf, 0.0)
    cov_p = sig2 * ((Vw * post_r) @ Vw.T + null_part)
    return ShrinkageFit(canon=c, lam=lam, b=b, coef=coef, cov_sandwich=cov_s, cov_posterior=cov_p)


def k_hkb(canon: Canonical) -> float:
    """Hoerl–Kennard–Baldwin ``k = r sigma^2 / ||gamma_LS||^2`` (spec 003 §3.4).

    ``||gamma_LS|| = ||x||`` because V_r is orthonormal. Returns 0 for a noise-free fit.
    """
    xx = float(canon.x @ canon.x)
    if canon.dof <= 0:
        raise UnderdeterminedError("ridge-HKB needs N > rank to estimate sigma^2")
    if xx == 0.0:
        return float("inf")
    return canon.rank * canon.sigma2 / xx


def _k_grid(canon: Canonical, n: int = 400) -> np.ndarray:
    d = canon.d
    return np.logspace(np.log10(d[-1]) - 8, np.log10(d[0]) + 2, n)


def gcv_curve(canon: Canonical, k) -> np.ndarray:
    """GCV score ``V(k) = N ||(I - H_k) z||^2 / (N - tr H_k)^2`` via the SVD (spec 003 §3.4)."""
    c = canon
    k = np.atleast_1d(np.asarray(k, dtype=float))[:, None]
    d = c.d[None, :]
    tr = np.sum(d / (d + k), axis=1)
    zz = float(c.z @ c.z)
    rss = zz - float(c.uz @ c.uz) + np.sum((k / (d + k)) ** 2 * c.uz[None, :] ** 2, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return c.n * rss / (c.n - tr) ** 2


def k_gcv(canon: Canonical) -> float:
    """GCV-optimal k: 400-point grid on log10 k in [log10 d_r - 8, log10 d_1 + 2],
    then a bounded Brent/golden-section refinement between the grid neighbours."""
    grid = _k_grid(canon)
    v = gcv_curve(canon, grid)
    v = np.where(np.isfinite(v), v, np.inf)
    i = int(np.argmin(v))
    lo = np.log10(grid[max(i - 1, 0)])
    hi = np.log10(grid[min(i + 1, grid.size - 1)])
    if hi <= lo:
        return float(grid[i])
    res = minimize_scalar(lambda t: float(gcv_curve(canon, 10.0**t)[0]), bounds=(lo, hi),
                          method="bounded", options={"xatol": 1e-10})
    kbest = 10.0 ** float(res.x)
    return kbest if gcv_curve(canon, kbest)[0] <= v[i] else float(grid[i])


@dataclass(frozen=True)
class RidgeResult:
    """Ridge fit: the rule, its k, and the shrinkage fit (coefficients and covariances)."""

    rule: str
    k: float
    fit: ShrinkageFit

    @property
    def coef(self) -> np.ndarray:
        return self.fit.coef

    @property
    def sd(self) -> np.ndarray:
        """Sandwich SD (spec 003 §3.5)."""
        return self.fit.sd_sandwich


def ridge(A, y, *, k="hkb", prior_mean=None, prior_scale=None, rtol: float = 1e-10) -> RidgeResult:
    """Ridge regression ``beta0 + W (At^T At + k I)^-1 At^T z``.

    Parameters
    ----------
    A, y : design (N, m) and response (N,).
    k : {"hkb", "gcv"} or float, default="hkb"
        The ridge constant or the rule that picks it (spec 003 §3.4).
    prior_mean, prior_scale : optional
        Centre and scale (beta0, w) of the system the penalty acts on; default raw
        system (0, 1).
    """
    canon = canonical_form(A, y, prior_mean=prior_mean, prior_scale=prior_scale, rtol=rtol)
    if isinstance(k, str):
        rule = k.lower()
        if rule == "hkb":
            kval = k_hkb(canon)
        elif rule == "gcv":
            kval = k_gcv(canon)
        else:
            raise InputError(f"unknown ridge rule '{k}' (use 'hkb', 'gcv' or a number)")
    else:
        rule, kval = "fixed", float(k)
        if not kval >= 0:
            raise InputError(f"ridge k must be >= 0, got {k}")
    lam = 1.0 / kval if kval > 0 else float("inf")
    return RidgeResult(rule=rule, k=kval, fit=shrink(canon, lam))
