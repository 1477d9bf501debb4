"""Ridge with HKB and GCV k in canonical form (spec 003 §3.4)."""

import numpy as np
import pytest

from inertialab.regress.ridge import canonical_form, gcv_curve, k_gcv, ridge, shrink


@pytest.fixture()
def problem():
    rng = np.random.default_rng(7)
    X = rng.standard_normal((25, 5))
    X[:, 4] = X[:, 3] + 1e-3 * rng.standard_normal(25)  # near-collinear pair
    beta = np.array([1.0, 0.5, -0.3, 0.2, 0.1])
    y = X @ beta + 0.2 * rng.standard_normal(25)
    return X, y, beta


def test_fixed_k_equals_textbook_ridge(problem):
    X, y, _ = problem
    k = 0.37
    ref = np.linalg.solve(X.T @ X + k * np.eye(5), X.T @ y)  # independent closed form
    np.testing.assert_allclose(ridge(X, y, k=k).coef, ref, rtol=1e-10)


def test_prior_centre_and_scale_equal_generalised_closed_form(problem):
    X, y, _ = problem
    b0 = np.array([0.9, 0.4, -0.2, 0.1, 0.1])
    w = np.array([1.0, 2.0, 0.5, 0.3, 0.3])
    k = 0.8
    At = X * w
    ref = b0 + w * np.linalg.solve(At.T @ At + k * np.eye(5), At.T @ (y - X @ b0))
    np.testing.assert_allclose(ridge(X, y, k=k, prior_mean=b0, prior_scale=w).coef, ref,
                               rtol=1e-10)


def test_hkb_k_formula(problem):
    X, y, _ = problem
    ls = np.linalg.lstsq(X, y, rcond=None)[0]
    s2 = np.sum((y - X @ ls) ** 2) / (25 - 5)
    assert ridge(X, y, k="hkb").k == pytest.approx(5 * s2 / (ls @ ls), rel=1e-10)


def test_gcv_curve_matches_direct_hat_matrix_and_minimum(problem):
    X, y, _ = problem
    canon = canonical_form(X, y)
    for k in (1e-3, 0.1, 3.0):
        H = X @ np.linalg.solve(X.T @ X + k * np.eye(5), X.T)
        direct = 25 * np.sum((y - H @ y) ** 2) / (25 - np.trace(H)) ** 2
        assert gcv_curve(canon, k)[0] == pytest.approx(direct, rel=1e-9)
    kb = k_gcv(canon)
    ks = np.logspace(np.log10(kb) - 1, np.log10(kb) + 1, 201)
    # refined optimum is no worse than any point of a fine local grid
    assert gcv_curve(canon, kb)[0] <= gcv_curve(canon, ks).min() * (1 + 1e-9)


def test_bias_and_sandwich_match_monte_carlo(problem):
    X, _, beta = problem
    rng = np.random.default_rng(11)
    sigma, k = 0.2, 2.0
    canon0 = canonical_form(X, X @ beta)
    fit0 = shrink(canon0, 1 / k)
    est = np.array([ridge(X, X @ beta + sigma * rng.standard_normal(25), k=k).coef
                    for _ in range(4000)])
    # bias is exact (linear estimator); 4000 runs: SE of the mean ~ sd/63
    L = np.linalg.solve(X.T @ X + k * np.eye(5), X.T)  # estimator = L y
    sd_true = sigma * np.sqrt(np.diag(L @ L.T))
    s2 = canonical_form(X, X @ beta + sigma * rng.standard_normal(25)).sigma2
    sand = shrink(canonical_form(X, X @ beta), 1 / k).cov_sandwich  # sigma2 = 0 here
    assert np.max(np.abs(sand)) < 1e-28  # noise-free: sigma2 is round-off only
    fit = shrink(canonical_form(X, X @ beta + sigma * rng.standard_normal(25)), 1 / k)
    np.testing.assert_allclose(fit.sd_sandwich / np.sqrt(fit.canon.sigma2),
                               sd_true / sigma, rtol=1e-9)  # sandwich = sigma^2 L L^T
    assert s2 > 0
    np.testing.assert_allclose(est.mean(0) - beta, fit0.bias(beta), atol=4 * sd_true.max() / 63)
    np.testing.assert_allclose(est.std(0), sd_true, rtol=0.05)  # SD of SD ~ 1/sqrt(8000)
