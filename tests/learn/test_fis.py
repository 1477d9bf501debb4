"""Tests of inertialab.learn.fis (spec 000 §8.1.5)."""

from __future__ import annotations

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.learn.fis import TSKFIS, genfis, grid_fis


def test_one_rule_fis_equals_linear_regression():
    rng = np.random.default_rng(0)
    X = rng.random((80, 2))
    y = 1.5 * X[:, 0] - 0.7 * X[:, 1] + 0.2 + 0.05 * np.sin(7 * X[:, 0])
    # a huge radius makes every point's potential alike: exactly one cluster
    fis = genfis(X, y, radius=5.0)
    assert fis.n_rules == 1
    A = np.column_stack([X, np.ones(len(y))])
    beta = np.linalg.lstsq(A, y, rcond=None)[0]
    np.testing.assert_allclose(fis.consequents[0], beta, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(fis.predict(X), A @ beta, atol=1e-12)


def test_genfis_widths_and_centres_follow_subclust():
    rng = np.random.default_rng(1)
    X = rng.random((100, 2)) * [4.0, 0.5]
    y = np.sin(X[:, 0]) + X[:, 1]
    fis = genfis(X, y, radius=0.4)
    span = np.ptp(X, axis=0)
    expected = 0.4 * span / np.sqrt(8.0)
    np.testing.assert_allclose(fis.mf_sigma.reshape(-1, 2), np.tile(expected, (fis.n_rules, 1)))
    # every rule centre is one of the data points (inputs of a subtractive-clustering centre)
    centres = fis.mf_center.reshape(-1, 2)
    for c in centres:
        assert np.min(np.abs(X - c).sum(axis=1)) < 1e-12


def test_normalised_firing_sums_to_one_and_falls_back_to_nearest_rule():
    fis = TSKFIS([0, 0], [0.0, 1.0], [0.01, 0.01], [[0], [1]], [[0.0, 1.0], [0.0, 2.0]])
    wb = fis.normalized_firing(np.array([[0.2], [50.0], [-50.0]]))
    np.testing.assert_allclose(wb.sum(axis=1), 1.0)
    # at x = 50 every w underflows (exp(-1.2e7)); the nearest rule (centre 1) alone fires
    np.testing.assert_allclose(wb[1], [0.0, 1.0])
    np.testing.assert_allclose(wb[2], [1.0, 0.0])
    # analytic value at 0.2: w1/w0 = exp(-(0.8^2 - 0.2^2)/(2e-4))... = exp(-3000)
    assert wb[0, 0] == pytest.approx(1.0)


def test_predict_matches_hand_computed_two_rule_system():
    fis = TSKFIS([0, 1, 0, 1], [0.0, 0.0, 1.0, 1.0], [0.5, 0.5, 0.5, 0.5],
                 [[0, 1], [2, 3]], [[1.0, 2.0, 3.0], [-1.0, 0.5, 0.0]])
    x = np.array([[0.3, 0.6]])
    w0 = np.exp(-(0.3**2 + 0.6**2) / 0.5)
    w1 = np.exp(-(0.7**2 + 0.4**2) / 0.5)
    f0 = 0.3 + 1.2 + 3.0
    f1 = -0.3 + 0.3
    assert fis.predict(x)[0] == pytest.approx((w0 * f0 + w1 * f1) / (w0 + w1), rel=1e-14)


def test_grid_fis_neighbours_cross_at_one_half():
    X = np.random.default_rng(2).random((30, 2))
    fis = grid_fis(X, n_mfs=3, bounds=[[0, 0], [1, 1]])
    assert fis.n_rules == 9
    c, s = fis.mf_center[:3], fis.mf_sigma[:3]
    mid = 0.5 * (c[0] + c[1])
    assert np.exp(-(mid - c[0]) ** 2 / (2 * s[0] ** 2)) == pytest.approx(0.5, rel=1e-12)


def test_serialisation_round_trip_and_validation():
    X = np.random.default_rng(4).random((40, 2))
    fis = genfis(X, X[:, 0] * X[:, 1])
    back = TSKFIS.from_dict(fis.to_dict())
    np.testing.assert_array_equal(back.predict(X), fis.predict(X))
    with pytest.raises(InputError):
        TSKFIS([0], [0.0], [-1.0], [[0]])
    with pytest.raises(InputError):
        fis.predict(np.zeros((3, 3)))
