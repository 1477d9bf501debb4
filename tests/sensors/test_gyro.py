"""Static FOG noise model (spec 001 §6.2): each component against its analytic AVAR."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.statistics.allan import oadev
from inertialab.sensors import gyro as G


def _only(**kw) -> G.GyroNoiseParams:
    base = dict(arw_deg_rth=0.0, bias_instability_dph=0.0, rrw_dph_rth=0.0,
                ramp_dph_per_h=0.0, q_arcsec=0.0, b0_dph=0.0)
    base.update(kw)
    return G.GyroNoiseParams(**base)


def test_unit_factors():
    # 1 deg/sqrt(h) = 60 (deg/h) sqrt(s); 1 deg/h/sqrt(h) = 1/60 (deg/h)/sqrt(s);
    # 1 deg/h^2 = 1/3600 (deg/h)/s (spec 001 §3.3 table).
    assert G._ARW_NATIVE == pytest.approx(60.0, rel=1e-15)
    assert G._RRW_NATIVE == pytest.approx(1 / 60.0, rel=1e-15)
    assert G._RAMP_NATIVE == pytest.approx(1 / 3600.0, rel=1e-15)


def test_white_rate_std_and_avar():
    # Per-sample std 60 N sqrt(fs); 2e5 samples -> sample std within 0.5 % (sd 0.16 %).
    fs, N = 100.0, 0.01
    y = G.simulate_gyro_noise(200_000, fs, _only(arw_deg_rth=N), 1)
    assert np.std(y) == pytest.approx(60 * N * math.sqrt(fs), rel=0.005)
    r = oadev(y, rate_hz=fs, taus=[0.01, 0.1, 1.0])
    # AVAR = (60N)^2/tau; edf > 3000 at these taus -> sd < 1.3 %, tolerance 5 %.
    np.testing.assert_allclose(r.dev, np.sqrt(G.model_avar(r.taus_s, _only(arw_deg_rth=N))),
                               rtol=0.05)


def test_rrw_and_ramp():
    fs = 10.0
    c = G.simulate_gyro_components(100_000, fs, _only(rrw_dph_rth=1.0, ramp_dph_per_h=0.5), 2)
    # RRW increments have std (K/60) sqrt(tau0) exactly by construction (sd 0.2 % at 1e5).
    assert np.std(np.diff(c.rrw)) == pytest.approx(math.sqrt(0.1) / 60, rel=0.01)
    # ramp: (R/3600) t exactly
    np.testing.assert_allclose(c.ramp, 0.5 / 3600 * np.arange(100_000) / fs, rtol=1e-12)
    assert c.rrw[0] == 0.0


def test_gauss_markov_stationary_std_and_avar():
    # One GM process (T_c = 1 s, std 1): sample std over 4e5 samples at 100 Hz (4000 T_c,
    # ~2000 independent values -> sd ~1.6 %), tolerance 6 %; AVAR vs spec formula 8 %.
    p = _only(bias_instability_dph=1 / 0.84, gm_tc_s=(1.0,))
    c = G.simulate_gyro_components(400_000, 100.0, p, 3)
    assert np.std(c.bias_instability) == pytest.approx(1.0, rel=0.06)
    r = oadev(c.bias_instability, rate_hz=100.0, taus=[0.1, 1.0, 2.0, 5.0])
    np.testing.assert_allclose(r.dev, np.sqrt(G.gm_avar(r.taus_s, 1.0, 1.0)), rtol=0.08)


def test_gm_sum_floor_is_bias_instability():
    # Spec 001 §6.2: the analytic ADEV of the five-GM sum is 0.93–0.99 x 0.6643 B for
    # 1 s <= tau <= 2000 s.
    tau = np.geomspace(1, 2000, 50)
    ratio = np.sqrt(G.model_avar(tau, _only(bias_instability_dph=1.0))) / 0.66428
    assert ratio.min() > 0.925 and ratio.max() < 0.995


def test_quantization_gives_q_over_sqrt12():
    # Spec 001 §7 check 4 (quantizer): with the mid preset's q = 0.1 arcsec and ARW
    # 0.01 deg/sqrt(h) at 200 Hz, AVAR at the shortest taus is 3Q^2/tau^2 + N^2/tau
    # with Q = q/sqrt(12), not q/sqrt(3): within 3 %.
    p = _only(arw_deg_rth=0.01, q_arcsec=0.1, b0_dph=0.5)
    y = G.simulate_gyro_noise(200_000, 200.0, p, 4)
    r = oadev(y, rate_hz=200.0, taus=[0.005, 0.01, 0.02])
    np.testing.assert_allclose(r.dev, np.sqrt(G.model_avar(r.taus_s, p)), rtol=0.03)
    # the output is a whole number of LSBs per sample
    steps = y * (1 / 200.0) / 0.1
    np.testing.assert_allclose(steps, np.round(steps), atol=1e-6)


def test_kasdin_flicker_flat():
    # Spec 001 §7 check 7: Kasdin 1/f ADEV flat within 15 % of 0.6643 B for m >= 8 over
    # two decades.
    p = _only(bias_instability_dph=1.0, bi_model="kasdin")
    y = G.simulate_gyro_noise(2**17, 1.0, p, 5)
    r = oadev(y, rate_hz=1.0, taus=[8, 16, 32, 64, 128, 256, 512, 800])
    np.testing.assert_allclose(r.dev / 0.66428, 1.0, atol=0.15)


def test_streams_independent_and_deterministic():
    a = G.simulate_gyro_components(5000, 10.0, "mid", 11)
    b = G.simulate_gyro_components(5000, 10.0, G.preset("mid").with_(q_arcsec=0.0), 11)
    np.testing.assert_array_equal(a.white, b.white)
    np.testing.assert_array_equal(a.bias_instability, b.bias_instability)
    np.testing.assert_array_equal(a.rrw, b.rrw)
    c = G.simulate_gyro_components(5000, 10.0, "mid", 11)
    np.testing.assert_array_equal(a.rate_dph, c.rate_dph)
    # without quantization the output is the sum of its parts
    np.testing.assert_allclose(b.rate_dph, 0.5 + b.white + b.bias_instability + b.rrw + b.ramp,
                               rtol=0, atol=1e-12)


def test_multipliers_scale_streams():
    n = 4000
    m = SimpleNamespace(white=np.full(n, 2.0), gm=np.full(n, 1.0), rrw=np.full(n, 3.0),
                        jitter=np.zeros(n))
    a = G.simulate_gyro_components(n, 10.0, "mid", 12)
    b = G.simulate_gyro_components(n, 10.0, "mid", 12, multipliers=m)
    np.testing.assert_allclose(b.white, 2 * a.white, rtol=1e-15)
    np.testing.assert_allclose(np.diff(b.rrw), 3 * np.diff(a.rrw), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(b.bias_instability, a.bias_instability, rtol=1e-15)


def test_bad_parameters():
    with pytest.raises(InputError, match="preset"):
        G.preset("ultra")
    with pytest.raises(InputError, match="samples"):
        G.simulate_gyro_noise(0, 10.0)
    with pytest.raises(InputError, match="rate"):
        G.simulate_gyro_noise(10, -1.0)
    assert G.GyroNoiseParams.from_dict(G.PRESETS["allan-test"].to_dict()) == G.PRESETS["allan-test"]
