"""``allan --imu`` through the one runner: the six-axis result is a Result, its JSON
envelope keeps its keys (pinned here), and a ``--check-on LOG`` is read by the runner
and checked by the workflow (``--out DIR/result.json`` is the printed envelope:
tests/cli/test_imu_noise.py)."""

import json

import numpy as np
import pandas as pd
import pytest

from inertialab.result import Result, check_result
from tests.helpers import run_cli

#: The envelope of ``allan --imu FILE --json``, in order (``meta`` holds the runner's
#: timestamps; ``non_estimable`` is there when a number is not estimable, as here: the
#: short log leaves K unresolved).
ENVELOPE = ["command", "schema_version", "inertialab_version", "dependencies", "inputs",
            "settings", "units", "warnings", "meta", "imu", "sha256_canonical"]
SETTINGS = {"confidence", "export", "export_file", "exports", "fitted_on", "force",
            "g_local_mps2", "gaps", "map", "method", "parse", "rate_hz", "tau_range_s", "taus",
            "terms", "warmup"}
IMU = ["rate_hz", "n_samples", "fitted_on", "axes", "kalibr"]


def _six_axis_log(path, n=2000, seed=3):
    """A static six-axis log: white rate noise 1e-3 rad/s and 2e-3 m/s^2 per sample at
    100 Hz, gravity on z."""
    rng = np.random.default_rng(seed)
    cols = {"t_s": np.arange(n) / 100.0}
    for ax in ("gx_rps", "gy_rps", "gz_rps"):
        cols[ax] = 1e-3 * rng.standard_normal(n)
    for ax in ("ax_mps2", "ay_mps2", "az_mps2"):
        cols[ax] = 2e-3 * rng.standard_normal(n) + (9.80665 if ax == "az_mps2" else 0.0)
    pd.DataFrame(cols).to_csv(path, index=False)
    return path


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    return _six_axis_log(tmp_path_factory.mktemp("imu") / "imu.csv")


@pytest.fixture
def seen(monkeypatch):
    """The results that reached the runner's check (command -> result)."""
    from inertialab.cli import runner

    got = {}

    def recording(result, command):
        got[command] = result
        return check_result(result, command)

    monkeypatch.setattr(runner, "check_result", recording)
    return got


@pytest.mark.filterwarnings("ignore")
def test_the_envelope_keys_are_pinned(log, tmp_path, seen):
    k = tmp_path / "imu.yaml"
    res = run_cli("allan", "--imu", log, "--export", "kalibr", k, "--json")
    assert res.returncode == 0, res.stderr
    env = json.loads(res.stdout)
    assert [key for key in env if key != "non_estimable"] == ENVELOPE
    assert set(env["settings"]) == SETTINGS and list(env["imu"]) == IMU
    assert env["command"] == "allan" and env["units"] == {"rate_hz": "Hz"}
    assert env["inputs"] == [{"path": str(log), "sha256": env["inputs"][0]["sha256"]}]
    assert env["settings"]["exports"] == [{"target": "kalibr", "file": str(k)}]
    assert env["settings"]["export_file"] == str(k) and k.is_file()
    assert len(env["sha256_canonical"]) == 64
    assert set(env["meta"]["timestamps"]) == {"started_utc", "finished_utc", "wall_s"}
    result = seen["allan"]
    assert isinstance(result, Result) and type(result).__name__ == "SixAxisRun"
    assert result.to_json()["imu"]["n_samples"] == 2000 and result.artifacts() == {}
    rows = result.summary_rows()
    assert rows[0][1][:3] == ["axis", "column", "status"] and isinstance(rows[-1], str)


@pytest.mark.filterwarnings("ignore")
def test_a_check_log_is_read_by_the_runner_and_checks_the_prediction(log, tmp_path, seen):
    other = _six_axis_log(tmp_path / "other.csv", seed=4)
    res = run_cli("allan", "--imu", log, "--predict-drift", "1,5", "--check-on", other,
                  "--json")
    assert res.returncode == 0, res.stderr
    env = json.loads(res.stdout)
    drift = env["settings"]["drift"]
    assert drift["check_on"] == str(other)
    gx = env["imu"]["axes"][0]["drift_prediction"]
    assert gx["check"]["n_windows"][0] > 0
    # one fitted log cannot say how another run or unit differs: the check says so
    assert gx["check"]["between_logs"].startswith("not measured: one log was fitted")
    # the check log read by the runner is the one the workflow checks against: the same
    # observed RMS as the workflow given that record directly
    from inertialab.io import read_record
    from inertialab.workflows import imu_noise as wn
    from inertialab.workflows.allan import AllanConfig

    cfg = AllanConfig(predict_drift="1,5", check_on=str(other))
    direct = wn.run(read_record(log, "gyro_log"), cfg, check=read_record(other, "gyro_log"))
    want = direct.to_json()["imu"]["axes"][0]["drift_prediction"]["check"]["observed_rms"]
    assert gx["check"]["observed_rms"] == pytest.approx(want, rel=1e-12)


def test_settings_refused_before_the_log_is_read(tmp_path):
    missing = tmp_path / "none.csv"
    res = run_cli("allan", "--imu", missing, "--check-on", "half")
    assert res.returncode == 2 and "--check-on needs --predict-drift" in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1
