"""Fuzz cases of the units and per-axis findings (generated data, one case per finding):
a check log in other units, a fine fibre-optic step in deg/h, accelerometers in mg,
unsigned counts with a known sensitivity, one constant axis. Each asserts the right
result against the generated truth, or exit 2 with one line naming the column, and that
``validate --kind imu`` agrees with the analysis."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest

from tests.helpers import run_inprocess

G = 9.80665
FS = 100.0


def _static_imu(n=60_000, seed=0):
    """Six static axes in SI: white noise, gravity on z (truth: N 2e-3 rad/s/sqrt(Hz),
    3e-3 m/s^2/sqrt(Hz))."""
    rng = np.random.default_rng(seed)
    g = 2e-3 * math.sqrt(FS) * rng.standard_normal((n, 3)) + [1e-3, -2e-3, 5e-4]
    a = 3e-3 * math.sqrt(FS) * rng.standard_normal((n, 3)) + [0.05, -0.1, G]
    return np.arange(n) / FS, g, a


def _write(path, t, g, a, gu="rps", au="mps2"):
    cols = {"t_s": t}
    for i, c in enumerate("xyz"):
        cols[f"g{c}_{gu}"] = g[:, i]
    for i, c in enumerate("xyz"):
        cols[f"a{c}_{au}"] = a[:, i]
    pd.DataFrame(cols).to_csv(path, index=False, float_format="%.17g")
    return path


def _one_error_line(err):
    lines = [x for x in err.splitlines() if x.startswith("error:")]
    assert len(lines) == 1, err
    return lines[0]


def test_check_log_in_its_own_units(tmp_path, capsys):
    """The same samples as check log, once in rad/s and m/s^2, once in deg/s and g: the
    observed drift is the same number (the check log converted by its own units). The
    analysed log is another draw (a check log holding its samples is refused)."""
    t, g, a = _static_imu(n=10_000)
    _, g0, a0 = _static_imu(n=10_000, seed=1)

    def write(name, gx, az, gu, au):
        p = tmp_path / name
        pd.DataFrame({"t_s": t, f"gx_{gu}": gx, f"az_{au}": az}).to_csv(
            p, index=False, float_format="%.17g")
        return p

    main = write("main.csv", g0[:, 0], a0[:, 2], "rps", "mps2")
    si = write("check_si.csv", g[:, 0], a[:, 2], "rps", "mps2")
    deg = write("check_deg.csv", np.degrees(g[:, 0]), a[:, 2] / G, "dps", "g")
    obs = {}
    for name, p in (("si", si), ("deg", deg)):
        code, out, err = run_inprocess(capsys, "allan", str(main), "--imu", "--predict-drift",
                                       "10", "--check-on", str(p), "--json")
        assert code in (0, None), err
        axes = json.loads(out)["imu"]["axes"]
        obs[name] = {x["axis"]: x["drift_prediction"]["check"]["observed_rms"] for x in axes}
    for ax in ("gx", "az"):
        np.testing.assert_allclose(obs["deg"][ax], obs["si"][ax], rtol=1e-9)


def test_fine_fog_step_in_deg_per_h(tmp_path, capsys):
    """A FOG in deg/h on a 0.02 deg/h grid: mapped without a unit, the step fits deg/s
    and deg/h alike, so it asks, naming both (validate alike); declared by its suffix,
    it is read in deg/h."""
    rng = np.random.default_rng(1)
    n = 5000
    y = np.round((rng.normal(0.0, 0.5, n) + 15.0) / 0.02) * 0.02  # deg/h, Earth rate
    p = tmp_path / "fog.csv"
    pd.DataFrame({"t_s": np.arange(n) / FS, "Rate": y}).to_csv(p, index=False)
    for cmd in (("validate", str(p), "--kind", "allan"), ("allan", str(p))):
        code, _, err = run_inprocess(capsys, *cmd, "--map", "t_s=t_s,rate_rps=Rate")
        line = _one_error_line(err)
        assert code == 2 and "'Rate'" in line and "deg/s and in deg/h" in line, err
    q = tmp_path / "fog_dph.csv"
    pd.DataFrame({"t_s": np.arange(n) / FS, "rate_dph": y}).to_csv(q, index=False)
    code, out, err = run_inprocess(capsys, "validate", str(q), "--kind", "allan", "--json")
    assert code in (0, None), err


def test_mg_accelerometer_checked_against_gravity(tmp_path, capsys):
    """Accelerometers written in g but labelled mg read |a| = 0.001 g: refused by the
    analysis and by validate, naming the columns and the unit they look like; the same
    samples in mg (|a| = 1000 mg) pass."""
    t, g, a = _static_imu(n=6000)
    bad = _write(tmp_path / "bad.csv", t, g, a / G, au="mg")
    for cmd in (("validate", str(bad), "--kind", "imu"), ("allan", str(bad), "--imu")):
        code, _, err = run_inprocess(capsys, *cmd)
        line = _one_error_line(err)
        assert code == 2 and "ax_mg, ay_mg, az_mg" in line and "look like g" in line, err
    good = _write(tmp_path / "good.csv", t, g, a / G * 1000.0, au="mg")
    code, _, err = run_inprocess(capsys, "validate", str(good), "--kind", "imu")
    assert code in (0, None), err


def test_unsigned_counts_with_known_sensitivity():
    """Unsigned 16-bit counts (zero at 32768) with lsb_per_g known: the mid-scale is
    removed (declared ``adc`` or detected), the calibrated biases are the truth's."""
    from inertialab.sim import triaxial_poses as tp
    from inertialab.workflows import triaxial as fc

    rec = tp.simulate("turntable62", seed=3)
    lpg = 16384.0
    for adc in ({"bits": 16, "signed": False}, None):
        df = rec.data.copy()
        for c in "xyz":
            df[f"a{c}_lsb"] = df.pop(f"a{c}_mps2") * lpg / rec.meta["g_local_mps2"] \
                + 32768.0
        meta = dict(rec.meta, units="lsb", lsb_per_g=lpg)
        if adc is not None:
            meta["adc"] = adc
        sd = fc.static_data_from_frame(df, meta)
        true_a = rec.data[["true_ax_mps2", "true_ay_mps2", "true_az_mps2"]].to_numpy()
        # the converted records are the sensor's output in m/s^2: the noise level apart
        assert np.max(np.abs(sd.a - true_a)) < 0.01
        f = fc.calibrate(sd.a, ref=sd.ref, objective="scalar", g=sd.g)
        np.testing.assert_allclose(f.x[:3], tp.X_MPU6050_A[:3], atol=0.01)


def test_one_constant_axis_flags_itself_and_the_rest_go_on(tmp_path, capsys):
    """A stuck gy: five axes analysed (N within 5 % of the truth), gy flagged
    'constant'; a 10-sample log refused by validate --kind imu as by the analysis."""
    t, g, a = _static_imu(n=30_000, seed=4)
    g[:, 1] = 0.0125
    p = _write(tmp_path / "stuck.csv", t, g, a)
    code, out, err = run_inprocess(capsys, "allan", str(p), "--imu", "--json")
    assert code in (0, None), err
    axes = {x["axis"]: x for x in json.loads(out)["imu"]["axes"]}
    assert axes["gy"]["status"] == "constant"
    for ax, n_true in (("gx", 2e-3), ("gz", 2e-3), ("ax", 3e-3), ("ay", 3e-3), ("az", 3e-3)):
        assert axes[ax]["status"] == "ok"
        assert axes[ax]["noise_density"]["value"] == pytest.approx(n_true, rel=0.05)
    code, _, err = run_inprocess(capsys, "validate", str(p), "--kind", "imu")
    assert code in (0, None), err
    short = _write(tmp_path / "short.csv", t[:10], g[:10], a[:10])
    codes = []
    for cmd in (("validate", str(short), "--kind", "imu"), ("allan", str(short), "--imu")):
        code, _, err = run_inprocess(capsys, *cmd)
        codes.append(code)
        _one_error_line(err)
    assert codes == [2, 2]
    # every axis stuck: nothing to analyse, refused by both alike
    g[:] = 0.0125
    a[:] = [0.0, 0.0, G]
    dead = _write(tmp_path / "dead.csv", t[:2000], g[:2000], a[:2000])
    for cmd in (("validate", str(dead), "--kind", "imu"), ("allan", str(dead), "--imu")):
        code, _, err = run_inprocess(capsys, *cmd)
        assert code == 2 and "constant" in _one_error_line(err)


def test_a_stuck_stretch_flags_its_axis_and_exports_refuse(tmp_path, capsys):
    """gy frozen for a quarter of the log (a driver resending its last sample): gy is
    'stuck' with the run's length and start, the other five axes are analysed exactly
    as in the same log without the frozen stretch, and an export is refused naming gy,
    nothing written. Quantised accelerometers at rest (a 3-mm/s^2 step: a third of the
    pairs repeat, like the ADIS16405's) are not flagged."""
    t, g, a = _static_imu(n=40_000, seed=5)
    a = np.round(a / 0.003) * 0.003

    def axes_of(name, g):
        p = _write(tmp_path / name, t, g, a)
        code, out, err = run_inprocess(capsys, "allan", str(p), "--imu", "--json")
        assert code in (0, None), err
        return p, {x["axis"]: x for x in json.loads(out)["imu"]["axes"]}

    _, clean = axes_of("clean.csv", g)
    g = g.copy()
    g[20_000:30_000, 1] = g[20_000, 1]
    p, axes = axes_of("frozen.csv", g)
    assert clean["gy"]["status"] == "ok" and axes["gy"]["status"] == "stuck"
    assert "10000 identical samples from sample 20000" in axes["gy"]["reason"]
    for ax in ("gx", "gz", "ax", "ay", "az"):
        assert axes[ax]["status"] == "ok", axes[ax]
        assert axes[ax]["noise_density"] == clean[ax]["noise_density"]
    dest = tmp_path / "kalibr.yaml"
    code, _, err = run_inprocess(capsys, "allan", str(p), "--imu", "--export", "kalibr",
                                 str(dest))
    assert code == 2 and "gy (stuck)" in _one_error_line(err) and not dest.exists()
