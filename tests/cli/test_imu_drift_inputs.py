"""``allan --imu`` drift prediction, warm-up and ``--pool`` on logs a user brings: a
horizon is checked against what the warm-up leaves, a check log must hold the analysed
axes, a horizon with nothing observed prints '-' (never 'nan'), the table shows the
interval its inside/outside is judged by, and a pool log with a constant axis is refused
naming that log and column."""

import json

import numpy as np
import pandas as pd

from tests.helpers import run_inprocess


def _white(path, seed, *, seconds=240.0, rate=100.0, axes=("gx_dps",), sd=0.05,
           constant=()):
    """A static log of white noise (``sd`` per sample) on ``axes``; ``constant`` axes
    hold one value throughout."""
    rng = np.random.default_rng(seed)
    n = int(seconds * rate)
    cols = {a: (np.full(n, 0.1) if a in constant else rng.normal(0.0, sd, n)) for a in axes}
    pd.DataFrame({"t_s": np.arange(n) / rate, **cols}).to_csv(path, index=False)
    return path


def test_a_horizon_past_what_the_warmup_leaves_of_the_half_is_refused(tmp_path, capsys):
    """240 s, 110 s cut: the first half of the 130 s left is 65 s, less than the 60-s
    horizon with its 10-s bias window (the whole log's half, 120 s, would hold it)."""
    a = _white(tmp_path / "a.csv", 0)
    code, _, err = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "110",
                                 "--predict-drift", "1,60", "--check-on", "half")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "a.csv" in err and "predict_drift" in err.replace("-", "_") and "60" in err
    assert "warm-up" in err


def test_a_check_log_without_the_analysed_axes_is_refused(tmp_path, capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=120.0, axes=("gx_dps", "gy_dps"))
    b = _white(tmp_path / "b.csv", 1, seconds=120.0, axes=("ax_mps2",), sd=0.01)
    code, _, err = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "0",
                                 "--predict-drift", "1", "--check-on", b)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "b.csv" in err and "gx gy" in err


def test_a_check_log_missing_some_axes_names_them(tmp_path, capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=60.0, axes=("gx_dps", "gy_dps"))
    b = _white(tmp_path / "b.csv", 1, seconds=60.0, axes=("gx_dps",))
    code, out, _ = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "0",
                                 "--predict-drift", "1", "--check-on", b, "--json")
    assert code in (0, None)
    d = json.loads(out)
    assert any("b.csv" in w and "no gy" in w and "not checked" in w for w in d["warnings"])
    axes = {x["axis"]: x for x in d["imu"]["axes"]}
    assert "check" in axes["gx"]["drift_prediction"]
    assert "check" not in axes["gy"]["drift_prediction"]


def test_a_horizon_the_check_log_cannot_observe_prints_a_dash_not_nan(tmp_path, capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=120.0)
    b = _white(tmp_path / "b.csv", 1, seconds=30.0)
    code, out, _ = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "0",
                                 "--predict-drift", "1,60", "--check-on", b)
    assert code in (0, None)
    rows = [ln for ln in out.splitlines() if "observed" in ln or "in model" in ln]
    assert rows and not any("nan" in ln.lower() for ln in rows)


def test_the_table_shows_the_interval_the_check_is_judged_by(tmp_path, capsys):
    """The inside/outside row is judged against the interval widened by the observed
    RMS's own sampling: the table shows that interval, and the JSON's."""
    a = _white(tmp_path / "a.csv", 0, seconds=240.0)
    code, out, _ = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "0",
                                 "--predict-drift", "1,60", "--check-on", "half", "--json")
    assert code in (0, None)
    chk = json.loads(out)["imu"]["axes"][0]["drift_prediction"]["check"]
    ci = chk["rms_ci_with_sampling"]
    code, out, _ = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "0",
                                 "--predict-drift", "1,60", "--check-on", "half")
    row = next(ln for ln in out.splitlines() if "with the check's sampling" in ln)
    assert f"{ci['low'][1]:.3g}-{ci['high'][1]:.3g}" in row
    # what the coverage and the RMS rest on: the windows observed, as in the JSON
    row = next(ln for ln in out.splitlines() if "windows observed" in ln)
    assert [v.strip() for v in row.split("│")[3:-1]] == [str(n) for n in chk["n_windows"]]


def test_a_pool_log_with_a_constant_axis_is_refused_naming_it(tmp_path, capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=120.0, axes=("gx_dps", "gy_dps"))
    b = _white(tmp_path / "b.csv", 1, seconds=120.0, axes=("gx_dps", "gy_dps"))
    c = _white(tmp_path / "c.csv", 2, seconds=120.0, axes=("gx_dps", "gy_dps"),
               constant=("gy_dps",))
    code, _, err = run_inprocess(capsys, "allan", a, b, c, "--imu", "--pool", "--warmup", "0")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "c.csv" in err and "a.csv" not in err and "gy_dps" in err


def test_a_pool_log_much_noisier_than_the_others_is_named_in_a_warning(tmp_path, capsys):
    """Three logs, one with three times the white noise: the between-log test says they
    differ, and a warning names that log (the pooled N averages the logs)."""
    a = _white(tmp_path / "a.csv", 0, seconds=60.0)
    b = _white(tmp_path / "b.csv", 1, seconds=60.0)
    c = _white(tmp_path / "loud.csv", 2, seconds=60.0, sd=0.15)
    code, out, _ = run_inprocess(capsys, "allan", a, b, c, "--imu", "--pool", "--warmup", "0",
                                 "--json")
    assert code in (0, None)
    d = json.loads(out)
    assert d["imu"]["axes"][0]["between_logs"]["verdict"] == "differ beyond sampling"
    hit = [w for w in d["warnings"] if "differ beyond sampling" in w]
    assert len(hit) == 1 and "loud.csv" in hit[0] and "gx_dps" in hit[0]


def test_a_pool_logs_stationarity_warning_names_the_log(tmp_path, capsys):
    """Three logs with one column name: the one whose second half is twice as noisy is
    named in its 'not stationary' warning, not only its column."""
    a = _white(tmp_path / "a.csv", 0, seconds=60.0)
    b = _white(tmp_path / "b.csv", 1, seconds=60.0)
    c = _white(tmp_path / "step.csv", 2, seconds=60.0)
    df = pd.read_csv(c)
    df.loc[df.index >= len(df) // 2, "gx_dps"] *= 2.0
    df.to_csv(c, index=False)
    code, out, _ = run_inprocess(capsys, "allan", a, b, c, "--imu", "--pool", "--warmup", "0",
                                 "--json")
    assert code in (0, None)
    hit = [w for w in json.loads(out)["warnings"] if "not stationary" in w]
    assert hit and all("step.csv" in w for w in hit)


def test_a_pool_of_two_rates_does_not_say_all_its_samples_are_at_the_first(tmp_path,
                                                                           capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=40.0)
    b = _white(tmp_path / "b.csv", 1, seconds=40.0, rate=200.0)
    code, out, _ = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--warmup", "0")
    assert code in (0, None)
    text = " ".join(out.split())  # the title as one line, however the table wraps it
    assert "12000 samples in all at 100 and 200 Hz" in text
    assert "samples at 100 Hz" not in text


def test_a_pool_log_too_short_for_a_horizon_is_named_and_left_out_of_the_spread_there(
        tmp_path, capsys):
    """Two 60-s logs and one of 30 s at a 40-s horizon (+ 10 s): the short log is named
    in a warning; at 40 s the between-log drift spread is the two long logs' alone (its
    own 40-s prediction would extrapolate its model), at 1 s all three count."""
    from inertialab.noise.statistics.allan import oadev
    from inertialab.workflows.imu_drift import DriftOptions
    from inertialab.workflows.imu_noise import fit_axis_terms
    from inertialab.workflows.imu_pool import drift_between

    a = _white(tmp_path / "a.csv", 0, seconds=60.0)
    b = _white(tmp_path / "b.csv", 1, seconds=60.0)
    c = _white(tmp_path / "c.csv", 2, seconds=30.0)
    code, out, _ = run_inprocess(capsys, "allan", a, b, c, "--imu", "--pool", "--warmup", "0",
                                 "--predict-drift", "1,40", "--json")
    assert code in (0, None)
    assert any("c.csv" in w and "40-s horizon" in w for w in json.loads(out)["warnings"])

    terms = []
    for seed, sd in ((0, 0.05), (1, 0.05), (2, 0.2)):
        y = np.random.default_rng(seed).normal(0.0, sd, 3000)
        dev = oadev(y, rate_hz=100.0, taus="octave", confidence=0.95)
        terms.append(fit_axis_terms(y, dev, "dps", "gyro", rate_hz=100.0, lines=()))
    opts = DriftOptions(horizons_s=(1.0, 40.0))
    within = [np.array([0.01, 0.02]), np.array([0.0, 0.03]), np.array([0.5, 0.9])]
    kw = dict(within=within, lengths_s=[60.0, 60.0, 30.0])
    three = drift_between(terms, [100.0] * 3, [None] * 3, opts, **kw)
    two = drift_between(terms[:2], [100.0] * 2, [None] * 2, opts, within=within[:2])
    every = drift_between(terms, [100.0] * 3, [None] * 3, opts, within=within)
    assert three[1] == two[1] and three[0] == every[0] and every[1] != two[1]


def test_a_warmup_too_long_for_one_pool_log_names_that_log(tmp_path, capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=60.0)
    b = _white(tmp_path / "short.csv", 1, seconds=30.0)
    code, _, err = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--warmup", "20")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "short.csv" in err and "a.csv" not in err and "--warmup 20" in err


def test_a_pool_check_log_of_another_sensor_kind_is_refused_as_the_check_log(tmp_path,
                                                                             capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=60.0)
    b = _white(tmp_path / "b.csv", 1, seconds=60.0)
    acc = _white(tmp_path / "acc.csv", 2, seconds=60.0, axes=("ax_mps2",), sd=0.01)
    code, _, err = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--warmup", "0",
                                 "--predict-drift", "1", "--check-on", acc)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "acc.csv: cannot be the check log: axes gx missing" in err
    assert err.count("acc.csv") == 1


def test_an_unobserved_horizon_has_no_interval_in_the_json(tmp_path, capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=120.0)
    b = _white(tmp_path / "b.csv", 1, seconds=30.0)
    code, out, _ = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "0",
                                 "--predict-drift", "1,60", "--check-on", b, "--json")
    assert code in (0, None)
    chk = json.loads(out)["imu"]["axes"][0]["drift_prediction"]["check"]
    assert chk["observed_rms"][1] is None and chk["inside_rms_ci"][1] is None
    assert chk["rms_ci_with_sampling"]["low"][1] is None
    assert chk["rms_ci_with_sampling"]["high"][1] is None
    assert 0 <= chk["rms_ci_with_sampling"]["low"][0] < chk["rms_ci_with_sampling"]["high"][0]


def test_pool_logs_of_other_column_names_pool_with_one_map(tmp_path, capsys):
    """One log names its column gx_dps, the other 'Gyro X [deg/s]': a map for the second
    no longer refuses the first (it has none of the map's sources and is read by its own
    names, said in a warning); a map whose source no log has is still refused."""
    a = _white(tmp_path / "a.csv", 0, seconds=40.0)
    b = _white(tmp_path / "b.csv", 1, seconds=40.0, axes=("Gyro X [deg/s]",))
    code, out, _ = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--warmup", "0",
                                 "--map", "gx_dps=Gyro X [deg/s]", "--json")
    assert code in (0, None)
    d = json.loads(out)
    assert [lg["columns"]["gx"] for lg in d["imu"]["logs"]] == ["gx_dps", "gx_dps"]
    assert any("a.csv" in w and "its own column names" in w for w in d["warnings"])
    code, _, err = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--warmup", "0",
                                 "--map", "gx_dps=Gyro Y")
    assert code == 2 and "Gyro Y" in err and len(err.strip().splitlines()) == 1


def test_a_check_logs_warmup_is_judged_with_its_temperature_and_named_if_too_long(
        tmp_path, capsys):
    """The check log's warm-up span is found as the analysed log's: with its temperature
    column (a 30-s settling the axes do not show cuts its start, so its 1-s horizon holds
    fewer windows); a --warmup too long for the check log names it."""
    a = _white(tmp_path / "a.csv", 0, seconds=120.0)
    b = _white(tmp_path / "b.csv", 1, seconds=120.0)
    df = pd.read_csv(b)
    t = df["t_s"].to_numpy()
    df["temp_c"] = 25.0 + 5.0 * np.exp(-t / 30.0) + np.random.default_rng(3).normal(
        0.0, 0.01, t.size)
    df.to_csv(b, index=False)
    code, out, _ = run_inprocess(capsys, "allan", a, "--imu", "--predict-drift", "1",
                                 "--check-on", b, "--json")
    assert code in (0, None)
    n = json.loads(out)["imu"]["axes"][0]["drift_prediction"]["check"]["n_windows"][0]
    assert n < 120 // 11
    short = _white(tmp_path / "short.csv", 2, seconds=30.0)
    code, _, err = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "20",
                                 "--predict-drift", "1", "--check-on", short)
    assert code == 2 and "short.csv" in err and len(err.strip().splitlines()) == 1


def test_pool_kind_units_on_one_log_is_refused_not_ignored(tmp_path, capsys):
    a = tmp_path / "a.csv"  # not read: refused before
    code, _, err = run_inprocess(capsys, "allan", a, "--imu", "--pool-kind", "units")
    assert code == 2 and "--pool-kind" in err and "--pool" in err
    assert len(err.strip().splitlines()) == 1


def _constant_check(tmp_path, capsys, pool: bool) -> None:
    axes = ("gx_dps", "gy_dps")
    logs = [_white(tmp_path / "a.csv", 0, seconds=40.0, axes=axes)]
    if pool:
        logs.append(_white(tmp_path / "b.csv", 1, seconds=40.0, axes=axes))
    c = _white(tmp_path / "c.csv", 2, seconds=40.0, axes=axes, constant=("gy_dps",))
    code, out, _ = run_inprocess(capsys, "allan", *logs, "--imu", *(("--pool",) if pool else ()),
                                 "--warmup", "0", "--predict-drift", "1", "--check-on", c,
                                 "--json")
    assert code in (0, None)
    d = json.loads(out)
    assert any("c.csv" in w and "gy_dps" in w and "not checked" in w for w in d["warnings"])
    axes_d = {x["axis"]: x["drift_prediction"] for x in d["imu"]["axes"]}
    assert "check" in axes_d["gx"] and "check" not in axes_d["gy"]


def test_a_constant_axis_of_the_check_log_is_not_checked_and_not_a_miss(tmp_path, capsys):
    """A check log whose gy is stuck at one value observes no drift there: that axis is
    named in a warning and not checked (it read 'NO' at every horizon, observed 0); a
    check log with no usable axis is refused."""
    _constant_check(tmp_path, capsys, pool=False)
    a = tmp_path / "a.csv"
    dead = _white(tmp_path / "dead.csv", 3, seconds=40.0, axes=("gx_dps", "gy_dps"),
                  constant=("gx_dps", "gy_dps"))
    code, _, err = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "0",
                                 "--predict-drift", "1", "--check-on", dead)
    assert code == 2 and "dead.csv" in err and len(err.strip().splitlines()) == 1


def test_a_constant_axis_of_a_pools_check_log_is_not_checked(tmp_path, capsys):
    _constant_check(tmp_path, capsys, pool=True)


def test_axes_a_pool_log_has_beyond_the_first_logs_are_named_as_left_out(tmp_path, capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=40.0)
    b = _white(tmp_path / "b.csv", 1, seconds=40.0, axes=("gx_dps", "ax_mps2"))
    code, out, _ = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--warmup", "0",
                                 "--json")
    assert code in (0, None)
    d = json.loads(out)
    assert [x["axis"] for x in d["imu"]["axes"]] == ["gx"]
    assert any("b.csv" in w and "ax" in w and "left out" in w for w in d["warnings"])


def test_an_inflated_export_says_which_sensor_the_check_log_could_not_inflate(tmp_path,
                                                                              capsys):
    """--inflate auto with a check log of gyros only: the accelerometer's values are
    exported as fitted, and the file says so (it said nothing of them)."""
    a = _white(tmp_path / "a.csv", 0, seconds=60.0, axes=("gx_dps", "ax_mps2"))
    b = _white(tmp_path / "b.csv", 1, seconds=60.0, axes=("gx_dps",))
    out_file = tmp_path / "kalibr.yaml"
    code, _, _ = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "0",
                               "--predict-drift", "1", "--check-on", b, "--export", "kalibr",
                               out_file, "--inflate", "auto")
    assert code in (0, None)
    text = out_file.read_text()
    assert "accelerometer noise density and random walk NOT inflated" in " ".join(
        text.replace("#", " ").split())


def test_two_pool_logs_that_differ_are_compared_not_one_called_farthest(tmp_path, capsys):
    a = _white(tmp_path / "a.csv", 0, seconds=40.0)
    b = _white(tmp_path / "loud.csv", 1, seconds=40.0, sd=0.15)
    code, out, _ = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--warmup", "0",
                                 "--json")
    assert code in (0, None)
    hit = [w for w in json.loads(out)["warnings"] if "differ beyond sampling" in w]
    assert len(hit) == 1 and "farthest" not in hit[0]
    assert "loud.csv's Allan deviation is 3" in hit[0] and "a.csv's there" in hit[0]


def test_a_check_log_that_is_a_copy_of_the_analysed_log_is_refused(tmp_path, capsys):
    """A copy under another name checks the model on the samples it was fitted on (a pool
    refuses it already): refused naming the copy."""
    a = _white(tmp_path / "a.csv", 0, seconds=40.0)
    copy = tmp_path / "copy.csv"
    copy.write_bytes(a.read_bytes())
    code, _, err = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "0",
                                 "--predict-drift", "1", "--check-on", copy)
    assert code == 2 and "copy.csv" in err and len(err.strip().splitlines()) == 1


def test_a_drift_prediction_at_another_confidence_is_refused(tmp_path, capsys):
    """The drift interval is 95 % and reads the terms' intervals as 95 % ones: with
    --confidence 0.68 its terms part came out about half as wide (ax 0.099 -> 0.049 in
    log-sd) and was still called 95 %; refused before any log is read, one log or a pool."""
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"  # not read
    for logs in ((a,), (a, b)):
        pool = ("--pool",) if len(logs) > 1 else ()
        code, _, err = run_inprocess(capsys, "allan", *logs, "--imu", *pool, "--confidence",
                                     "0.68", "--predict-drift", "1")
        assert code == 2 and "--confidence" in err and "--predict-drift" in err
        assert len(err.strip().splitlines()) == 1


def test_options_the_six_axis_mode_does_not_use_are_refused_not_ignored(tmp_path, capsys):
    """--taus many and --stat mdev were accepted and the octave OADEV used all the same;
    --no-terms with --pool was ignored (the pool fits terms)."""
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"  # not read: refused before
    for extra in (("--taus", "many"), ("--stat", "mdev")):
        for logs in ((a,), (a, b)):
            pool = ("--pool",) if len(logs) > 1 else ()
            code, _, err = run_inprocess(capsys, "allan", *logs, "--imu", *pool, *extra)
            assert code == 2 and extra[0] in err and len(err.strip().splitlines()) == 1
    code, _, err = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--no-terms")
    assert code == 2 and "--terms" in err and len(err.strip().splitlines()) == 1
