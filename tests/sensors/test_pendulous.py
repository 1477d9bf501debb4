"""Tests of inertialab.sensors.pendulous (spec 000 §1-§3.1)."""

from __future__ import annotations

import numpy as np
import pytest

from inertialab.errors import UnderdeterminedError
from inertialab.sensors.pendulous import (
    SingleAxisCoefficients,
    bias_0_180,
    estimate_input,
    fit_single_axis,
    integrated_output,
    reference_target,
    scale_factor_eq3,
    tumble_positions,
)

COEF = SingleAxisCoefficients(k0=1.3, k1=1012.0, k2=0.008, kip=-0.006, kp=0.31)


def test_positions_follow_the_sin_cos_convention():
    p = tumble_positions(24)
    assert p.angle_deg[1] == 15.0 and p.angle_deg[-1] == 345.0
    assert p.a_in_g[0] == 0.0 and p.a_pend_g[0] == 1.0
    assert p.a_in_g[12] == 0.0 and p.a_pend_g[12] == -1.0
    assert p.a_in_g[6] == 1.0 and p.a_pend_g[6] == 0.0
    np.testing.assert_allclose(p.a_in_g**2 + p.a_pend_g**2, 1.0, rtol=1e-15)


def test_fit_recovers_noise_free_coefficients():
    p = tumble_positions(24)
    U = COEF.output(p.a_in_g, p.a_pend_g)
    fit = fit_single_axis(p.a_in_g, p.a_pend_g, U)
    got = fit.coefficients
    for k in ("k0", "k1", "k2", "kip", "kp"):
        # 24 well-conditioned equations: only rounding error (~1e-13 of K1) remains
        assert getattr(got, k) == pytest.approx(getattr(COEF, k), abs=1e-10)
    assert fit.residual_rms < 1e-10


def test_fit_standard_errors_match_monte_carlo_spread():
    p = tumble_positions(24)
    rng = np.random.default_rng(0)
    k0s, ses = [], []
    for _ in range(400):
        U = COEF.output(p.a_in_g, p.a_pend_g) + 0.002 * rng.standard_normal(24)
        f = fit_single_axis(p.a_in_g, p.a_pend_g, U)
        k0s.append(f.coefficients.k0)
        ses.append(f.stderr["k0"])
    # 400 replicas: the SD of an SD estimate is ~ 1/sqrt(800) = 3.5 %; allow 15 %
    assert np.std(k0s) == pytest.approx(np.mean(ses), rel=0.15)


def test_two_positions_cannot_separate_five_terms():
    with pytest.raises(UnderdeterminedError):
        fit_single_axis([0.0, 1.0], [1.0, 0.0], [1.0, 2.0])


def test_bias_from_0_and_180_cancels_misalignment():
    p = tumble_positions(24)
    U = COEF.output(p.a_in_g, p.a_pend_g)
    assert bias_0_180(U[0], U[12]) == pytest.approx(COEF.k0, abs=1e-12)


def test_eq3_scale_factor_closed_form():
    p = tumble_positions(24)
    U = COEF.output(p.a_in_g, p.a_pend_g)
    k = scale_factor_eq3(U, COEF.k0, p.a_in_g)
    a, ap = p.a_in_g, p.a_pend_g
    m = a != 0
    expected = COEF.k1 + COEF.k2 * a[m] + COEF.kip * ap[m] + COEF.kp * ap[m] / a[m]
    np.testing.assert_allclose(k[m], expected, rtol=1e-12)
    assert np.all(np.isnan(k[~m]))


def test_integrated_output_equals_linear_part_and_input_estimate_inverts():
    p = tumble_positions(24)
    U = COEF.output(p.a_in_g, p.a_pend_g)
    Ua = integrated_output(U, p.a_in_g, p.a_pend_g, COEF)
    np.testing.assert_allclose(Ua, reference_target(p.a_in_g, COEF), atol=1e-12)
    a_hat = estimate_input(U, p.a_pend_g, COEF, passes=1)
    # one fixed-point pass leaves an error of order (K2/K1)^2 ~ 1e-10 g
    np.testing.assert_allclose(a_hat, p.a_in_g, atol=1e-9)


def test_coefficients_round_trip():
    assert SingleAxisCoefficients.from_dict(COEF.to_dict()) == COEF
    assert COEF.bias_g == pytest.approx(1.3 / 1012.0)


def test_bias_and_eq3_scale_factor_drift_per_input_level():
    """Figs. 3/4 of the seed: noise-free tumbles at five temperatures
    with K0(T), K1(T) known; averaging eq. 3 over the two positions of a level cancels
    the Kip and Kp terms (a_p = ±cos), leaving K1(T) + K2 a_i exactly."""
    from inertialab.sensors.pendulous import bias_scale_factor_drift

    p = tumble_positions(24)
    temps = np.array([-40.0, 0.0, 25.0, 55.0, 70.0])
    sp, tt, ai, U = [], [], [], []
    for t in temps:
        dt = t - 55.0
        c = SingleAxisCoefficients(k0=COEF.k0 + 2e-3 * dt, k1=COEF.k1 * (1 + 3e-5 * dt),
                                   k2=COEF.k2, kip=COEF.kip, kp=COEF.kp)
        sp.append(np.full(24, t))
        tt.append(np.full(24, t + 0.1))
        ai.append(p.a_in_g)
        U.append(c.output(p.a_in_g, p.a_pend_g))
    r = bias_scale_factor_drift(np.concatenate(sp), np.concatenate(tt), np.concatenate(ai),
                                np.concatenate(U), k1_ref=COEF.k1)
    np.testing.assert_array_equal(r.set_point_c, temps)
    np.testing.assert_allclose(r.temp_c, temps + 0.1)
    # bias drift 2 µV/°C... in mg: 2e-3 mV/°C x dT / K1c x 1e3
    np.testing.assert_allclose(r.bias_drift_mg, 2e-3 * (temps - 55) / COEF.k1 * 1e3, atol=1e-12)
    assert r.levels_g.size == 12 and 0.0 not in r.levels_g
    k1t = COEF.k1 * (1 + 3e-5 * (temps - 55))
    expect = k1t[:, None] + COEF.k2 * r.levels_g[None, :]
    np.testing.assert_allclose(r.scale_factor_mv_per_g, expect, rtol=1e-12)
    np.testing.assert_allclose(r.scale_factor_drift_mv_per_g,
                               (k1t - COEF.k1)[:, None] * np.ones((1, 12)), atol=1e-9)
    assert r.summary()["max_scale_factor_drift_ppm"] == pytest.approx(3e-5 * 95 * 1e6, rel=1e-9)
