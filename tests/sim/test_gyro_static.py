"""Rig gyro-static: record shape, sidecar, truth, reproducibility."""

from __future__ import annotations

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.statistics.allan import oadev
from inertialab.sensors.gyro import model_avar, preset
from inertialab.sim.gyro_static import simulate


def test_record_and_meta():
    r = simulate("allan-test", hours=0.1, rate_hz=20.0, seed=3)
    assert list(r.record.columns) == ["t_s", "rate_dph"]
    assert len(r.record) == 7200
    np.testing.assert_allclose(np.diff(r.record["t_s"]), 0.05, rtol=1e-12)
    m = r.meta
    assert m["fs_hz"] == 20.0 and m["seed"] == 3 and m["source"] == "virtual_lab"
    assert m["truth_terms"]["N"] == {"value": 0.01, "unit": "deg/sqrt(h)"}
    assert m["truth_terms"]["Q"]["value"] == pytest.approx(0.5)
    # east axis: zero Earth rate; the output mean is b0 plus noise
    assert m["earth_rate_dph"] == 0.0
    # truth components add up to the output (no quantizer in allan-test)
    tr = r.truth
    total = (tr["true_static_dph"] + tr["true_white_dph"] + tr["true_gm_dph"]
             + tr["true_rrw_dph"] + tr["true_ramp_dph"] + tr["true_quantization_dph"])
    np.testing.assert_allclose(r.record["rate_dph"], total, rtol=0, atol=1e-9)


def test_same_seed_same_numbers():
    a = simulate("mid", hours=0.05, seed=9).record["rate_dph"].to_numpy()
    b = simulate("mid", hours=0.05, seed=9).record["rate_dph"].to_numpy()
    c = simulate("mid", hours=0.05, seed=10).record["rate_dph"].to_numpy()
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_north_axis_earth_rate():
    # psi = 0 at 32.06 deg latitude: 15.041 cos(32.06 deg) = 12.75 deg/h (spec 001 §6.1).
    r = simulate("mid", hours=0.01, heading_deg=0.0, seed=1)
    assert r.meta["earth_rate_dph"] == pytest.approx(12.75, abs=0.01)


def test_allan_curve_matches_preset_model():
    # OADEV of a 2-h allan-test record against the analytic AVAR of the preset at
    # taus with edf > 100 (sd < 7 %): 15 %.
    r = simulate("allan-test", hours=2.0, rate_hz=10.0, seed=4)
    d = oadev(r.record["rate_dph"].to_numpy(), rate_hz=10.0, taus=[0.1, 1, 10, 100])
    np.testing.assert_allclose(d.dev, np.sqrt(model_avar(d.taus_s, preset("allan-test"))),
                               rtol=0.15)


def test_bad_arguments():
    with pytest.raises(InputError, match="preset"):
        simulate("ultra")
    with pytest.raises(InputError, match="hours"):
        simulate("mid", hours=-1)
    with pytest.raises(InputError, match="too short"):
        simulate("mid", hours=1e-6)
    with pytest.raises(InputError, match="unknown simulate option"):
        simulate("mid", hours=0.01, colour="red")
