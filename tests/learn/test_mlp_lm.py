"""Tests of the LM-trained MLP (spec 004 §3.5-3.6, acceptance A2-A4)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from inertialab.errors import DataQualityWarning, InputError
from inertialab.learn.mlp_lm import (
    MLPRegressorLM,
    forward,
    jacobian,
    n_params,
    nguyen_widrow,
    split_indices,
    train_lm,
    unpack,
)


def test_jacobian_matches_central_differences():
    # A2: analytic vs central finite differences, max relative error < 1e-6.
    rng = np.random.default_rng(3)
    d, S = 3, 7
    theta = rng.normal(size=n_params(d, S))
    X = rng.uniform(-1, 1, size=(40, d))
    J = jacobian(theta, X, S)
    h = 1e-6
    Jfd = np.empty_like(J)
    for k in range(theta.size):
        tp, tm = theta.copy(), theta.copy()
        tp[k] += h
        tm[k] -= h
        Jfd[:, k] = (forward(tp, X, S) - forward(tm, X, S)) / (2 * h)
    # Central differences: truncation O(h^2) ~ 1e-12, rounding ~ eps/h ~ 1e-10, so
    # 1e-6 relative (entries below 1e-2 in size compared absolutely at 1e-8) is safe.
    rel = np.abs(J - Jfd) / np.maximum(np.abs(Jfd), 1e-2)
    assert rel.max() < 1e-6


def test_nguyen_widrow_layout():
    d, S = 2, 10
    theta = nguyen_widrow(d, S, rng=1)
    W1, b1, W2, b2 = unpack(theta, d, S)
    beta = 0.7 * S ** (1 / d)
    np.testing.assert_allclose(np.linalg.norm(W1, axis=1), 2 * beta, rtol=1e-12)
    lam = np.linspace(-1, 1, S)
    np.testing.assert_allclose(b1, 2 * beta * lam * np.sign(W1[:, 0]), rtol=1e-12)
    assert np.all(np.abs(W2) <= 1) and abs(b2) <= 1


def test_split_counts_round_half_up():
    # spec 004 §3.4: n_val = floor(0.1 Q + 0.5): Q = 85 -> 9 (banker's round(8.5) = 8).
    tr, va = split_indices(85, 0.1, "random", 0)
    assert va.size == 9 and tr.size == 76
    assert np.intersect1d(tr, va).size == 0
    tr, va = split_indices(85, 0.1, "block", 0)
    np.testing.assert_array_equal(va, np.arange(76, 85))


def _teacher(seed, n=200):
    rng = np.random.default_rng(seed)
    Wt = rng.normal(size=n_params(2, 5))
    X = rng.uniform(-1, 1, size=(n, 2))
    return X, forward(Wt, X, 5)


@pytest.mark.slow
def test_lm_converges_on_teacher_net():
    # A3: student 2-5-1, no validation, min_grad 0, best of 5 restarts, 300 epochs:
    # training MSE < 1e-4 var(target) in >= 9/10 seeds.
    ok = 0
    for seed in range(10):
        X, y = _teacher(seed)
        best = np.inf
        for r in range(5):
            net = MLPRegressorLM(hidden=5, max_epochs=300, min_grad=0.0, val_fraction=0.0,
                                 scale=False, rng=100 * seed + r).fit(X, y)
            best = min(best, float(np.mean((net.predict(X) - y) ** 2)))
        ok += best < 1e-4 * np.var(y)
    assert ok >= 9


def test_learns_known_function():
    # sin(pi x) on [-1, 1], 300 samples with noise 0.01: the held-out RMSE must be
    # near the noise floor; 0.03 allows 3x the noise for approximation error.
    rng = np.random.default_rng(0)
    x = rng.uniform(-1, 1, 300)
    y = np.sin(np.pi * x) + rng.normal(0, 0.01, x.size)
    net = MLPRegressorLM(hidden=8, rng=5).fit(x, y)
    xt = np.linspace(-0.95, 0.95, 101)
    err = net.predict(xt) - np.sin(np.pi * xt)
    assert np.sqrt(np.mean(err ** 2)) < 0.03
    assert net.report_.n_val == 30 and net.report_.n_train == 270


def test_early_stopping_returns_best_validation_theta():
    # A4: crafted case: the validation targets are the negated training function, so
    # fitting the training data worsens validation; the run must stop on max_fail
    # exactly 6 epochs after the best validation epoch and return that epoch's theta.
    rng = np.random.default_rng(1)
    X = rng.uniform(-1, 1, size=(80, 1))
    y = np.sin(3 * X[:, 0])
    Xv = rng.uniform(-1, 1, size=(20, 1))
    yv = -np.sin(3 * Xv[:, 0])
    theta0 = nguyen_widrow(1, 6, rng=2)
    theta, rep = train_lm(theta0, X, y, 6, X_val=Xv, y_val=yv)
    assert rep.stop_reason == "max_fail"
    assert rep.epochs - rep.best_epoch == 6
    v = np.asarray(rep.val_mse)
    assert v[rep.best_epoch] == v.min()
    assert np.all(v[rep.best_epoch + 1:] >= v.min())
    # independent recomputation of the returned theta's validation MSE
    vm = float(np.mean((forward(theta, Xv, 6) - yv) ** 2))
    assert vm == pytest.approx(v.min(), rel=1e-12)


def test_training_mse_never_increases():
    X, y = _teacher(4, n=60)
    theta0 = nguyen_widrow(2, 4, rng=0)
    _, rep = train_lm(theta0, X, y, 4, max_epochs=50, min_grad=0.0)
    t = np.asarray(rep.train_mse)
    assert np.all(np.diff(t) <= 0)


def test_scaling_is_equivariant():
    # mapminmax makes the fit invariant to an affine change of the target's unit:
    # predictions of y' = 1000 y + 5 equal 1000 * predictions of y + 5 (rounding only).
    rng = np.random.default_rng(2)
    X = rng.uniform(0, 50, size=(60, 2))
    y = np.tanh(X[:, 0] / 25 - 1) + 0.1 * X[:, 1] / 50
    a = MLPRegressorLM(hidden=4, rng=9, max_epochs=40).fit(X, y)
    b = MLPRegressorLM(hidden=4, rng=9, max_epochs=40).fit(X, 1000 * y + 5)
    np.testing.assert_allclose(b.predict(X), 1000 * a.predict(X) + 5, rtol=1e-7, atol=1e-6)


def test_same_seed_same_numbers_and_roundtrip():
    X, y = _teacher(7, n=100)
    a = MLPRegressorLM(hidden=5, rng=11).fit(X, y)
    b = MLPRegressorLM(hidden=5, rng=11).fit(X, y)
    np.testing.assert_array_equal(a.predict(X), b.predict(X))
    c = MLPRegressorLM.from_dict(json.loads(json.dumps(a.to_dict())))
    np.testing.assert_array_equal(c.predict(X), a.predict(X))


def test_explicit_validation_overrides_fraction():
    X, y = _teacher(8, n=50)
    Xv, yv = _teacher(9, n=13)
    net = MLPRegressorLM(hidden=3, rng=0).fit(X, y, validation=(Xv, yv))
    assert net.report_.n_train == 50 and net.report_.n_val == 13


def test_constant_target_warns_and_predicts_constant():
    X = np.linspace(0, 1, 30)
    with pytest.warns(DataQualityWarning):
        net = MLPRegressorLM(hidden=3, rng=0).fit(X, np.full(30, 2.5))
    np.testing.assert_allclose(net.predict(X), 2.5, atol=1e-12)


def test_errors():
    with pytest.raises(RuntimeError):
        MLPRegressorLM().predict(np.zeros((2, 1)))
    with pytest.raises(InputError):
        MLPRegressorLM(split="middle").fit(np.zeros((10, 1)), np.arange(10.0))
    with pytest.raises(InputError):
        MLPRegressorLM().fit(np.zeros((10, 1)), np.arange(9.0))
    with pytest.raises(InputError):
        MLPRegressorLM().fit(np.full((10, 1), np.nan), np.arange(10.0))
