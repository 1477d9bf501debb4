"""Tests of the fog-vibration rig (spec 001 §6)."""

import hashlib
import math

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.io import read_record, write_record
from inertialab.sensors.gyro_vibration import bias_shift_dph
from inertialab.sim.fog_vibration import GENERATOR_VERSION, simulate

# spec §6.4: golden SHA-256 of rate_dph for (E2, seed 0); update only with a version bump
GOLDEN_E2_SEED0 = "d83a7f03896cbc45d4903f22c7cf0a03e015af58f25243ef33514fb770465ac0"
SHORT = dict(p1_s=120.0, p3_s=120.0, p2_fixed_s=120.0)


def test_default_sizes_and_golden_hash():
    # spec §6.1/§6.3: E2 = 3 x 1800 s at 200 Hz = 1.08 M samples; E1 P2 = 60 log2(500) + 5 s
    r = simulate("fixed", 0)
    assert GENERATOR_VERSION == "fog-vibration/1"
    assert len(r.record) == 1_080_000
    h = hashlib.sha256(r.record["rate_dph"].to_numpy().tobytes()).hexdigest()
    assert h == GOLDEN_E2_SEED0
    s = simulate("sweep", 0)
    p2 = 60 * math.log2(500) + 5
    assert s.meta["p2_s"] == pytest.approx(p2)
    assert int((s.record["vib_on"] == 1).sum()) == int(round(p2 * 200))
    f = s.record["vib_freq_hz"].to_numpy()[s.record["vib_on"].to_numpy() == 1]
    # 1 oct/min from 1 Hz, clipped at 500 Hz for the 5-s dwell (1000 samples less the one
    # lost to rounding the P2 length to whole samples)
    assert f[0] == 1.0 and f[12_000] == pytest.approx(2 ** (12_000 / 200 / 60))
    assert 999 <= np.sum(f == 500.0) <= 1001


def test_same_seed_same_numbers_and_seed_matters():
    a = simulate("fixed", 3, **SHORT).record["rate_dph"].to_numpy()
    b = simulate("fixed", 3, **SHORT).record["rate_dph"].to_numpy()
    c = simulate("fixed", 4, **SHORT).record["rate_dph"].to_numpy()
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_record_schema_phases_and_columns():
    r = simulate("fixed", 1, **SHORT)
    d = r.record
    assert list(d.columns) == ["t_s", "rate_dph", "vib_on", "vib_freq_hz", "vib_acc_g", "phase"]
    on = d["vib_on"].to_numpy() == 1
    assert np.all((d["vib_freq_hz"].to_numpy() > 0) == on)
    ph = d["phase"].to_numpy()
    assert np.all(np.diff(ph) >= 0) and set(np.unique(ph)) == {1, 2, 3}
    assert np.all((ph == 2) == on)
    np.testing.assert_allclose(np.diff(d["t_s"].to_numpy()), 1 / 200.0, rtol=1e-9)
    for key in ("fs_hz", "experiment", "acc_g", "latitude_deg", "heading_deg", "source",
                "seed", "generator_version", "t_on_s", "t_off_s"):
        assert key in r.meta
    assert r.meta["source"] == "virtual_lab"


def test_output_is_quantized_integral_of_truth():
    # integrate-then-quantize: the sum of (rate - true rate) over any span telescopes to the
    # quantization (+ jitter) error at its two ends, so its mean is bounded by
    # (q + 2 * 5 sigma_jitter) / (tau0 * n) (sigma_jitter = q/sqrt(12))
    r = simulate("fixed", 2, **SHORT)
    x = r.record["rate_dph"].to_numpy()
    true = r.truth["true_rate_dph"].to_numpy()
    q, tau0 = 0.1, 1 / 200.0
    for sl in (slice(0, 24_000), slice(24_000, 48_000), slice(0, x.size)):
        n = sl.stop - sl.start
        assert abs(np.mean(x[sl] - true[sl])) <= (q + 10 * q / math.sqrt(12)) / (tau0 * n)
    # output angle is a multiple of q (plus nothing): rate * tau0 sums to multiples of q
    ang = np.cumsum(x) * tau0
    np.testing.assert_allclose(ang / q, np.round(ang / q), atol=1e-6)


def test_bias_shift_truth_and_noise_increase():
    r = simulate("fixed", 5, **SHORT)
    t = r.truth
    on = r.record["vib_on"].to_numpy() == 1
    bv = t["true_bias_vib_dph"].to_numpy()
    # after 10 lag constants the lagged shift equals b_v(500 Hz) = 9.18 deg/h
    assert bv[on][-1] == pytest.approx(float(bias_shift_dph(500.0)), rel=1e-9)
    assert bv[0] == 0.0
    # ARW x (1 + 0.5 f/500) = 1.5 at 500 Hz: white-stream std ratio P2/P1 within 3 %
    # (24 000 samples each -> std of a std estimate ~0.5 %)
    w = t["true_white_dph"].to_numpy()
    ratio = w[on].std() / w[: on.argmax()].std()
    assert ratio == pytest.approx(1.5, rel=0.03)
    # white std = 60 N sqrt(fs) = 0.6 * sqrt(200) deg/h in P1 (within 3 %)
    assert w[: on.argmax()].std() == pytest.approx(0.6 * math.sqrt(200), rel=0.03)


def test_no_vibration_control_run():
    r = simulate("fixed", 6, vibration=False, **SHORT)
    t = r.truth
    for c in ("true_bias_vib_dph", "true_thermal_dph", "true_edge_dph", "true_lines_dph"):
        assert np.all(t[c].to_numpy() == 0)
    # drive columns are kept
    assert (r.record["vib_on"] == 1).sum() == 24_000


def test_lines_alias_to_100_hz_at_500_hz_drive():
    # 500 Hz at fs = 200 Hz lands on 100 Hz (Nyquist): the line is +-A sin(...) alternating
    r = simulate("fixed", 7, **SHORT)
    lines = r.truth["true_lines_dph"].to_numpy()[r.record["vib_on"].to_numpy() == 1]
    spec = np.abs(np.fft.rfft(lines))
    assert np.argmax(spec) == spec.size - 1  # the Nyquist bin


def test_round_trip_through_record_files(tmp_path):
    r = simulate("sweep", 8, p1_s=60.0, p3_s=60.0, sweep_oct_per_min=30.0)
    p = tmp_path / "sweep.csv"
    write_record(r.record, p, r.meta)
    rec = read_record(p, "gyro_log")
    np.testing.assert_array_equal(rec.data["rate_dph"].to_numpy(), r.record["rate_dph"].to_numpy())
    assert rec.meta["experiment"] == "sweep" and rec.meta["seed"] == 8


def test_bad_arguments():
    with pytest.raises(InputError):
        simulate("random", 0)
    with pytest.raises(InputError):
        simulate("fixed", 0, preset="nope")
    with pytest.raises(InputError):
        simulate("fixed", 0, nonsense=1)
    with pytest.raises(InputError):
        simulate("sweep", 0, f_start_hz=600.0)
