"""The one polynomial regressor family (learn/poly.py): total-degree, separable and
tensor-product polynomials (spec 001 §3.9, spec 000 §4 POLY-2D) and POLY-SEP."""

from __future__ import annotations

import numpy as np
import pytest

from inertialab.errors import NotFittedError
from inertialab.learn.poly import PolynomialRegressor, SeparatePolynomials


def test_tensor_polynomial_is_least_squares_on_its_monomials():
    rng = np.random.default_rng(0)
    X = rng.random((50, 2)) * [100, 1000]
    y = 3 + 0.2 * X[:, 0] - 1e-3 * X[:, 0] ** 2 * X[:, 1] + 1e-5 * X[:, 0] ** 3
    tp = PolynomialRegressor(degrees=(3, 1)).fit(X, y)
    np.testing.assert_allclose(tp.predict(X), y, rtol=1e-9, atol=1e-8)
    # T^m N^n for m <= 3, n <= 1: 8 monomials, first input's power outermost
    assert tp.powers_ == [(0, 0), (0, 1), (1, 0), (1, 1), (2, 0), (2, 1), (3, 0), (3, 1)]
    # a T^3 N term (total degree 4) is in the (3, 1) tensor set, not in total degree 3
    y4 = y + 1e-6 * X[:, 0] ** 3 * X[:, 1]
    tp4 = PolynomialRegressor(degrees=(3, 1)).fit(X, y4)
    np.testing.assert_allclose(tp4.predict(X), y4, rtol=1e-9, atol=1e-6)
    td = PolynomialRegressor(degree=3).fit(X, y4)
    assert np.max(np.abs(td.predict(X) - y4)) > 1.0
    back = PolynomialRegressor.from_dict(tp.to_dict())
    np.testing.assert_array_equal(back.predict(X), tp.predict(X))


def test_separate_polynomials_recover_cubic_bias_and_scale_factor():
    # a unit whose bias and scale factor are exact cubics in T: POLY-SEP is exact
    T = np.repeat(np.arange(-40.0, 71.0, 10.0), 24)
    a = np.tile(np.round(np.sin(np.deg2rad(15.0 * np.arange(24))), 15), 12)
    k0 = 2.0 + 0.01 * T - 1e-4 * T ** 2 + 1e-6 * T ** 3
    k1 = 1000.0 * (1 + 3e-5 * T - 1e-7 * T ** 2)
    N = k0 + k1 * a
    ref = {"k0": 2.5, "k1": 1001.0, "k2": 0.0}
    sep = SeparatePolynomials(degree=3).fit(T, N, a, T, ref)
    pred = sep.predict(np.column_stack([T, N]))
    np.testing.assert_allclose(pred, ref["k0"] + ref["k1"] * a, atol=1e-8)
    assert SeparatePolynomials.from_dict(sep.to_dict()).to_dict() == sep.to_dict()
    with pytest.raises(NotFittedError):
        SeparatePolynomials().predict(np.zeros((1, 2)))
