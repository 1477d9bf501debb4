"""Tests of the triaxial accelerometer model (spec 002 §1.2, §3.1, §3.6, §7.1 items 1-2, 4-5)."""

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.regress.nlls import levenberg_marquardt
from inertialab.sensors import triaxial as tx

X_TRUE = np.array([0.25, -0.35, 0.55, 1.021, 0.985, 1.012, 0.012, -0.008, 0.015])  # §6.1
PHI = np.array([0.003, -0.004, 0.006])


def sphere(n, seed=0, g=9.8):
    d = np.random.default_rng(seed).standard_normal((n, 3))
    return g * d / np.linalg.norm(d, axis=1)[:, None]


def random_x(rng):
    box = tx.search_box("scalar")
    return box[:, 0] + (box[:, 1] - box[:, 0]) * rng.random(9)


def test_round_trip_random_params():
    # §7.1 item 1: correct(forward(x, a)) == a to 1e-12 (pure float round-off of a 3x3 solve)
    rng = np.random.default_rng(1)
    a = sphere(200, 2)
    for _ in range(20):
        x = random_x(rng)
        assert np.max(np.abs(tx.correct(x, tx.forward(x, a)) - a)) < 1e-12


def test_k_inverse_is_inverse():
    th = np.array([0.03, -0.02, 0.04])
    assert np.allclose(tx.k_matrix(th) @ tx.k_inverse(th), np.eye(3), atol=1e-15)


def test_lq_to_params_inverts_skr():
    # §7.1 item 1: lq_to_params(S K R(phi)) returns k, theta and R(phi) to 1e-12
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = random_x(rng)
        phi = rng.uniform(-0.05, 0.05, 3)
        C = tx.gain_matrix(x) @ tx.rotation(phi)
        lq = tx.lq_to_params(C)
        assert np.max(np.abs(lq.x_tail - x[3:])) < 1e-12
        assert np.max(np.abs(lq.rotation - tx.rotation(phi))) < 1e-12


def test_rotation_is_orthogonal_and_matches_small_angle():
    phi = np.array([0.01, -0.02, 0.03])
    R = tx.rotation(phi)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-15)
    assert np.isclose(np.linalg.det(R), 1.0)
    # first order: R ~ I + [phi]x, error is second order (|phi|^2/2 ~ 7e-4)
    assert np.max(np.abs(R - np.eye(3) - tx.skew(phi))) < 1e-3


@pytest.mark.parametrize("objective", ["norm", "norm2", "scalar", "scalar12"])
def test_analytic_jacobian_matches_central_difference(objective):
    # central differences with h=1e-6 have truncation error ~h^2*|f'''| and round-off ~eps/h ~1e-10
    rng = np.random.default_rng(4)
    a_t = sphere(40, 5)
    x = X_TRUE + 0.01 * rng.standard_normal(9)
    if objective == "scalar12":
        x = np.r_[x, PHI]
    a = tx.forward(X_TRUE, a_t)
    J = tx.jacobian(x, a, objective=objective, ref=a_t)
    Jn = np.empty_like(J)
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = 1e-6
        Jn[:, i] = (tx.residuals(x + e, a, objective=objective, ref=a_t)
                    - tx.residuals(x - e, a, objective=objective, ref=a_t)) / 2e-6
    assert np.max(np.abs(J - Jn)) < 1e-7


@pytest.mark.parametrize("objective", ["norm", "norm2", "scalar", "scalar12"])
def test_population_objective_equals_single(objective):
    rng = np.random.default_rng(6)
    a_t = sphere(30, 7)
    a = tx.forward(X_TRUE, a_t)
    X = np.array([X_TRUE + 0.01 * rng.standard_normal(9) for _ in range(5)])
    if objective == "scalar12":
        X = np.hstack([X, rng.uniform(-0.01, 0.01, (5, 3))])
    many = tx.objective_many(X, a, objective=objective, ref=a_t)
    single = [tx.objective_value(x, a, objective=objective, ref=a_t) for x in X]
    assert np.allclose(many, single, rtol=1e-12, atol=1e-18)


def test_objective_definitions_by_hand():
    # J_H = mean(|a|-g)^2 at x0 for two vectors of norm 10 and 9 (g = 9.8): (0.04 + 0.64)/2
    a = np.array([[10.0, 0, 0], [0, 9.0, 0]])
    assert np.isclose(tx.j_h(tx.X0, a), (0.2**2 + 0.8**2) / 2)
    assert np.isclose(tx.j_h2(tx.X0, a), ((100 - 96.04) ** 2 + (81 - 96.04) ** 2) / (4 * 96.04) / 2)
    ref = np.array([[9.8, 0, 0], [0, 9.8, 0]])
    assert np.isclose(tx.s9(tx.X0, a, ref), (0.2**2 + 0.8**2) / 2)


@pytest.mark.parametrize("objective", ["norm", "scalar", "scalar12"])
def test_lm_noise_free_recovery_sphere1000(objective):
    # §7.1 item 2: LM on sphere1000-clean recovers x (and phi = 0 for S12) to 1e-9
    a_t = sphere(1000, 0)
    a = tx.forward(X_TRUE, a_t)
    x0 = np.r_[tx.X0, 0, 0, 0] if objective == "scalar12" else tx.X0
    truth = np.r_[X_TRUE, 0, 0, 0] if objective == "scalar12" else X_TRUE
    res = levenberg_marquardt(lambda x: tx.residuals(x, a, objective=objective, ref=a_t), x0,
                              jac=lambda x: tx.jacobian(x, a, objective=objective, ref=a_t))
    assert np.max(np.abs(res.x - truth)) < 1e-9


def test_s12_removes_mount_bias_and_s9_shows_it():
    # §7.1 item 5 on a 62-position latitude-ring schedule (built here independently of the sim)
    pitches = np.deg2rad([0, 30, 60, 90, 120, 150, 180])
    counts = [1, 8, 14, 16, 14, 8, 1]
    dirs = [(np.sin(p) * np.cos(h), np.sin(p) * np.sin(h), np.cos(p))
            for p, c in zip(pitches, counts) for h in 2 * np.pi * np.arange(c) / c]
    r = 9.8 * np.array(dirs)
    a = tx.forward(X_TRUE, r, phi=PHI)
    res12 = levenberg_marquardt(lambda x: tx.residuals(x, a, objective="scalar12", ref=r),
                                np.r_[tx.X0, 0, 0, 0],
                                jac=lambda x: tx.jacobian(x, a, objective="scalar12", ref=r))
    assert np.max(np.abs(res12.x - np.r_[X_TRUE, PHI])) < 1e-9
    res9 = levenberg_marquardt(lambda x: tx.residuals(x, a, objective="scalar", ref=r), tx.X0,
                               jac=lambda x: tx.jacobian(x, a, objective="scalar", ref=r))
    J9 = 2 * res9.cost / 62
    assert J9 > 1e-4
    dth = res9.x[6:9] - X_TRUE[6:9]
    # first-order theory: theta errors = (-phi_z, -phi_y, -phi_x); second-order terms ~phi^2 < 5e-4
    assert np.max(np.abs(dth - (-PHI[[2, 1, 0]]))) < 5e-4


def test_scalar_objective_without_reference_raises():
    a = tx.forward(X_TRUE, sphere(20))
    with pytest.raises(InputError, match="reference"):
        tx.residuals(tx.X0, a, objective="scalar")


def test_bad_shapes_and_unknown_objective():
    with pytest.raises(InputError):
        tx.correct(tx.X0[:5], np.zeros((3, 3)))
    with pytest.raises(InputError, match="unknown objective"):
        tx.residuals(tx.X0, np.ones((3, 3)), objective="nope")
    with pytest.raises(InputError):
        tx.residuals(tx.X0, np.ones((3, 2)))
