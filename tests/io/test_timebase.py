"""The one time base of a record: decided once by read_record (rate option > sidecar
fs_hz > time stamps), one jitter policy (a warning with the figures, NaN slots for lost
samples), and every command reporting the same rate for the same file."""

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from tests.helpers import run_inprocess

from inertialab.errors import DataQualityWarning, InputError
from inertialab.io import read_record, write_record
from inertialab.io.timestamps import decide_timebase

PX4 = Path(__file__).resolve().parents[1] / "data" / "px4"


def _write(tmp_path, t, meta=None, name="log.csv"):
    y = np.random.default_rng(0).normal(size=t.size)
    return write_record(pd.DataFrame({"t_s": t, "rate_dph": y}), tmp_path / name, meta or {})


def test_precedence_rate_option_then_sidecar_then_stamps(tmp_path):
    t = np.arange(500) / 100.0 * 1.002  # a logger clock 0.2 % slow of the nominal 100 Hz
    p = _write(tmp_path, t)
    rec = read_record(p, "gyro_log")
    assert rec.timebase.source == "timestamps"
    assert rec.timebase.rate_hz == pytest.approx(499 / t[-1], rel=1e-12)
    p = _write(tmp_path, t, {"fs_hz": 100.0}, name="side.csv")
    rec = read_record(p, "gyro_log")
    assert (rec.timebase.source, rec.timebase.rate_hz) == ("sidecar", 100.0)
    assert rec.timebase.stamps_rate_hz == pytest.approx(499 / t[-1], rel=1e-12)
    rec = read_record(p, "gyro_log", rate_hz=50.0)
    assert (rec.timebase.source, rec.timebase.rate_hz, rec.timebase.tau0_s) == \
        ("argument", 50.0, 0.02)
    assert rec.meta["timebase"]["rate_hz"] == 50.0


def test_sidecar_rate_contradicting_the_stamps_is_an_error_naming_both(tmp_path):
    # the fuzz case: fs_hz 10 beside stamps stepping 1e-7 s
    p = _write(tmp_path, np.arange(100) * 1e-7, {"fs_hz": 10.0})
    with pytest.raises(InputError, match=r"log.csv: column 't_s': the sidecar's fs_hz = 10 Hz "
                                         r"contradicts the time stamps \(1e\+07 Hz"):
        read_record(p, "gyro_log")
    # the rate option settles it
    assert read_record(p, "gyro_log", rate_hz=10.0).timebase.rate_hz == 10.0


def test_one_jitter_policy_warning_with_figures_and_nan_slots(tmp_path):
    n, fs = 2000, 50.0
    keep = np.ones(n, bool)
    keep[[300, 301, 1500]] = False
    t = np.arange(n)[keep] / fs
    p = _write(tmp_path, t)
    with pytest.warns(DataQualityWarning) as rec_w:
        rec = read_record(p, "gyro_log")
    msgs = [str(w.message) for w in rec_w if issubclass(w.category, DataQualityWarning)
            and "time stamps" in str(w.message)]
    assert len(msgs) == 1 and "3 sample(s) lost" in msgs[0] and "rows 301" in msgs[0]
    tb = rec.timebase
    assert (tb.n_slots, tb.n_missing, tb.n_gaps) == (n, 3, 2)
    assert tb.rate_hz == pytest.approx(fs, rel=1e-12)
    placed = tb.place(rec.column("rate_dph"))
    assert placed.size == n and np.isnan(placed[[300, 301, 1500]]).all()
    np.testing.assert_array_equal(placed[keep], rec.column("rate_dph"))


def test_uniform_stamps_no_warning_and_no_stamps_no_rate():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tb = decide_timebase(np.arange(10) * 0.01, n=10)
    assert tb.index is None and tb.jitter_max_rel == 0.0 and tb.rate_hz == pytest.approx(100)
    assert decide_timebase(None, n=10) is None
    assert decide_timebase(None, n=10, nominal_hz=5.0).source == "sidecar"


def test_validate_and_allan_report_the_same_rate_on_a_real_ulog(capsys):
    # a real PX4 log whose sensor_combined loses one sample in three: the mean arrival
    # rate is 187 Hz, the sensor's grid 250 Hz; every command takes the grid's rate
    pytest.importorskip("pyulog")
    f = PX4 / "px4_tagged_6s.ulg"
    code, out, err = run_inprocess(capsys, "validate", f, "--kind", "gyro_log", "--json")
    assert code in (0, None), err
    v = json.loads(out)
    code, out, err = run_inprocess(capsys, "allan", f, "--json")
    assert code in (0, None), err
    a = json.loads(out)
    assert v["timebase"]["rate_hz"] == pytest.approx(250.0, rel=1e-6)
    assert 1.0 / a["tau0_s"] == pytest.approx(v["timebase"]["rate_hz"], rel=1e-12)
    assert a["settings"]["rate_hz"] == v["timebase"]["rate_hz"]
    assert v["timestamps"]["mean_rate_hz"] < 190  # the kept samples' mean, not the rate


def test_imu_and_batch_report_the_validate_rate(tmp_path, capsys):
    pytest.importorskip("pyulog")
    import shutil

    f = tmp_path / "log.ulg"
    shutil.copy(PX4 / "px4_events_4s.ulg", f)
    runs = {}
    for name, args in (("validate", ("validate", f, "--kind", "imu", "--json")),
                       ("imu", ("allan", f, "--imu", "--json")),
                       ("batch", ("batch", "allan", "--inputs", tmp_path / "*.ulg",
                                  "--scheduler", "serial", "--json"))):
        code, out, err = run_inprocess(capsys, *args)
        assert code in (0, None), err
        runs[name] = json.loads(out)
    rate = runs["validate"]["timebase"]["rate_hz"]
    assert rate == pytest.approx(250.0, rel=1e-9)
    assert runs["imu"]["settings"]["rate_hz"] == rate
    assert runs["batch"]["units"][0]["figures"]["rate_hz"] == rate
