"""Nonlinear least squares with covariance and the batched Gauss-Newton (spec 002 §3.6, §6.4)."""

import numpy as np
import pytest
from scipy.optimize import curve_fit

from inertialab.errors import InputError
from inertialab.regress.nlls import batched_gauss_newton, covariance, levenberg_marquardt


def expo_problem(seed=0, n=60):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 4, n)
    y = 2.5 * np.exp(-0.7 * t) + 0.3 + 0.01 * rng.standard_normal(n)
    return t, y


def test_lm_matches_curve_fit_and_its_covariance():
    # independent implementation: scipy.optimize.curve_fit's pcov (absolute_sigma=False)
    # uses the same s^2 (J^T J)^-1; agreement limited by optimiser tolerance (~1e-8 rel)
    t, y = expo_problem()
    f = lambda p: p[0] * np.exp(-p[1] * t) + p[2] - y  # noqa: E731
    res = levenberg_marquardt(f, np.array([1.0, 1.0, 0.0]))
    popt, pcov = curve_fit(lambda t, a, b, c: a * np.exp(-b * t) + c, t, y, p0=[1, 1, 0])
    assert np.allclose(res.x, popt, rtol=1e-6)
    assert np.allclose(res.cov, pcov, rtol=1e-4)
    assert np.allclose(res.stderr, np.sqrt(np.diag(pcov)), rtol=1e-4)


def test_linear_covariance_is_textbook():
    # linear model y = X b: cov = s^2 (X^T X)^-1 exactly (analytic truth)
    rng = np.random.default_rng(1)
    X = np.column_stack([np.ones(30), rng.standard_normal(30)])
    y = X @ [1.0, 2.0] + 0.1 * rng.standard_normal(30)
    res = levenberg_marquardt(lambda b: X @ b - y, np.zeros(2), jac=lambda b: X)
    bhat = np.linalg.lstsq(X, y, rcond=None)[0]
    r = X @ bhat - y
    cov = (r @ r / 28) * np.linalg.inv(X.T @ X)
    assert np.allclose(res.x, bhat, atol=1e-12)
    assert np.allclose(res.cov, cov, rtol=1e-9)


def test_covariance_null_when_singular_or_underdetermined():
    J = np.array([[1.0, 1.0], [2.0, 2.0], [3.0, 3.0]])
    assert covariance(J, np.ones(3)).cov is None
    assert covariance(np.eye(2), np.ones(2)).cov is None  # m == p


def test_underdetermined_raises():
    with pytest.raises(InputError, match="underdetermined"):
        levenberg_marquardt(lambda p: np.array([p[0] - 1.0]), np.zeros(3))


def test_bounded_and_robust_variants():
    t, y = expo_problem(2)
    y = y.copy()
    y[::10] += 1.0  # gross outliers
    f = lambda p: p[0] * np.exp(-p[1] * t) + p[2] - y  # noqa: E731
    plain = levenberg_marquardt(f, np.array([1.0, 1.0, 0.0]))
    robust = levenberg_marquardt(f, np.array([1.0, 1.0, 0.0]), loss="soft_l1", f_scale=0.03)
    truth = np.array([2.5, 0.7, 0.3])
    assert np.max(np.abs(robust.x - truth)) < np.max(np.abs(plain.x - truth))
    assert np.max(np.abs(robust.x - truth)) < 0.05
    bounded = levenberg_marquardt(f, np.array([1.0, 1.0, 0.0]), bounds=([0, 0, 0.5], [5, 5, 1]))
    assert bounded.x[2] >= 0.5 - 1e-12


def test_batched_gauss_newton_matches_per_problem_lm():
    # U exponential fits in one batch must agree with scipy per problem (1e-8, both converge to
    # the same unique least-squares minimum at tolerance 1e-12)
    U = 40
    rng = np.random.default_rng(3)
    t = np.linspace(0, 4, 50)
    P = np.column_stack([rng.uniform(1, 3, U), rng.uniform(0.3, 1.0, U), rng.uniform(-1, 1, U)])
    Y = P[:, :1] * np.exp(-P[:, 1:2] * t) + P[:, 2:3] + 0.01 * rng.standard_normal((U, t.size))

    def fun_jac(X, idx):
        e = np.exp(-X[:, 1:2] * t)
        R = X[:, :1] * e + X[:, 2:3] - Y[idx]
        J = np.stack([e, -X[:, :1] * t * e, np.ones_like(e)], axis=2)
        return R, J

    res = batched_gauss_newton(fun_jac, np.tile([1.0, 1.0, 0.0], (U, 1)))
    assert res.converged.all()
    for u in range(U):
        ref = levenberg_marquardt(lambda p, u=u: p[0] * np.exp(-p[1] * t) + p[2] - Y[u],
                                  np.array([1.0, 1.0, 0.0]))
        assert np.allclose(res.x[u], ref.x, atol=1e-8)
        assert np.allclose(res.stderr[u], ref.stderr, rtol=1e-5)
