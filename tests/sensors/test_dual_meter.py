"""Dual-meter g^2 model (spec 003 §1.3–1.6, §2.3)."""

import numpy as np
import pytest

from inertialab import units
from inertialab.errors import InputError
from inertialab.sensors.dual_meter import (
    COEF_NAMES,
    average_directions,
    estimable_combinations,
    g2_design,
    g2_observation,
    harmonic_map,
    harmonic_matrix,
    ieee1293_output,
    meter_outputs,
    null_directions,
    pa_tumble_output,
    reduce_to_g,
    single_design,
)

COEF = {"KA0": 5e-4, "KB0": -3e-4, "kA1": 1.5e-4, "kB1": -8e-5, "eta": 1.2e-4,
        "KA2": 4e-5, "KB2": 1.5e-5, "KAx": 1e-5, "KBx": -8e-6}
THETA = 2 * np.pi * np.arange(20) / 20


@pytest.mark.parametrize("sa,sb", [(1, 1), (-1, 1), (1, -1), (-1, -1)])
def test_g2_design_equals_harmonic_form_and_null_directions(sa, sb):
    A = g2_design(THETA, s_a=sa, s_b=sb)
    # identities s^3 = (3s - sin3t)/4 etc. make this exact up to round-off
    np.testing.assert_allclose(A, harmonic_matrix(THETA) @ harmonic_map(s_a=sa, s_b=sb),
                               atol=1e-15)
    np.testing.assert_allclose(A @ null_directions(s_a=sa, s_b=sb), 0, atol=1e-14)
    M = harmonic_map(s_a=sa, s_b=sb)
    for c in estimable_combinations(s_a=sa, s_b=sb).values():
        # estimable iff orthogonal to both null directions
        assert np.allclose(c @ null_directions(s_a=sa, s_b=sb), 0)
        assert np.allclose(np.linalg.pinv(M) @ M @ c, c)


def test_linearised_g2_matches_exact_to_second_order():
    # spec §1.5: y ~ a^T K with remainder of order K^2 (~1e-7 for K0 ~ 5e-4)
    ua, ub = meter_outputs(THETA, COEF)
    y = g2_observation(ua, ub)
    K = np.array([COEF[n] for n in COEF_NAMES])
    rem = y - g2_design(THETA) @ K
    assert np.max(np.abs(rem)) < 5e-7
    assert np.max(np.abs(rem)) > 1e-9  # the remainder is real, not zero


def test_head_error_cancels_in_g2_but_not_in_single_output():
    d = 4.85e-6 * 5  # 5 arcsec
    ua0, ub0 = meter_outputs(THETA, COEF)
    ua1, ub1 = meter_outputs(THETA + d * np.sin(THETA + 0.3), COEF)
    assert np.max(np.abs(ua1 - ua0)) > 1e-5
    # first-order cancellation: change is (coefficient ~1e-4) x (angle 2.4e-5) ~ 1e-8
    assert np.max(np.abs(g2_observation(ua1, ub1) - g2_observation(ua0, ub0))) < 1e-7


def test_ieee1293_reduces_to_pa_tumble():
    ai, ao = np.sin(THETA), np.cos(THETA)
    full = ieee1293_output(ai, 0.0, ao, K0=1e-4, k1=2e-4, K2=3e-5, K_io=7e-6, K_ip=9e-6,
                           K_po=5e-6, K_pp=4e-6, delta_o=1e-5)
    # with a_p = 0 the a_p terms vanish (spec §1.3)
    np.testing.assert_allclose(full, pa_tumble_output(ai, ao, K0=1e-4, k1=2e-4, K2=3e-5,
                                                      Kx=7e-6), rtol=0, atol=1e-16)


def test_single_design_recovers_coefficients_without_head_error():
    delta = 9.7e-5
    ua, _ = meter_outputs(THETA + delta, COEF)
    X, off = single_design(THETA, "A")
    b = np.linalg.lstsq(X, ua - off, rcond=None)[0]
    # linearisation in delta: errors of order delta^2 ~ 1e-8 and K*delta ~ 5e-8
    np.testing.assert_allclose(b, [COEF["KA0"], COEF["kA1"], delta, COEF["KA2"], COEF["KAx"]],
                               atol=1e-7)
    with pytest.raises(InputError):
        single_design(THETA, "C")


def test_reduce_to_g_and_direction_average():
    g_loc = 9.80625
    s_nom = 1.3e-3 * 5000 * g_loc / units.G_STANDARD  # V per local g
    u = reduce_to_g(np.array([s_nom, -2 * s_nom]), k1_nom_ma_per_g=1.3, r_load_ohm=5000,
                    g_local_mps2=g_loc)
    np.testing.assert_allclose(u, [1.0, -2.0], rtol=1e-14)
    # resistor TC: R(30 C) = R0 (1 + 1e-6 * 5)
    u2 = reduce_to_g(s_nom * (1 + 5e-6), k1_nom_ma_per_g=1.3, r_load_ohm=5000,
                     g_local_mps2=g_loc, t_r_c=30.0, r_alpha_per_c=1e-6, r_t0_c=25.0)
    assert u2 == pytest.approx(1.0, rel=1e-14)
    with pytest.raises(InputError):
        reduce_to_g(1.0, k1_nom_ma_per_g=1.3, r_load_ohm=5000, g_local_mps2=g_loc,
                    r_alpha_per_c=1e-6)
    m, d = average_directions([1.0, 2.0], [3.0, 2.0])
    np.testing.assert_allclose(m, [2.0, 2.0])
    np.testing.assert_allclose(d, [-2.0, 0.0])
