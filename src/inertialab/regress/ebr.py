"""Empirical Bayes ridge (EBR) for rank-deficient linear models (spec 003 §3.3).

Model: ``y = A beta + e``, ``e ~ N(0, sigma^2 I)``, prior ``beta - beta0 ~ N(0, lambda
sigma^2 W^2)``. In canonical coordinates (:func:`inertialab.regress.ridge.canonical_form`)
the posterior mean shrinks each canonical LS coordinate ``x_i`` by
``b_i = lambda d_i / (1 + lambda d_i)``; the variance ratio lambda is estimated from the
data by one of three rules:

* ``"E1"`` (default) moment/Stein equation ``sum d_i x_i^2/(1 + lambda d_i) = (r - 2)
  sigma~^2``, ``sigma~^2 = S/(N - r + 2)``; reduces to the James–Stein rule with unknown
  sigma^2 when all d_i are equal; positive-part fallback lambda = 0;
* ``"E2"`` type-II maximum likelihood of the marginal ``x_i ~ N(0, sigma^2 (1 + lambda
  d_i)/d_i)``;
* ``"E3"`` SURE for the parameter loss.

The paper's second root lambda0 (its eqs. 17–19, lost from the seed) is reconstructed as
the root of ``r_eff(lambda) = (r + 2)/2`` and reported with the per-data-set flag
``minimax_sufficient_``; ``lambda_combination`` picks lambda*, max or min of the two.

Along the null directions of ``A`` the estimate stays at the prior centre: with the
paper-faithful prior (beta0 = 0, W = I) EBR then agrees with minimum-norm least squares
there, and the class warns (:class:`~inertialab.errors.NonIdentifiableWarning`) naming
the null directions. Written by hand: no library implements these lambda rules with
the rank-deficient canonical form (scikit-learn's ``BayesianRidge`` estimates two
precisions by evidence maximisation and has no prior centre; note its ``lambda_`` is a
*precision*, whereas ``lambda_`` here is the prior *variance ratio*).

References
----------
Spec 003 §3.3 (steps 0–8), §3.5. Shinozaki & Chang (1993), Commun. Statist. Theory
Methods; Kubokawa & Srivastava (2004), Commun. Statist. Theory Methods 33(8).
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from inertialab.errors import (
    InputError,
    NonIdentifiableWarning,
    NotFittedError,
    ShrinkageWarning,
    UnderdeterminedError,
)
from inertialab.estimator import Estimator
from inertialab.regress.lstsq import null_space_text
from inertialab.regress.ridge import Canonical, _k_grid, canonical_form, shrink

__all__ = ["EmpiricalBayesRidge", "lambda_e1", "lambda_e2", "lambda_e3", "lambda_zero", "r_eff"]


def _root_log(f, lo: float, hi: float, *, rtol: float = 1e-12) -> float:
    """Root of a monotone ``f`` in ``[lo, hi]`` found in log space (relative accuracy)."""
    return float(np.exp(brentq(lambda t: f(np.exp(t)), np.log(lo), np.log(hi),
                               xtol=rtol, rtol=rtol, maxiter=500)))


def _G(canon: Canonical, lam: float) -> float:
    d = canon.d
    return float(np.sum(d * canon.x**2 / (1.0 + lam * d)))


def lambda_e1(canon: Canonical) -> float:
    """E1: root lambda* of ``G(lambda) = (r - 2) sigma~^2`` (spec 003 §3.3 step 6).

    ``G`` decreases strictly from ``sum d_i x_i^2`` to 0, so the root is unique when
    ``G(0)`` exceeds the right side; otherwise 0 (positive part). A noise-free fit
    (S = 0) gives ``inf`` (no shrinkage).
    """
    c = canon
    if c.rank < 3:
        raise UnderdeterminedError(f"E1 needs rank >= 3, the design has rank {c.rank}")
    rhs = (c.rank - 2) * c.sigma2_stein
    g0 = _G(c, 0.0)
    if g0 <= rhs:
        return 0.0
    if rhs <= 0.0:
        return float("inf")
    f = lambda lam: _G(c, lam) - rhs  # noqa: E731
    lo = 1e-30 / c.d[0]
    hi = 1.0 / c.d[0]
    while f(hi) > 0:
        hi *= 2.0
        if hi > 1e300:
            return float("inf")
    while f(lo) < 0:  # pragma: no cover - G(lo) ~ G(0) > rhs
        lo /= 1e3
    return _root_log(f, lo, hi)


def lambda_e2(canon: Canonical) -> float:
    """E2: type-II maximum likelihood of lambda (spec 003 §3.3 step 6)."""
    c = canon
    d, x2 = c.d, c.x**2
    s2 = c.sigma2
    if not s2 > 0:
        return float("inf") if s2 == 0 else 0.0

    def negll(lam):
        return 0.5 * float(np.sum(np.log1p(lam * d) + d * x2 / (s2 * (1.0 + lam * d))))

    lams = 1.0 / _k_grid(c)[::-1]
    vals = np.array([negll(v) for v in lams])
    i = int(np.argmin(vals))
    if negll(0.0) <= vals[i]:
        return 0.0
    lo = np.log(lams[max(i - 1, 0)])
    hi = np.log(lams[min(i + 1, lams.size - 1)])
    res = minimize_scalar(lambda t: negll(np.exp(t)), bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-10})
    return float(np.exp(res.x)) if res.fun <= vals[i] else float(lams[i])


def _sure(canon: Canonical, lam) -> np.ndarray:
    c = canon
    lam = np.atleast_1d(np.asarray(lam, dtype=float))[:, None]
    d, x2, s2 = c.d[None, :], c.x[None, :] ** 2, c.sigma2
    one_b = 1.0 / (1.0 + lam * d)
    return np.sum(s2 / d + one_b**2 * x2 - 2.0 * (s2 / d) * one_b, axis=1)


def lambda_e3(canon: Canonical) -> float:
    """E3: minimise SURE of the parameter loss over the GCV grid (lambda = 1/k) [X]."""
    c = canon
    if not c.sigma2 > 0:
        return float("inf") if c.sigma2 == 0 else 0.0
    lams = 1.0 / _k_grid(c)[::-1]  # ascending
    v = _sure(c, lams)
    i = int(np.argmin(v))
    if i == lams.size - 1:
        return float(lams[-1])
    lo = np.log(lams[max(i - 1, 0)])
    hi = np.log(lams[i + 1])
    res = minimize_scalar(lambda t: float(_sure(c, np.exp(t))[0]), bounds=(lo, hi),
                          method="bounded", options={"xatol": 1e-10})
    return float(np.exp(res.x)) if res.fun <= v[i] else float(lams[i])


def r_eff(canon: Canonical, lam: float) -> float:
    """``r_eff(lambda) = sum_i (1 + lambda d_r)/(1 + lambda d_i)`` (spec 003 §3.3)."""
    d = canon.d
    if np.isinf(lam):
        return float(np.sum(d[-1] / d))
    return float(np.sum((1.0 + lam * d[-1]) / (1.0 + lam * d)))


def lambda_zero(canon: Canonical) -> float:
    """lambda0: root of ``r_eff(lambda) = (r + 2)/2``; ``inf`` if r_eff never gets there."""
    r = canon.rank
    target = (r + 2) / 2.0
    if r_eff(canon, float("inf")) >= target:
        return float("inf")
    f = lambda lam: r_eff(canon, lam) - target  # noqa: E731
    lo, hi = 1e-12 / canon.d[0], 1.0 / canon.d[-1]
    while f(hi) > 0:
        hi *= 10.0
    while f(lo) < 0:  # pragma: no cover - r_eff(lo) ~ r > target
        lo /= 1e3
    return _root_log(f, lo, hi)


_RULES = {"E1": lambda_e1, "E2": lambda_e2, "E3": lambda_e3}


class EmpiricalBayesRidge(Estimator):
    """Empirical Bayes ridge regression (scikit-learn style).

    Parameters
    ----------
    prior_mean : (m,) array_like, optional
        Prior centre beta0; default 0 (the paper-faithful prior, spec 003 §3.3 step 0).
    prior_scale : (m,) array_like, optional
        Prior scales w (same units as the coefficients); default 1 (W = I).
    method : {"E1", "E2", "E3"}, default="E1"
        Rule for the variance ratio lambda (spec 003 §3.3 step 6).
    lambda_combination : {"star", "max", "min"}, default="star"
        Return lambda*, ``max(lambda*, lambda0)`` or ``min(lambda*, lambda0)``.
    rtol : float, default=1e-10
        Relative singular-value threshold of the rank decision.
    warn : bool, default=True
        Emit :class:`NonIdentifiableWarning` for a rank-deficient design and
        :class:`ShrinkageWarning` when lambda = 0 (estimate = prior centre).

    Attributes
    ----------
    coef_ : (m,) posterior-mean estimate.
    coef_cov_ : (m, m) posterior covariance (the one to publish, spec §3.3 step 8).
    coef_cov_sandwich_ : (m, m) sampling covariance with lambda fixed (0 along null
        directions; never read it as the accuracy of a non-estimable coefficient).
    coef_sd_, coef_sd_sandwich_ : square roots of their diagonals.
    lambda_ : the lambda used (prior variance *ratio*, not a precision).
    lambda_star_, lambda0_, minimax_sufficient_ : E-rule root, lambda0, flag.
    k_ : 1/lambda_.  shrinkage_ : (r,) factors b_i.  rank_, singular_values_,
    null_space_, sigma2_, dof_, r_eff_ : design and noise diagnostics.
    feature_names_in_ : names (from a DataFrame X, else x0, x1, ...).

    Examples
    --------
    Where the data determine every coefficient, the estimate is the truth within its
    posterior standard deviation:

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> X = rng.normal(size=(200, 3))
    >>> beta = np.array([1.0, -2.0, 0.5])
    >>> y = X @ beta + rng.normal(0.0, 0.1, 200)
    >>> ebr = EmpiricalBayesRidge().fit(X, y)
    >>> bool(np.all(np.abs(ebr.coef_ - beta) < 3 * ebr.coef_sd_)), ebr.rank_
    (True, 3)
    >>> bool(np.allclose(ebr.predict(X[:2]), X[:2] @ beta, atol=0.05))
    True
    """

    def __init__(self, *, prior_mean=None, prior_scale=None, method: str = "E1",
                 lambda_combination: str = "star", rtol: float = 1e-10, warn: bool = True):
        self.prior_mean = prior_mean
        self.prior_scale = prior_scale
        self.method = method
        self.lambda_combination = lambda_combination
        self.rtol = rtol
        self.warn = warn

    def fit(self, X, y) -> EmpiricalBayesRidge:
        """Fit to design ``X`` (N, m) and response ``y`` (N,). Returns ``self``."""
        names = getattr(X, "columns", None)
        X = np.asarray(X, dtype=float)
        if X.ndim != 2:
            raise InputError(f"X must be 2-D, got shape {X.shape}")
        m = X.shape[1]
        self.feature_names_in_ = (tuple(str(c) for c in names) if names is not None
                                  else tuple(f"x{j}" for j in range(m)))
        rule = str(self.method).upper()
        if rule not in _RULES:
            raise InputError(f"unknown EBR method '{self.method}' (use E1, E2 or E3)")
        if self.lambda_combination not in ("star", "max", "min"):
            raise InputError(f"unknown lambda_combination '{self.lambda_combination}'")
        canon = canonical_form(X, y, prior_mean=self.prior_mean, prior_scale=self.prior_scale,
                               rtol=self.rtol)
        if canon.dof <= 0:
            raise UnderdeterminedError(
                f"EBR needs more observations ({canon.n}) than the design rank ({canon.rank}) "
                "to estimate the noise variance")
        lam_star = _RULES[rule](canon)
        lam0 = lambda_zero(canon) if canon.rank >= 1 else float("inf")
        lam = {"star": lam_star, "max": max(lam_star, lam0),
               "min": min(lam_star, lam0)}[self.lambda_combination]
        fit = shrink(canon, lam)
        self.canonical_ = canon
        self.fit_ = fit
        self.lambda_star_ = lam_star
        self.lambda0_ = lam0
        self.minimax_sufficient_ = bool(lam_star <= lam0)
        self.lambda_ = lam
        self.k_ = fit.k
        self.shrinkage_ = fit.b
        self.coef_ = fit.coef
        self.coef_cov_ = fit.cov_posterior
        self.coef_cov_sandwich_ = fit.cov_sandwich
        self.coef_sd_ = fit.sd_posterior
        self.coef_sd_sandwich_ = fit.sd_sandwich
        self.rank_ = canon.rank
        self.singular_values_ = canon.singular_values_all
        self.null_space_ = canon.V_0 * canon.w[:, None]
        self.sigma2_ = canon.sigma2
        self.dof_ = canon.dof
        self.r_eff_ = r_eff(canon, lam) if canon.rank else float("nan")
        self.warnings_ = []
        if canon.rank < m:
            # null directions of A itself (V_0 spans the null space of A W; W V_0 that of A)
            Q, _ = np.linalg.qr(self.null_space_)
            text = "; ".join(null_space_text(Q, self.feature_names_in_))
            msg = (f"design has rank {canon.rank} < {m}: along {text} the estimate is the "
                   "prior centre, not information from the data")
            self.warnings_.append(msg)
            if self.warn:
                warnings.warn(msg, NonIdentifiableWarning, stacklevel=2)
        if lam == 0.0:
            msg = ("lambda = 0: the estimate equals the prior centre and the posterior "
                   "covariance is 0 (over-confident)")
            self.warnings_.append(msg)
            if self.warn:
                warnings.warn(msg, ShrinkageWarning, stacklevel=2)
        return self

    def _check(self):
        if not hasattr(self, "coef_"):
            raise NotFittedError("EmpiricalBayesRidge is not fitted; call fit(X, y) first")

    def predict(self, X) -> np.ndarray:
        """``X @ coef_``."""
        self._check()
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != self.coef_.size:
            raise InputError(f"X must have {self.coef_.size} columns, got shape {X.shape}")
        return X @ self.coef_

    def bias(self, beta_true) -> np.ndarray:
        """Exact bias for a known truth (simulation), spec 003 §3.3 step 8."""
        self._check()
        return self.fit_.bias(beta_true)

    def closed_form_coef(self) -> np.ndarray:
        """``beta0 + W (At^T At + k I)^-1 At^T z``: the closed form, as a cross-check."""
        self._check()
        c = self.canonical_
        if self.lambda_ == 0.0:
            return c.beta0.copy()
        At = c.A * c.w
        k = self.k_
        g = np.linalg.solve(At.T @ At + k * np.eye(At.shape[1]), At.T @ c.z)
        return c.beta0 + c.w * g
