"""Rank-aware least squares (spec 003 §3.2, AC-1)."""

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.regress.lstsq import lstsq, naive_normal_equations, sparse_null_basis


def _g2(n):
    t = 2 * np.pi * np.arange(n) / n
    s, c = np.sin(t), np.cos(t)
    return np.column_stack([s, c, s * s, c * c, -s * c, s**3, c**3, s * s * c, -s * c * c])


def test_full_rank_matches_numpy_and_textbook_covariance():
    # independent implementation: numpy.linalg.lstsq and (X^T X)^-1 for the covariance
    rng = np.random.default_rng(1)
    X = rng.standard_normal((30, 4))
    y = X @ np.array([1.0, -2.0, 0.5, 3.0]) + 0.1 * rng.standard_normal(30)
    r = lstsq(X, y)
    ref = np.linalg.lstsq(X, y, rcond=None)[0]
    assert r.rank == 4 and r.dof == 26
    np.testing.assert_allclose(r.coef, ref, rtol=1e-12)  # both SVD solutions, round-off only
    s2 = np.sum((y - X @ ref) ** 2) / 26
    np.testing.assert_allclose(r.sd, np.sqrt(s2 * np.diag(np.linalg.inv(X.T @ X))), rtol=1e-10)
    assert r.estimable.all()


def test_ac1_rank_seven_and_null_space_of_g2_design():
    A = _g2(20)
    r = lstsq(A, np.zeros(20) + 1e-3 * np.sin(np.arange(20)))
    assert r.rank == 7
    assert r.singular_values[7] / r.singular_values[0] < 1e-12
    assert r.cond > 1e12
    # spec §1.6 singular values for 20 equally spaced positions (printed to 4 figures)
    np.testing.assert_allclose(r.singular_values[:7],
                               [4.044, 4.044, 3.162, 2.236, 1.581, 1.071, 1.071], atol=6e-4)
    n1 = np.zeros(9)
    n1[[0, 5, 8]] = (-1, 1, -1)
    n2 = np.zeros(9)
    n2[[1, 6, 7]] = (-1, 1, 1)
    Q, _ = np.linalg.qr(np.column_stack([n1, n2]))
    cosines = np.linalg.svd(Q.T @ r.null_space, compute_uv=False)  # principal angles
    assert np.all(cosines > 1 - 1e-9)
    # kA1, kB1, eta estimable alone; K0, K2, Kx not
    assert r.estimable.tolist() == [False, False, True, True, True, False, False, False, False]
    assert np.all(np.isinf(r.sd[~r.estimable])) and np.all(np.isfinite(r.sd[r.estimable]))


def test_combination_estimable_and_not():
    A = _g2(20)
    beta = np.array([5e-4, -3e-4, 1.5e-4, -8e-5, 1.2e-4, 4e-5, 1.5e-5, 1e-5, -8e-6])
    r = lstsq(A, A @ beta)
    c = np.zeros(9)
    c[[5, 8]] = 1.0  # KA2 + KBx is estimable, and exact for noise-free data
    comb = r.combination(c, "KA2+KBx")
    assert comb.value == pytest.approx(beta[5] + beta[8], abs=1e-15)
    with pytest.raises(InputError, match="not estimable"):
        r.combination(np.eye(9)[5], "KA2")


def test_sparse_null_basis_reads_off_couplings():
    A = _g2(20)
    r = lstsq(A, np.ones(20))
    B = sparse_null_basis(r.null_space)
    # pivot at KA0 and KB0 with unit weight: n1 = (1, -1, 1) on (KA0, KA2, KBx)
    np.testing.assert_allclose(B[[0, 5, 8], 0], [1, -1, 1], atol=1e-12)
    np.testing.assert_allclose(B[[1, 6, 7], 1], [1, -1, -1], atol=1e-12)


def test_naive_normal_equations_are_unstable_on_rank_deficient_design():
    A = _g2(20)
    rng = np.random.default_rng(3)
    y = A @ np.full(9, 1e-4) + 1e-6 * rng.standard_normal(20)
    b = naive_normal_equations(A, y)
    # either LAPACK flags singularity (NaN) or the solution wanders along the null space
    # by more than the coefficients' own size (1e-4); min-norm has no null component
    mn = lstsq(A, y).coef
    assert np.any(np.isnan(b)) or np.max(np.abs(b - mn)) > 1e-4


def test_bad_shapes_rejected():
    with pytest.raises(InputError):
        lstsq(np.ones((3, 2)), np.ones(4))
    with pytest.raises(InputError):
        lstsq(np.array([[1.0, np.nan]]), np.ones(1))
