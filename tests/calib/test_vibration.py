"""Tests of the vibration-bias model (calib.vibration; spec 001 §3.7-3.10, §4)."""

import numpy as np
import pandas as pd
import pytest

from inertialab.calib.model_types import load_model
from inertialab.calib.vibration import (
    VibrationModel,
    VibrationRun,
    bias_targets,
    residual_metrics,
)
from inertialab.errors import ExtrapolationWarning, InputError, NotFittedError
from inertialab.io.modelfile import save_model
from inertialab.sensors.gyro_vibration import bias_shift_dph
from inertialab.workflows.vibration import run_from_frame


def _frame(n1=400, n2=300, n3=300, fs=100.0, f=50.0, rate=None):
    n = n1 + n2 + n3
    on = np.zeros(n, dtype=np.int8)
    on[n1:n1 + n2] = 1
    fr = np.where(on == 1, f, 0.0)
    ph = np.where(np.arange(n) < n1, 1, np.where(on == 1, 2, 3)).astype(np.int8)
    x = np.zeros(n) if rate is None else rate
    return pd.DataFrame({"t_s": np.arange(n) / fs, "rate_dph": x, "vib_on": on,
                         "vib_freq_hz": fr, "vib_acc_g": 5.0 * on, "phase": ph})



# ------------------------------------------------------------------ targets and metrics

def test_bias_targets_exact_on_a_known_curve():
    # approximation = beta + g(f) in P2, beta in P1 -> each bin mean is g at the bin's
    # frequencies (1-Hz bins of a linear sweep) within the curvature of g over 1 Hz
    fs = 200.0
    n1, n2, n3 = 2000, 100_000, 2000
    n = n1 + n2 + n3
    f = np.zeros(n)
    f[n1:n1 + n2] = np.linspace(1.0, 500.0, n2)
    on = (f > 0).astype(np.int8)
    df = pd.DataFrame({"t_s": np.arange(n) / fs, "rate_dph": np.zeros(n), "vib_on": on,
                       "vib_freq_hz": f})
    run = run_from_frame(df)
    beta = 0.7
    approx = beta + np.where(on == 1, bias_shift_dph(f), 0.0)
    tg = bias_targets(run, approx, guard_s=0.0)
    assert tg.beta_dph == pytest.approx(beta)
    assert tg.f_hz[0] == 1.0 and tg.f_hz[-1] == 500.0 and np.all(np.diff(tg.f_hz) == 1)
    # bins at the ends are half-filled (centres at the range ends); skip them
    np.testing.assert_allclose(tg.e_dph[1:-1], bias_shift_dph(tg.f_hz[1:-1]), atol=2e-3)
    assert np.all(tg.count[1:-1] >= 8)
    # option of spec §3.7: every 2^L-th sample of the guarded P2 window
    ts = bias_targets(run, approx, guard_s=1.0, mode="samples", level=6)
    k = np.arange(n1 + 200, n1 + n2 - 200)[::64]
    np.testing.assert_array_equal(ts.f_hz, f[k])
    np.testing.assert_allclose(ts.e_dph, approx[k] - beta)
    with pytest.raises(InputError):
        bias_targets(run, approx, mode="nope")


def test_residual_metrics_on_constructed_signal():
    fs = 10.0
    n1, n2, n3 = 1000, 1000, 1000
    x = np.concatenate([np.full(n1, 1.0), np.full(n2, 3.0), np.full(n3, 1.0)])
    x[n1 + 500] = 10.0  # a spike inside the guarded P2 window
    x[n1] = -4.0  # a spike at the onset
    df = _frame(n1, n2, n3, fs=fs, rate=x)
    run = run_from_frame(df)
    m = residual_metrics(x, run, guard_s=10.0, edge_s=10.0)
    # P2 without 100-sample guards: 800 samples of 3 with one 10 -> mean 3 + 7/800
    assert m["delta_b"] == pytest.approx(2.0 + 7.0 / 800)
    assert m["edge_on"] == pytest.approx(5.0)  # |-4 - 1|
    assert m["edge_off"] == pytest.approx(2.0)
    assert m["mean"]["P3"] == pytest.approx(1.0)
    assert m["stability_10s"]["P1"] == pytest.approx(0.0)


# ------------------------------------------------------------------ model

def test_model_fits_clips_and_round_trips(tmp_path):
    f = np.arange(1.0, 501.0)
    e = bias_shift_dph(f)
    m = VibrationModel().fit(f, e)
    assert m.rbf_.mse_ <= 1e-4
    # the 4th-order polynomial misses the 470-Hz resonance (check 15's note: ~+3 deg/h at
    # 500 Hz even without noise; here the noise-free curve, error > 1 deg/h)
    assert abs(m.predict([500.0], model="poly")[0] - e[-1]) > 1.0
    assert abs(m.predict([500.0])[0] - e[-1]) < 0.05
    with pytest.warns(ExtrapolationWarning, match="clipped"):
        v = m.predict([600.0])
    assert v[0] == pytest.approx(m.predict([500.0])[0])
    p = tmp_path / "model.json"
    save_model(m, p, units={"f": "hz", "bias": "dph"})
    m2 = load_model(p, expected_type="vibration-compensation")
    xs = np.linspace(1, 500, 77)
    np.testing.assert_array_equal(m.predict(xs), m2.predict(xs))
    np.testing.assert_array_equal(m.predict(xs, model="poly"), m2.predict(xs, model="poly"))


def test_compensate_subtracts_model_only_while_vibrating():
    f = np.arange(1.0, 501.0)
    m = VibrationModel().fit(f, bias_shift_dph(f))
    n = 5000
    x = np.random.default_rng(0).normal(size=n)
    on = np.zeros(n, bool)
    on[2000:3000] = True
    fr = np.where(on, 300.0, 0.0)
    approx = np.zeros(n)
    out = m.compensate(x, on, fr, approx=approx)
    np.testing.assert_allclose(out[~on], 0.0)
    np.testing.assert_allclose(out[on], -m.predict([300.0])[0])
    raw = m.compensate(x, on, fr, apply_to="raw", model="poly")
    np.testing.assert_allclose(raw[~on], x[~on])
    with pytest.raises(RuntimeError):
        VibrationModel().predict([1.0])


# ------------------------------------------------------------------ model-file fixtures

def test_model_fixtures_v1_still_load():
    # tests/data/models/{vibration-compensation,rbf}-v1.json were written by save_model
    # (format version 1) from the noise-free b_v curve at 1, 6, ..., 496 Hz (see
    # tests/data/README.md); they must load and give the numbers they gave when written
    from pathlib import Path

    d = Path(__file__).resolve().parents[1] / "data" / "models"
    m = load_model(d / "vibration-compensation-v1.json", expected_type="vibration-compensation")
    r = load_model(d / "rbf-v1.json", expected_type="rbf")
    xs = [1.0, 251.0, 466.0, 471.0, 496.0]
    np.testing.assert_allclose(m.predict(xs), [1.0653066257322124, 1.0653066257322124,
                                               11.048343910112356, 11.15847209049774,
                                               9.577668603119587], rtol=1e-12)
    np.testing.assert_allclose(m.predict(xs, model="poly"),
                               [0.309375921068482, 1.3899868922768408, 9.62237831701889,
                                10.019117392023443, 12.190639731371528], rtol=1e-12)
    np.testing.assert_allclose(r.predict(xs), [1.2734459157895253, 1.2734459157895253,
                                               11.048343910112354, 11.158472090497739,
                                               9.577668603119587], rtol=1e-12)
    assert m.level == 6 and m.rbf_.n_neurons_ == 40 and r.n_neurons_ == 30


# ------------------------------------------------------------------ estimator contract

def test_not_fitted_format_version_and_params():
    m = VibrationModel(spread=2.0)
    with pytest.raises(NotFittedError):
        m.to_dict()
    assert m.get_params()["spread"] == 2.0 and m.set_params(goal=1e-3) is m
    assert m.goal == 1e-3
    with pytest.raises(ValueError, match="no parameter"):
        m.set_params(bogus=1)
    from inertialab.estimator import clone

    c = clone(m)
    assert c.get_params() == m.get_params() and not hasattr(c, "rbf_")
    f = np.linspace(1.0, 50.0, 20)
    assert m.fit(f, bias_shift_dph(f)) is m
    d = m.to_dict()
    assert d["format_version"] == VibrationModel.FORMAT_VERSION == 1
    # a payload without the key is version 1; a newer one is refused
    d1 = {k: v for k, v in d.items() if k != "format_version"}
    np.testing.assert_array_equal(VibrationModel.from_dict(d1).predict(f), m.predict(f))
    with pytest.raises(InputError, match="newer"):
        VibrationModel.from_dict({**d, "format_version": 2})
    for field in ("poly", "rbf", "f_range_hz"):  # a damaged payload is one InputError
        with pytest.raises(InputError, match=rf"^vibration model payload\.{field}: must be "):
            VibrationModel.from_dict({**d, field: None})


def test_vibration_run_phases():
    run = VibrationRun(rate_dph=np.zeros(10), vib_on=np.r_[[0] * 3, [1] * 4, [0] * 3] == 1,
                       freq_hz=np.r_[[0] * 3, [5.0] * 4, [0] * 3], fs_hz=1.0, k_on=3, k_off=6)
    assert run.phase_slices() == {"P1": slice(0, 3), "P2": slice(3, 7), "P3": slice(7, 10)}
    with pytest.raises(InputError, match="too short"):
        run.guarded(run.p2, 2.0)


def test_select_spread_prefers_smoothing_on_noisy_targets():
    # noisy samples (sd 0.3 deg/h) of the smooth b_v curve: at the seed's goal some spreads
    # are ill-conditioned (held-out RMSE many times the noise); the held-out choice lands
    # near the noise floor
    from inertialab.calib.vibration import phase_stats, select_spread

    f = np.arange(1.0, 201.0)
    e = bias_shift_dph(f) + np.random.default_rng(0).normal(0, 0.3, f.size)
    train = f % 2 == 1
    sel = select_spread(f, e, train, grid=(0.3, 1.2, 10.0, 20.0), goal=1e-4)
    assert sel["grid"] == [0.3, 1.2, 10.0, 20.0] and len(sel["heldout_rmse"]) == 4
    assert sel["chosen_rmse"] == min(sel["heldout_rmse"])
    assert sel["chosen"] == sel["grid"][int(np.argmin(sel["heldout_rmse"]))]
    assert max(sel["heldout_rmse"]) > 5 * sel["chosen_rmse"]
    assert sel["chosen_rmse"] < 1.5 * 0.3
    with pytest.raises(InputError, match="at least 5"):
        select_spread(f[:4], e[:4], train[:4])
    # per-phase bias and 10-s stability of a constructed signal
    run = VibrationRun(rate_dph=np.r_[np.zeros(200), np.full(200, 3.0), np.ones(200)],
                       vib_on=np.r_[[0] * 200, [1] * 200, [0] * 200] == 1,
                       freq_hz=np.r_[[0] * 200, [5.0] * 200, [0] * 200], fs_hz=10.0,
                       k_on=200, k_off=399)
    ps = phase_stats(run.rate_dph, run)
    assert ps["bias"] == {"P1": 0.0, "P2": 3.0, "P3": 1.0}
    assert ps["stability_10s"]["P2"] == 0.0
