"""The thermal-imu model: lag and order recovered from a noise-free quantised ramp, the
span refusal naming the instance, save/load round trip, the v1 fixture, and the ANFIS
method beside the polynomial."""

from pathlib import Path

import numpy as np
import pytest
from scipy.signal import lfilter

from inertialab.calib.model_types import load_model, save_model
from inertialab.calib.thermal_imu import FitSettings, fit_imu_model
from inertialab.errors import InputError
from inertialab.io.formats.thermal_logs import ImuThermalLog, SensorStream
from inertialab.sim.thermal_imu import chamber

MODELS = Path(__file__).resolve().parents[1] / "data" / "models"


def _lag(x, dt, tau):
    a = np.exp(-dt / tau)
    return lfilter([1 - a], [1, -a], x, zi=[a * x[0]])[0]


def _noise_free_log(tau=30.0, ramp="calibration", rate=1.0):
    """A gyro whose offsets are cubic/quintic in the element temperature, read through a
    first-order sensor lag ``tau`` and 1 °C quantisation; no noise."""
    t, ch = chamber(ramp, rate)
    el = _lag(ch, 1 / rate, 60.0)
    reported = np.round(_lag(el, 1 / rate, tau))
    u = (el - 20.5) / 35.5
    off = np.column_stack([1e-3 * (u + 0.3 * u ** 2 - 0.4 * u ** 3),
                           -2e-3 * u + 5e-4 * u ** 3, 1e-3 * (u - 0.5 * u ** 4 + 0.6 * u ** 5)])
    return ImuThermalLog("<test>", "table", [SensorStream("gyro", 0, 7, t, reported, off)]), el, off


def test_lag_order_and_hysteresis_recovered_without_noise():
    log, el, off = _noise_free_log(tau=30.0)
    fit = fit_imu_model(log)
    s = fit.model.sensors[0]
    # without noise every order from the true one up reaches the de-quantisation floor
    # (0.1 % of the drift); the quintic axis needs at least 5
    assert all(a["order"] >= 3 for a in s["axes"]) and s["axes"][2]["order"] >= 5
    for a, ax in enumerate(s["axes"]):
        assert abs(ax["tau_s"] - 30.0) <= 5.0, ax["tau_s"]
        drift = np.std(off[:, a])
        assert ax["rms_in"] < 0.01 * drift and ax["rms_cv"] < 0.02 * drift
        # the lag term closes the heating/cooling loop
        assert abs(ax["hysteresis"]) < 0.1 * abs(ax["hysteresis_tau0"])
    st = log.streams[0]
    corr, outside = fit.model.correct(s, st.t_s, st.temp_c, st.values)
    assert outside == 0
    assert np.max(np.abs(corr)) < 0.03 * np.max(np.abs(off))


def test_a_span_under_10_c_is_refused_naming_the_instance():
    log, _, _ = _noise_free_log()
    st = log.streams[0]
    keep = st.temp_c < st.temp_c.min() + 8
    short = ImuThermalLog("<t>", "table", [SensorStream("gyro", 2, 99, st.t_s[keep],
                                                        st.temp_c[keep], st.values[keep])])
    with pytest.raises(InputError, match=r"gyro 2 \(device 99\): the temperature spans only"):
        fit_imu_model(short)


def test_save_load_round_trip_corrects_the_same(tmp_path):
    log, _, _ = _noise_free_log(rate=0.2)
    m = fit_imu_model(log).model
    back = load_model(save_model(m, tmp_path / "m.json"), expected_type="thermal-imu")
    st = log.streams[0]
    a = m.correct(m.sensors[0], st.t_s, st.temp_c, st.values)[0]
    b = back.correct(back.sensors[0], st.t_s, st.temp_c, st.values)[0]
    np.testing.assert_array_equal(a, b)


def test_model_fixture_v1_still_loads():
    m = load_model(MODELS / "thermal-imu-v1.json", expected_type="thermal-imu")
    t, temp = np.array([0.0, 100.0, 200.0, 300.0]), np.array([-20.0, 0.0, 30.0, 60.0])
    got, n = m.correct(m.sensor("gyro", 0), t, temp, np.zeros((4, 3)))
    want = [[-0.0015678915, -0.0030931913, 0.0009808646],
            [-0.0006453117, -0.0009571476, 0.0004781164],
            [0.0003413023, 0.0008067755, -0.0003852649],
            [0.0001589179, 0.0016306401, -0.0008758288]]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    assert n == 2  # -20 and 60 °C lie outside the fixture's -15..56 °C


def test_anfis_method_learns_the_lag_from_t_and_slope():
    pytest.importorskip("scipy")
    log, _, off = _noise_free_log(rate=0.1)
    st = log.streams[0]
    one = ImuThermalLog("<t>", "table", [SensorStream("gyro", 0, 7, st.t_s, st.temp_c,
                                                      st.values[:, :1].repeat(3, axis=1))])
    fit = fit_imu_model(one, FitSettings(method="scm-anfis", epochs=10, bin_s=20.0))
    s = fit.model.sensors[0]
    assert s["axes"][0]["anfis"] is not None and fit.model.method == "scm-anfis"
    corr, _ = fit.model.correct(s, st.t_s, st.temp_c, one.streams[0].values)
    assert np.std(corr[:, 0]) < 0.1 * np.std(off[:, 0])


def test_scale_factor_fitted_where_the_log_has_several_orientations():
    from inertialab.io.formats.thermal_logs import streams_from_frame
    from inertialab.sim.thermal_imu import simulate

    log = simulate(6, rate_hz=1.0, n_instances=1, faces=6)
    m = fit_imu_model(streams_from_frame(log.frame)).model
    s = m.sensor("accel", 0)
    f = log.frame
    el, zero = f["true_temp_c"].to_numpy(), np.zeros(len(f))
    for a, ax in enumerate(s["axes"]):
        name = ax["axis"]
        assert ax["scale"] is not None
        g = f[f"true_g_{name}"].to_numpy()
        truth = f[f"true_off_{name}"].to_numpy() + f[f"true_scale_{name}"].to_numpy() * g
        # offset and scale learnt, at the element temperature (what T + tau dT/dt stands
        # for), against the truth; measured 1.5, 2.0 and 6.4 % of the drift (1 Hz log)
        est = m.axis_offset(s, a, el, zero) + m.axis_scale(s, a, el, zero) * g
        err = est - truth
        assert np.std(err - err.mean()) < 0.1 * np.std(truth), (name, np.std(err))
    # a level log: no scale factor
    level = fit_imu_model(streams_from_frame(simulate(6, rate_hz=0.2, n_instances=1).frame))
    assert all(ax["scale"] is None for ax in level.model.sensor("accel", 0)["axes"])


def test_a_heating_only_log_gets_no_lag_term_and_no_hysteresis():
    log, _, _ = _noise_free_log(ramp="heat", rate=0.2)
    s = fit_imu_model(log).model.sensors[0]
    assert all(ax["tau_s"] == 0.0 and ax["hysteresis"] is None for ax in s["axes"])


def test_settings_are_read_by_name_from_any_object():
    """fit_imu_model reads its settings by name from any object (a command's Config): the
    same model as the FitSettings with those values, what the object lacks at the
    defaults of FitSettings, a bad method refused naming it."""
    import json
    from types import SimpleNamespace

    log, _, _ = _noise_free_log(rate=0.1)
    typed = fit_imu_model(log, FitSettings(max_order=3, seed=5))
    plain = fit_imu_model(log, SimpleNamespace(max_order=3, seed=5, split="random"))
    assert plain.settings == FitSettings(max_order=3, seed=5)
    assert json.dumps(plain.model.to_dict()) == json.dumps(typed.model.to_dict())
    assert max(ax["order"] for ax in plain.model.sensors[0]["axes"]) <= 3
    assert fit_imu_model(log).settings == FitSettings()
    with pytest.raises(InputError, match="argument 'method'"):
        fit_imu_model(log, SimpleNamespace(method="anfis"))
