"""``simulate KIND``: each rig's command writes exactly what the rig produces with the
same settings (read back and compared with the rig called directly), carries the runner's
envelope, and refuses bad settings with one line naming the flag."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from inertialab.cli.simulate import RIGS
from tests.helpers import run_inprocess as run


def _numeric_equal(path, frame):
    """The record written at ``path`` holds ``frame``'s numbers exactly (CSV round trip)."""
    got = pd.read_csv(path)
    assert list(got.columns) == list(frame.columns)
    for c in frame.columns:
        if pd.api.types.is_numeric_dtype(frame[c]):
            np.testing.assert_array_equal(got[c].to_numpy(float), frame[c].to_numpy(float))


def test_every_rig_is_a_command(capsys):
    code, out, _ = run(capsys, "simulate", "--help")
    assert code == 0
    assert all(kind in out for kind in RIGS)


def test_storage_drift_writes_the_rigs_record(capsys, tmp_path):
    from inertialab.sim.drift import simulate_storage_batch

    out = tmp_path / "s.csv"
    code, text, err = run(capsys, "simulate", "storage-drift", "--units", "2", "--days", "40",
                          "--seed", "5", "--skip-weekends", "--out", out, "--json")
    assert code == 0, err
    env = json.loads(text)
    assert env["command"] == "simulate storage-drift" and env["inputs"] == []
    assert env["settings"] == {"preset": "paper", "units": 2, "days": 40, "seed": 5,
                               "outliers": True, "missing_prob": None, "skip_weekends": True}
    assert set(env["meta"]["timestamps"]) == {"started_utc", "finished_utc", "wall_s"}
    ref = simulate_storage_batch(2, 40, "paper", rng=5, skip_weekends=True)
    assert env["rows"] == len(ref.frame) and env["path"] == str(out)
    _numeric_equal(out, ref.frame)
    assert json.loads((tmp_path / "s.meta.json").read_text())["seed"] == 5


def test_thermal_tumble_seeds_reach_the_rig(capsys, tmp_path):
    from inertialab.sim.thermal_tumble import simulate

    out = tmp_path / "t.csv"
    code, text, err = run(capsys, "simulate", "thermal-tumble", "--lot-seed", "3", "--unit", "1",
                          "--seed", "77", "--out", out, "--json")
    assert code == 0, err
    env = json.loads(text)
    ref = simulate("paper", 3, 1, seed=77)
    assert env["settings"]["seed"] == 77 and env["unit_id"] == ref.unit.unit_id
    assert env["noise_floor_ug"] == pytest.approx(ref.noise_floor_ug, rel=0, abs=0)
    _numeric_equal(out, ref.frame)


def test_dual_tumble_two_orientations_and_a_fog_truth_table(capsys, tmp_path):
    out = tmp_path / "d.csv"
    code, text, err = run(capsys, "simulate", "dual-tumble", "--scenario", "S5", "--seed", "4",
                          "--out", out, "--json")
    assert code == 0, err
    env = json.loads(text)
    second = tmp_path / "d_orient2.csv"
    assert env["written"] == [str(out), str(second)] and second.is_file()
    assert env["settings"]["scenario"] == "S5" and env["settings"]["seed"] == 4
    assert json.loads((tmp_path / "d.meta.json").read_text())["truth"] == env["truth"]
    fog, truth = tmp_path / "v.csv", tmp_path / "truth.csv"
    code, text, err = run(capsys, "simulate", "fog-vibration", "--p1-s", "20", "--p2-s", "20",
                          "--p3-s", "20", "--truth", truth, "--out", fog)
    assert code == 0, err
    assert text.startswith(f"wrote {fog} (") and truth.stat().st_size > 0


@pytest.mark.parametrize("args, flag", [
    (["thermal-tumble", "--unit", "-1"], "--unit"),
    (["fog-vibration", "--experiment", "up"], "--experiment"),
    (["storage-drift", "--missing-prob", "1"], "--missing-prob"),
    (["triaxial-poses", "--scenario", "cube"], "unknown scenario 'cube'"),
])
def test_bad_settings_are_one_line_and_write_nothing(capsys, tmp_path, args, flag):
    out = tmp_path / "x.csv"
    code, text, err = run(capsys, "simulate", *args, "--out", out)
    assert code == 2 and text == "" and err.count("\n") == 1 and flag in err, err
    assert not out.exists()


def test_out_must_be_a_file(capsys, tmp_path):
    code, _, err = run(capsys, "simulate", "ferraris-session", "--out", tmp_path)
    assert code == 2 and "--out must be a file for this command" in err
