"""Motion refused per axis, with the reason (workflows.imu_noise_static), and exports that
refuse axes that are not static: simulated flights and benches of known truth, and the
PX4 logs of the shared data."""

import json
import math

import numpy as np
import pandas as pd
import pytest

from inertialab.io import validate_frame
from inertialab.workflows.imu_noise import analyse_record
from inertialab.workflows.imu_noise_static import band_excess, motion_reasons
from tests.helpers import run_inprocess

G = 9.80665
FS = 250.0


def _flight(seed=0, seconds=69.0):
    """A 69-s flight at 250 Hz: each rate the sum of six sinusoids of 0.3-3 Hz (about
    +-2.7 rad/s together) plus white noise of 0.005 rad/s per sample; the accelerometer
    the gravity direction of the integrated roll and pitch plus white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * FS)) / FS
    rates = np.zeros((t.size, 3))
    for k in range(3):
        for _ in range(6):
            f, ph = rng.uniform(0.3, 3.0), rng.uniform(0, 2 * np.pi)
            rates[:, k] += 0.45 * np.sin(2 * np.pi * f * t + ph)
    roll = np.cumsum(rates[:, 0]) / FS
    pitch = np.cumsum(rates[:, 1]) / FS
    acc = G * np.column_stack([-np.sin(pitch), np.sin(roll) * np.cos(pitch),
                               np.cos(roll) * np.cos(pitch)])
    gyro = rates + 0.005 * rng.standard_normal(rates.shape)
    acc = acc + 0.03 * rng.standard_normal(acc.shape)
    return t, gyro, acc


def _bench(seed=1, seconds=300.0, wobble=0.0):
    """A static bench: white noise on six axes, gravity on z, and optionally a 0.5-Hz
    line of ``wobble`` rad/s on gx (a pump, a fan)."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * FS)) / FS
    gyro = 0.005 * rng.standard_normal((t.size, 3))
    gyro[:, 0] += wobble * np.sin(2 * np.pi * 0.5 * t)
    acc = 0.03 * rng.standard_normal((t.size, 3)) + [0.0, 0.0, G]
    return t, gyro, acc


def _frame(t, gyro, acc):
    d = {"t_s": t}
    for i, c in enumerate("xyz"):
        d[f"g{c}_rps"] = gyro[:, i]
    for i, c in enumerate("xyz"):
        d[f"a{c}_mps2"] = acc[:, i]
    return pd.DataFrame(d)


def test_simulated_flight_is_not_static_on_all_six_axes():
    t, gyro, acc = _flight()
    cols = {f"g{c}": gyro[:, i] for i, c in enumerate("xyz")}
    cols.update({f"a{c}": acc[:, i] for i, c in enumerate("xyz")})
    why = motion_reasons(cols, FS)
    assert sorted(why) == sorted(cols)
    assert all(("white-noise floor" in w or "gravity direction" in w) for w in why.values())


@pytest.mark.parametrize("seed", [0, 5])
@pytest.mark.parametrize("name", ["consumer-100hz", "industrial-400hz", "consumer-1khz",
                                  "accel-200hz"])
def test_static_presets_pass_on_every_axis_through_their_own_low_pass(name, seed):
    # the presets carry a Butterworth low-pass at rate/10 (as real MEMS do): the bands
    # it rolls off are no white floor, and no axis of a static 3-min triad is refused
    from benchmarks.motion_check import preset_triad

    cols, fs = preset_triad(name, seed, 0.05)
    assert motion_reasons(cols, fs) == {}
    assert all(band_excess(y, fs)[0] < 2.0 for y in cols.values())


@pytest.mark.parametrize("name", ["consumer-100hz", "industrial-400hz", "consumer-1khz",
                                  "accel-200hz"])
def test_the_floor_is_the_white_density_not_the_roll_off(name):
    # one-sided PSD of the white noise, quantisation included: 2 N^2; the floor (the
    # lowest band median of the plateau) sits a little under it on 30 min
    from inertialab.sim.mems_presets import preset, simulate

    r = simulate(name, hours=0.5, seed=11)
    floor = band_excess(r.y, r.rate_hz)[3]
    assert floor / (2.0 * preset(name).n_total(r.rate_hz) ** 2) == pytest.approx(0.95, abs=0.1)


@pytest.mark.parametrize("seed", [0, 3])
@pytest.mark.parametrize("kind", ["flight", "handling", "sway"])
def test_simulated_motion_is_refused_on_all_six_axes(kind, seed):
    import benchmarks.motion_check as mc

    cols = getattr(mc, kind)(seed)
    assert sorted(motion_reasons(cols, mc.FS)) == sorted(mc.AXES)


def test_a_filter_set_low_passes_and_motion_through_it_is_still_refused():
    # the sensor's low-pass at rate/50 (consumer-100hz: 2 Hz) is its roll-off, not a
    # floor; motion through a filter at rate/100 is still motion on every axis
    import benchmarks.motion_check as mc

    from inertialab.sim.mems_presets import preset, simulate

    r = simulate(preset("consumer-100hz").with_(lpf_fraction=0.02), hours=0.05, seed=4)
    assert motion_reasons({"gx": r.y}, r.rate_hz) == {}
    for kind in ("handling", "sway"):
        cols = mc.low_passed(getattr(mc, kind)(1), 0.01)
        assert sorted(motion_reasons(cols, mc.FS)) == sorted(mc.AXES)


def test_a_broad_sway_is_motion_a_narrow_line_of_the_same_power_is_not():
    import benchmarks.motion_check as mc

    rng = np.random.default_rng(2)
    sway = mc.sway(2)["gx"]
    t = np.arange(sway.size) / mc.FS
    line = 0.005 * rng.standard_normal(t.size) + sway.std() * math.sqrt(2) * np.sin(
        2 * np.pi * 0.3 * t)
    assert "gx" in motion_reasons({"gx": sway}, mc.FS)
    assert motion_reasons({"gx": line}, mc.FS) == {}


def test_bench_with_a_narrow_line_is_static_and_reports_the_line():
    # a 0.5-Hz line 10x the per-sample noise; 300 s is too short for the line search at
    # 0.5 Hz (16 bins of 30 Welch segments), so the gyro axis alone over 600 s
    t, gyro, acc = _bench(wobble=0.05, seconds=600.0)
    rec = validate_frame(pd.DataFrame({"t_s": t, "gx_rps": gyro[:, 0]}), "gyro_log",
                         path="bench.csv")
    res = analyse_record(rec)
    assert [a.status for a in res.axes] == ["ok"]
    cols = {f"g{c}": gyro[:, i] for i, c in enumerate("xyz")}
    cols.update({f"a{c}": acc[:, i] for i, c in enumerate("xyz")})
    assert motion_reasons(cols, FS) == {}
    lines = res.axis("gx").terms.lines
    assert lines and abs(lines[0].f_hz - 0.5) < 0.02
    # the line's amplitude is the truth's within 10 %
    assert lines[0].amplitude == pytest.approx(0.05, rel=0.1)


def test_exports_refuse_a_moving_log_and_force_says_so(tmp_path, capsys):
    t, gyro, acc = _flight(seconds=40.0)
    f = tmp_path / "flight.csv"
    _frame(t, gyro, acc).to_csv(f, index=False)
    k, r = tmp_path / "k.yaml", tmp_path / "r.yaml"
    code, _, err = run_inprocess(capsys, "allan", str(f), "--imu", "--export", "kalibr",
                                 str(k), "--export", "ros", str(r))
    errors = [x for x in err.splitlines() if x.startswith("error:")]
    assert code == 2 and len(errors) == 1 and "gx (not static)" in errors[0]
    assert "--force" in errors[0] and not k.exists() and not r.exists()


def test_every_export_written_and_the_span_named(tmp_path, capsys):
    t, gyro, acc = _bench(seconds=120.0)
    gyro[:, 2] = 0.02  # a stuck gz: flagged 'constant', left out of the gyro value
    f = tmp_path / "bench.csv"
    _frame(t, gyro, acc).to_csv(f, index=False)
    k, r = tmp_path / "k.yaml", tmp_path / "r.yaml"
    code, out, err = run_inprocess(capsys, "allan", str(f), "--imu", "--export", "kalibr",
                                   str(k), "--export", "ros", str(r), "--json")
    assert code == 2 and not k.exists() and "gz (constant)" in err
    code, out, err = run_inprocess(capsys, "allan", str(f), "--imu", "--export", "kalibr",
                                   str(k), "--export", "ros", str(r), "--json", "--force")
    assert code in (0, None), err
    assert k.exists() and r.exists()
    text = k.read_text()
    assert "gyroscope values: the largest of gx, gy; left out: gz (constant)" in text
    assert "accelerometer values: the largest of ax, ay, az." in text
    assert "Written (forced) although gz (constant)" in text
    settings = json.loads(out)["settings"]
    assert [e["target"] for e in settings["exports"]] == ["kalibr", "ros"]
    # the density written is the largest of the two static gyro axes (truth 0.005/sqrt(250))
    dens = float(text.split("gyroscope_noise_density:")[1].split()[0])
    assert dens == pytest.approx(0.005 / math.sqrt(FS), rel=0.1)


def _shared_px4():
    from benchmarks.real_logs import SHARED

    d = SHARED.parent / "px4"
    if not d.is_dir():
        pytest.skip("the shared data folder is absent (a clone without it)")
    return d


def test_px4_moving_log_refused_on_six_axes_and_sensor_combined_named():
    from inertialab.errors import DataQualityWarning
    from inertialab.io import read_record

    rec = read_record(_shared_px4() / "sample_appended_multiple.ulg", "gyro_log")
    with pytest.warns(DataQualityWarning) as w:
        res = analyse_record(rec)
    assert [a.status for a in res.axes] == ["not static"] * 6
    text = " ".join(str(x.message) for x in w)
    assert "sensor_combined" in text and "sensor_gyro" in text and "sensor_accel" in text
    assert "sensor_gyro" in res.settings["source_note"]


def test_the_command_line_names_flags_in_warnings_notes_and_help(capsys):
    # library messages name the argument ('topic', 'pool'); the user reads the flag
    code, out, err = run_inprocess(capsys, "allan", str(_shared_px4() / "sample_appended_multiple.ulg"),
                                   "--imu", "--no-terms")
    assert code in (0, None), err
    assert "--topic" in err + out and "argument '" not in err + out
    code, out, err = run_inprocess(capsys, "allan", "--help")
    assert "With --pool:" in " ".join(out.split())
