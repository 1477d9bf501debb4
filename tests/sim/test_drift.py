"""Tests of the storage-drift virtual lab (spec 004 §7)."""

from __future__ import annotations

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.sim.drift import PRESETS, benchmark_process, simulate_storage_batch


def test_batch_layout_and_truth_decomposition():
    b = simulate_storage_batch(4, 60, "paper", rng=3)
    df = b.frame
    assert sorted(df["unit_id"].unique()) == ["QA001", "QA002", "QA003", "QA004"]
    for col in ("date", "day", "bias_mg", "sf_ma_per_g", "temp_c", "true_bias_mg",
                "true_sf_ma_per_g", "is_outlier_true"):
        assert col in df.columns
    # measured = truth + turn-on + measurement + outlier, exactly (same numbers, mg)
    resid = df["bias_mg"] - df["true_bias_mg"] - df["bias_turnon_mg"] - df["bias_meas_mg"] \
        - df["bias_outlier_mg"]
    assert np.max(np.abs(resid)) < 1e-12
    # truth = b0 + aging + wander + thermal
    for p in b.params:
        u = df[df["unit_id"] == p["unit_id"]]
        latent = p["b0_ug"] * 1e-3 + u["bias_aging_mg"] + u["bias_wander_mg"] + u["bias_thermal_mg"]
        assert np.max(np.abs(latent - u["true_bias_mg"])) < 1e-12
        k1 = p["k1_ma_per_g"]
        sf_ppm = (u["sf_ma_per_g"] / k1 - 1) * 1e6
        parts = u[["sf_wander_ppm", "sf_thermal_ppm", "sf_turnon_ppm", "sf_meas_ppm",
                   "sf_outlier_ppm"]].sum(axis=1)
        assert np.max(np.abs(sf_ppm - parts)) < 1e-6  # ppm; float rounding of k1 (1+1e-6 x)
        assert u["day"].iloc[0] == 0


def test_same_seed_same_record_and_unit_streams_independent():
    a = simulate_storage_batch(3, 50, "nav", rng=9).frame
    b = simulate_storage_batch(3, 50, "nav", rng=9).frame
    assert a.equals(b)
    # unit 1 of a 5-unit batch is the same as unit 1 of a 3-unit batch (spawned streams)
    c = simulate_storage_batch(5, 50, "nav", rng=9).frame
    assert a[a.unit_id == "QA001"].reset_index(drop=True).equals(
        c[c.unit_id == "QA001"].reset_index(drop=True))


def test_noise_levels_follow_preset():
    # 12 units x 400 days: the sample SD of eta is within 5 % of sigma_eta
    # (relative SE of an SD from ~4500 samples is ~1 %).
    b = simulate_storage_batch(12, 400, "paper", rng=1, missing_prob=0.0)
    pre = PRESETS["paper"]
    assert np.std(b.frame["bias_turnon_mg"] * 1e3) == pytest.approx(pre.sigma_eta_ug, rel=0.05)
    assert np.std(b.frame["sf_turnon_ppm"]) == pytest.approx(pre.sigma_etak_ppm, rel=0.05)
    # missing days ~ 5 %, outliers ~ 0.5 % per quantity (binomial, 4800 days)
    b2 = simulate_storage_batch(12, 400, "paper", rng=1)
    frac_missing = 1 - len(b2.frame) / (12 * 400)
    assert 0.035 < frac_missing < 0.065
    size = np.abs(b2.frame["bias_outlier_mg"][b2.frame["bias_outlier_mg"] != 0]) * 1e3
    np.testing.assert_allclose(size, 8 * pre.sigma_eta_ug)


def test_s1_skeleton_cycle_and_draw_order():
    # noise-free S1 settles on the period-6 cycle of spec §7.3
    y = np.zeros(400)
    for t in range(2, 400):
        a, b = y[t - 1], y[t - 2] - 0.5
        y[t] = -0.4 * (3 - a * a) / (1 + a * a) + 0.6 * (3 - b ** 3) / (1 + b ** 4)
    cyc = sorted(np.round(y[-6:], 3))
    np.testing.assert_allclose(cyc, sorted([0.563, 0.957, 1.365, 1.511, 0.818, 0.019]), atol=2e-3)
    # the draw is one normal(0, 0.1, n + 200) from default_rng(seed)
    s = benchmark_process("S2", 10, 5)
    eps = np.random.default_rng(5).normal(0, 0.1, 210)
    y2 = np.zeros(210)
    y2[:3] = 0.1
    for t in range(3, 210):
        y2[t] = 0.3 * y2[t - 1] + 0.9 * np.tanh(-2 * y2[t - 3]) + eps[t]
    np.testing.assert_array_equal(s, y2[200:])


def test_bad_arguments():
    with pytest.raises(InputError):
        simulate_storage_batch(2, 10, "lab")
    with pytest.raises(InputError):
        benchmark_process("S9", 10)


def test_mackey_glass_matches_the_anfis_benchmark_series():
    # the learner benchmark uses Jang's Mackey-Glass set-up; the
    # independent RK4 integration in tests/learn/test_anfis.py must give the same values
    from inertialab.sim.drift import mackey_glass
    from tests.learn.test_anfis import _mackey_glass

    x = mackey_glass(600)
    np.testing.assert_allclose(x, _mackey_glass(n_t=800)[118:718], rtol=0, atol=1e-12)
    assert 0.4 < x.min() < 0.5 and 1.2 < x.max() < 1.35  # the chaotic attractor's range
