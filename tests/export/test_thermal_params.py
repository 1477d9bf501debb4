"""PX4 and ArduPilot thermal parameter files read back and evaluated with the firmware's
formulas, written out here from the firmware sources (PX4
``TemperatureCompensation::calc_thermal_offsets_3D``: clip to TMIN/TMAX, cubic in
T - TREF, subtracted; ArduPilot ``AP_InertialSensor_TCal::correct_sensor``: constrain T
and the calibration temperature to TMIN/TMAX, cubic without constant about 35 °C times
1e-6, ``v - P(T - 35) + P(T_cal - 35)``)."""

import numpy as np
import pytest

from inertialab.calib.thermal_imu import fit_imu_model
from inertialab.errors import InputError
from inertialab.export import get, targets
from inertialab.export import thermal_params as tp
from inertialab.io.formats.thermal_logs import streams_from_frame
from inertialab.sim.thermal_imu import simulate


@pytest.fixture(scope="module")
def model():
    return fit_imu_model(streams_from_frame(simulate(5, rate_hz=1.0, n_instances=1).frame)).model


def _px4_firmware(p, kind, slot, temp):
    """PX4's evaluation, transcribed: per sample, clip then X0 + X1 d + X2 d^2 + X3 d^3."""
    pre = f"TC_{'A' if kind == 'accel' else 'G'}{slot}_"
    out = []
    for t in temp:
        if t > p[pre + "TMAX"]:
            d = p[pre + "TMAX"] - p[pre + "TREF"]
        elif t < p[pre + "TMIN"]:
            d = p[pre + "TMIN"] - p[pre + "TREF"]
        else:
            d = t - p[pre + "TREF"]
        out.append([sum(p[f"{pre}X{k}_{a}"] * d ** k for k in range(4)) for a in range(3)])
    return np.array(out)


def _ap_firmware(p, kind, imu, temp, v, cal):
    """ArduPilot's correct_sensor, transcribed."""
    pre = f"INS_TCAL{imu}_"
    key = "ACC" if kind == "accel" else "GYR"

    def poly(e, a):
        c = [p[f"{pre}{key}{k}_{'XYZ'[a]}"] for k in (1, 2, 3)]
        return (c[0] + (c[1] + c[2] * e) * e) * e * 1e-6

    lo, hi = p[pre + "TMIN"], p[pre + "TMAX"]
    tc = min(max(cal, lo), hi)
    out = np.array(v, float)
    for i, t in enumerate(temp):
        t = min(max(t, lo), hi)
        for a in range(3):
            out[i, a] += -poly(t - 35.0, a) + poly(tc - 35.0, a)
    return out


def test_registry_offers_both_targets():
    assert targets("thermal-imu") == ("px4", "ardupilot")


def test_px4_file_reads_back_and_matches_the_firmware_and_the_model(model, tmp_path):
    path = tmp_path / "tc.params"
    get("thermal-imu", "px4").write(model, path)
    text = path.read_text()
    assert "held-out RMS" in text and "order-3" in text  # the residual it leaves
    p = tp.read_px4(text)
    assert p["TC_A_ENABLE"] == 1 and p["TC_G_ENABLE"] == 1
    for s in model.sensors:
        pre = f"TC_{'A' if s['kind'] == 'accel' else 'G'}0_"
        assert p[pre + "ID"] == s["device_id"] and isinstance(p[pre + "ID"], int)
        assert sum(k.startswith(pre + "X") for k in p) == 12
        temp = np.linspace(s["t_min"] - 20, s["t_max"] + 20, 57)
        fw = _px4_firmware(p, s["kind"], 0, temp)
        ours = tp.px4_offset(p, s["kind"], 0, temp)
        np.testing.assert_allclose(ours, fw, rtol=1e-5, atol=1e-7)  # float32 firmware
        # clamped outside TMIN/TMAX
        np.testing.assert_allclose(ours[temp > s["t_max"]], ours[temp > s["t_max"]][:1]
                                   .repeat((temp > s["t_max"]).sum(), 0), atol=0)
        # the model's order-3 form (written at 9 significant digits)
        inside = (temp >= s["t_min"]) & (temp <= s["t_max"])
        want = np.polynomial.polynomial.polyval(temp[inside] - s["t_ref"],
                                                np.asarray(s["px4"]["x"]))
        np.testing.assert_allclose(ours[inside], want.T, rtol=1e-5, atol=1e-8)


def test_ardupilot_file_reads_back_and_equals_the_px4_form_about_35c(model, tmp_path):
    path = tmp_path / "tcal.param"
    get("thermal-imu", "ardupilot").write(model, path, {"caltemp_c": 24.0})
    p = tp.read_ardupilot(path.read_text())
    assert p["INS_TCAL1_ENABLE"] == 1 and p["INS_ACC1_CALTEMP"] == 24.0
    px = tp.read_px4(tp.px4_text(model.px4_sensors()))
    for s in model.sensors:
        temp = np.linspace(s["t_min"] - 10, s["t_max"] + 10, 41)
        v = np.full((temp.size, 3), 0.3)
        fw = _ap_firmware(p, s["kind"], 1, temp, v, 24.0)
        ours = tp.ardupilot_correct(p, s["kind"], 1, temp, v, 24.0)
        np.testing.assert_allclose(ours, fw, rtol=0, atol=2e-6 if s["kind"] == "accel" else 2e-7)
        # the same correction as PX4's, relative to the calibration temperature
        off = tp.px4_offset(px, s["kind"], 0, temp) - tp.px4_offset(px, s["kind"], 0, [24.0])
        np.testing.assert_allclose(v - ours, off, rtol=0,
                                   atol=2e-5 if s["kind"] == "accel" else 2e-6)
        assert np.all(ours[temp < p["INS_TCAL1_TMIN"]] == ours[0])  # constrained


def test_malformed_files_are_refused():
    with pytest.raises(InputError, match="line 2"):
        tp.read_px4("# c\n1 1 TC_A0_ID 5\n")
    with pytest.raises(InputError, match="line 1"):
        tp.read_ardupilot("INS_TCAL1_TMIN 1 2\n")
