"""Tests of inertialab.sensors.gyro_vibration (spec 001 §6.3)."""

import numpy as np
import pytest

from inertialab.sensors.gyro_vibration import (
    VibrationEffects,
    bias_shift_dph,
    drive_phase_rad,
    edge_transient_dph,
    first_order_lag,
    noise_multipliers,
    thermal_drift_dph,
    vibration_lines_dph,
)


def test_bias_shift_matches_spec_table():
    # spec §6.3 prints the values to 2 decimals: tolerance 0.005
    f = [1, 100, 300, 400, 470, 500]
    expect = [0.58, 0.75, 2.15, 4.91, 11.15, 9.18]
    np.testing.assert_allclose(bias_shift_dph(f), expect, atol=0.005)
    # (a / 5 g)^2 scaling
    assert bias_shift_dph(300.0, acc_g=10.0) == pytest.approx(4 * bias_shift_dph(300.0))


def test_first_order_lag_step_response():
    # unit step through tau = 0.5 s at 200 Hz: y(t_k) = 1 - a^(k+1), exactly
    fs, tau = 200.0, 0.5
    y = first_order_lag(np.ones(400), tau, fs)
    a = np.exp(-1 / (fs * tau))
    np.testing.assert_allclose(y, 1 - a ** np.arange(1, 401), rtol=1e-12)
    # starting from x0 = 1 a constant input stays constant
    np.testing.assert_allclose(first_order_lag(np.ones(10), tau, fs, x0=1.0), 1.0)
    np.testing.assert_array_equal(first_order_lag([1.0, 2.0], 0.0, fs), [1.0, 2.0])


def test_drive_phase_is_cumulative():
    fs = 200.0
    f = np.full(5, 50.0)
    np.testing.assert_allclose(drive_phase_rad(f, fs), 2 * np.pi * 50 / fs * np.arange(5))


@pytest.mark.parametrize("f0", [30.0, 180.0, 500.0])
def test_lines_are_interval_averages(f0):
    # the sinc form equals the mean of A_h sin(h Phi(t)) over [t_k, t_k + tau0), checked by
    # a 2000-point midpoint rule per interval (error ~ (h f tau0 / 2000)^2 ~ 1e-5 relative)
    fs = 200.0
    k = np.arange(50)
    f = np.full(k.size, f0)
    phi = drive_phase_rad(f, fs)
    got = vibration_lines_dph(phi, f, fs)
    e = VibrationEffects()
    sub = (np.arange(2000) + 0.5) / 2000 / fs
    ref = np.zeros(k.size)
    a1 = e.line_amp_dph * (e.line_offset + f0 / e.f_ref_hz)
    for h, rel in enumerate(e.line_rel, start=1):
        ph = h * (phi[:, None] + 2 * np.pi * f0 * sub[None, :])
        ref += a1 * rel * np.sin(ph).mean(axis=1)
    np.testing.assert_allclose(got, ref, atol=1e-4 * a1)


def test_lines_alias_and_null():
    # 400 Hz is an exact multiple of fs = 200 Hz: every harmonic averages to 0
    fs = 200.0
    f = np.full(100, 400.0)
    assert np.max(np.abs(vibration_lines_dph(drive_phase_rad(f, fs), f, fs))) < 1e-9
    # vib_on mask zeroes the lines
    f = np.full(10, 30.0)
    assert np.all(vibration_lines_dph(drive_phase_rad(f, fs), f, fs, vib_on=np.zeros(10)) == 0)


def test_thermal_drift_and_edges():
    t = np.array([0.0, 100.0, 3700.0, 3760.0, 10_000.0])
    d = thermal_drift_dph(t, 100.0, 3700.0)
    # +2 deg/h per hour for 3600 s -> 2 deg/h at t_off, then e^-1 after 60 s
    np.testing.assert_allclose(d[:4], [0.0, 0.0, 2.0, 2.0 * np.exp(-1)], rtol=1e-12)
    assert d[4] < 1e-40
    tt = np.array([9.0, 10.0, 10.125, 11.125])
    e = edge_transient_dph(tt, [10.0])
    np.testing.assert_allclose(e, [0.0, 0.0, 5 * np.exp(-0.125) * np.sin(np.pi / 2),
                                   5 * np.exp(-1.125) * np.sin(np.pi * 4.5)], atol=1e-12)


def test_noise_multipliers():
    on = np.array([0, 1, 1, 0])
    f = np.array([0.0, 500.0, 100.0, 0.0])
    m = noise_multipliers(on, f)
    np.testing.assert_allclose(m.white, [1, 1.5, 1.1, 1])
    np.testing.assert_allclose(m.gm, [1, 2, 2, 1])
    np.testing.assert_allclose(m.rrw, [1, 3, 3, 1])
    np.testing.assert_allclose(m.jitter, [0, 1, 1, 0])
