"""Empirical Bayes ridge (spec 003 §3.3, AC-5)."""

import warnings

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError, NonIdentifiableWarning, NotFittedError, ShrinkageWarning
from inertialab.regress.ebr import (
    _G,
    EmpiricalBayesRidge,
    _sure,
    lambda_e2,
    lambda_zero,
    r_eff,
)
from inertialab.regress.lstsq import lstsq
from inertialab.regress.ridge import canonical_form

NAMES = ["KA0", "KB0", "kA1", "kB1", "eta", "KA2", "KB2", "KAx", "KBx"]
BETA = np.array([5e-4, -3e-4, 1.5e-4, -8e-5, 1.2e-4, 4e-5, 1.5e-5, 1e-5, -8e-6])


def _g2(n):
    t = 2 * np.pi * np.arange(n) / n
    s, c = np.sin(t), np.cos(t)
    return np.column_stack([s, c, s * s, c * c, -s * c, s**3, c**3, s * s * c, -s * c * c])


def _equal_d(seed=0, N=30, m=6, d=4.0):
    rng = np.random.default_rng(seed)
    Q, _ = np.linalg.qr(rng.standard_normal((N, m)))
    X = Q * np.sqrt(d)
    y = X @ rng.normal(0, 0.3, m) + 0.5 * rng.standard_normal(N)
    return X, y


def test_e1_equals_james_stein_for_equal_d():
    for seed in range(5):
        X, y = _equal_d(seed)
        e = EmpiricalBayesRidge(warn=False).fit(X, y)
        c = e.canonical_
        N, r, d = 30, 6, 4.0
        x2 = float(c.x @ c.x)
        b_js = max(0.0, 1 - (r - 2) * c.rss / ((N - r + 2) * d * x2))
        # the E1 root is found to rtol 1e-12 in log lambda
        np.testing.assert_allclose(e.shrinkage_, b_js, atol=1e-12)


def test_g_is_strictly_decreasing():
    X, y = _equal_d(3)
    canon = canonical_form(_g2(20), _g2(20) @ BETA + 1e-6 * np.sin(np.arange(20.0)))
    lams = np.logspace(-6, 14, 200)
    for c in (canonical_form(X, y), canon):
        g = np.array([_G(c, v) for v in lams])
        assert np.all(np.diff(g) < 0)


def test_lambda_zero_path_returns_prior_centre_with_warning():
    rng = np.random.default_rng(5)
    X = rng.standard_normal((40, 5))
    b0 = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    Q, _ = np.linalg.qr(X)
    noise = rng.standard_normal(40)
    noise -= Q @ (Q.T @ noise)  # residual space only: x = 0 exactly, so G(0) = 0 <= rhs
    y = X @ b0 + noise
    with pytest.warns(ShrinkageWarning):
        e = EmpiricalBayesRidge(prior_mean=b0).fit(X, y)
    assert e.lambda_ == 0.0
    np.testing.assert_array_equal(e.coef_, b0)
    assert np.all(e.coef_cov_ == 0)


def test_closed_form_equals_canonical_on_paper_system():
    rng = np.random.default_rng(2)
    A = _g2(20)
    y = A @ BETA + 8e-7 * rng.standard_normal(20)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NonIdentifiableWarning)
        e = EmpiricalBayesRidge().fit(A, y)
    # k/d_r ~ 1e-5: the normal-equation solve loses digits (spec AC-5 tolerance 1e-9)
    assert np.max(np.abs(e.closed_form_coef() - e.coef_)) < 1e-9 * np.max(np.abs(e.coef_))
    # paper-faithful prior: null-space part zero, so EBR ~ min-norm LS (AC-7 first part)
    mn = lstsq(A, y).coef
    assert np.max(np.abs(e.coef_ - mn)) < 1e-8


def test_posterior_covariance_equals_conjugate_formula():
    rng = np.random.default_rng(4)
    A = _g2(12)
    y = A @ BETA + 1e-6 * rng.standard_normal(12)
    w = np.array([2e-5, 2e-5, 3e-5, 3e-5, 5e-6, 5e-6, 5e-6, 5e-6, 5e-6])
    b0 = BETA + 1e-5
    e = EmpiricalBayesRidge(prior_mean=b0, prior_scale=w, warn=False).fit(A, y)
    # independent: posterior of beta is N(., sigma^2 (A^T A + k W^-2)^-1) with k = 1/lambda
    k = 1 / e.lambda_
    ref = e.sigma2_ * np.linalg.inv(A.T @ A + k * np.diag(1 / w**2))
    np.testing.assert_allclose(e.coef_cov_, ref, rtol=1e-6, atol=1e-12 * np.abs(ref).max())
    ref_mean = b0 + np.linalg.solve(A.T @ A + k * np.diag(1 / w**2), A.T @ (y - A @ b0))
    np.testing.assert_allclose(e.coef_, ref_mean, rtol=1e-6, atol=1e-12)


def test_nonidentifiable_warning_names_null_directions():
    A = pd.DataFrame(_g2(20), columns=NAMES)
    y = A.to_numpy() @ BETA + 1e-6 * np.cos(np.arange(20.0))
    with pytest.warns(NonIdentifiableWarning, match=r"KA0 .*KA2 .*KBx.*KB0 .*KB2 .*KAx"):
        EmpiricalBayesRidge().fit(A, y)


def test_e2_score_equation_and_e3_minimum():
    X, y = _equal_d(3, N=30, m=6, d=1.0)  # seed with an interior E2 optimum
    X = X * np.sqrt(np.array([1, 2, 4, 8, 16, 32.0]))
    c = canonical_form(X, y)
    lam = lambda_e2(c)
    d, x2, s2 = c.d, c.x**2, c.sigma2
    assert 0 < lam < np.inf
    lhs = np.sum(d / (1 + lam * d))
    rhs = np.sum(d**2 * x2 / (s2 * (1 + lam * d) ** 2))
    assert lhs == pytest.approx(rhs, rel=1e-6)  # score = 0 at the interior optimum
    e3 = EmpiricalBayesRidge(method="E3", warn=False).fit(X, y).lambda_
    grid = np.logspace(np.log10(e3) - 2, np.log10(e3) + 2, 401)
    smin = _sure(c, grid).min()
    assert _sure(c, e3)[0] <= smin + 1e-9 * abs(smin)  # no fine-grid point does better


def test_lambda0_root_and_combination():
    A = _g2(20)
    y = A @ BETA + 1e-6 * np.sin(3.3 * np.arange(20.0))
    e = EmpiricalBayesRidge(warn=False).fit(A, y)
    assert r_eff(e.canonical_, e.lambda0_) == pytest.approx((7 + 2) / 2, rel=1e-9)
    assert e.minimax_sufficient_ == (e.lambda_star_ <= e.lambda0_)
    emax = EmpiricalBayesRidge(lambda_combination="max", warn=False).fit(A, y)
    assert emax.lambda_ == max(e.lambda_star_, e.lambda0_)
    assert lambda_zero(e.canonical_) == e.lambda0_


def test_predict_before_fit_and_bad_method():
    with pytest.raises(NotFittedError):
        EmpiricalBayesRidge().predict(np.ones((2, 2)))
    with pytest.raises(InputError):
        EmpiricalBayesRidge(method="E9").fit(np.eye(3), np.ones(3))
