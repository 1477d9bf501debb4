"""``allan --imu LOG1 LOG2 --pool`` and ``--warmup`` on the command line: the pooled JSON
keeps the six-axis layout with logs[] per axis; a log that cannot join is refused (exit
2) naming it; several logs without pooling are refused; --warmup is reported."""

import json

import numpy as np
import pandas as pd

from inertialab.sim.mems_presets import simulate
from tests.helpers import run_inprocess


def _write(path, seed, axes=("gx",), hours=0.1):
    cols = {}
    for j, ax in enumerate(axes):
        r = simulate("consumer-100hz", hours=hours, seed=seed + j)
        cols[f"{ax}_{r.unit}"] = r.y
    pd.DataFrame({"t_s": np.arange(r.y.size) / r.rate_hz, **cols}).to_csv(path, index=False)
    return path


def test_pool_json_keeps_the_layout_with_each_logs_terms(tmp_path, capsys):
    a, b = _write(tmp_path / "a.csv", 0), _write(tmp_path / "b.csv", 5)
    code, out, _ = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--pool-kind",
                                 "units", "--warmup", "0", "--json")
    assert code in (0, None)
    imu = json.loads(out)["imu"]
    assert imu["pooled"] and imu["pool_kind"] == "units" and len(imu["logs"]) == 2
    ax = imu["axes"][0]
    assert ax["axis"] == "gx" and [lg["file"] for lg in ax["logs"]] == [str(a), str(b)]
    assert ax["model_choice"]["chosen"] in ("wls", "wls-flicker")
    assert set(ax["model_choice"]["scores"]) == {"wls", "wls-flicker"}
    assert set(ax["between_logs"]) >= {"verdict", "p_value", "worst_tau_s"}


def test_a_log_missing_an_axis_is_refused_naming_it(tmp_path, capsys):
    a = _write(tmp_path / "a.csv", 0, axes=("gx", "gy"), hours=0.02)
    b = _write(tmp_path / "b.csv", 5, hours=0.02)
    code, _, err = run_inprocess(capsys, "allan", a, b, "--imu", "--pool")
    assert code == 2 and "b.csv" in err and "axes gy missing" in err
    assert len(err.strip().splitlines()) == 1


def test_several_logs_without_pool_are_refused(tmp_path, capsys):
    a, b = _write(tmp_path / "a.csv", 0, hours=0.02), _write(tmp_path / "b.csv", 5, hours=0.02)
    code, _, err = run_inprocess(capsys, "allan", a, b, "--imu")
    assert code == 2 and "--pool" in err


def test_warmup_setting_is_reported_in_the_six_axis_json(tmp_path, capsys):
    a = _write(tmp_path / "a.csv", 0, hours=0.1)
    code, out, _ = run_inprocess(capsys, "allan", a, "--imu", "--warmup", "60", "--json")
    assert code in (0, None)
    imu = json.loads(out)["imu"]
    assert imu["axes"][0]["warmup"]["excluded_s"] == 60.0
    assert imu["axes"][0]["stationarity"]["verdict"] in ("stationary", "not stationary")
    assert imu["n_samples"] == 36000 - 6000  # 0.1 h at 100 Hz, 60 s cut


def test_a_log_that_cannot_be_read_is_refused_naming_it_before_any_fit(tmp_path, capsys,
                                                                       monkeypatch):
    from inertialab.workflows import imu_pool

    def no_fit(*a, **k):
        raise AssertionError("a pooled axis was fitted")

    monkeypatch.setattr(imu_pool, "pool_axis", no_fit)
    a = _write(tmp_path / "a.csv", 0, hours=0.02)
    b = tmp_path / "b.csv"
    b.write_text("t_s,gx_dph\n0.0,abc\n")
    code, _, err = run_inprocess(capsys, "allan", a, b, tmp_path / "none.csv", "--imu",
                                 "--pool")
    assert code == 2 and "b.csv" in err and len(err.strip().splitlines()) == 1


def test_a_check_log_in_the_pool_is_refused_before_any_log_is_read(tmp_path, capsys):
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"  # neither exists: nothing is read
    code, _, err = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--predict-drift",
                                 "10", "--check-on", b)
    assert code == 2 and "--check-on" in err and "not in the pool" in err


def test_the_same_log_twice_is_refused_by_name_or_by_content(tmp_path, capsys, monkeypatch):
    """A log given twice (the same path, or a copy under another name) would read as two
    logs that agree: a between-log spread of none. It is refused naming it, before any
    fit; so is a check log whose samples are one of the pool's."""
    import shutil

    from inertialab.workflows import imu_pool

    def no_fit(*a, **k):
        raise AssertionError("a pooled axis was fitted")

    monkeypatch.setattr(imu_pool, "pool_axis", no_fit)
    a, b = _write(tmp_path / "a.csv", 0, hours=0.02), _write(tmp_path / "b.csv", 5, hours=0.02)
    copy = shutil.copy(a, tmp_path / "copy.csv")
    for files in ((a, a), (a, b, copy)):
        code, _, err = run_inprocess(capsys, "allan", *files, "--imu", "--pool")
        assert code == 2 and "the same samples as" in err and len(err.strip().splitlines()) == 1
    code, _, err = run_inprocess(capsys, "allan", a, b, "--imu", "--pool", "--predict-drift",
                                 "1", "--check-on", copy)
    assert code == 2 and "copy.csv" in err and "not in the pool" in err
