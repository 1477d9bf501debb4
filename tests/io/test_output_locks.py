"""Outputs of a run are locked before any work: a second run to the same --out or
--export is refused at once (exit 2) while the first holds the lock; a lock file left by
a killed run never blocks; two outputs of one run may not overlap."""

import fcntl
import os
from pathlib import Path

from tests.helpers import run_inprocess

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"


def _simulate(capsys, out):
    return run_inprocess(capsys, "simulate", "gyro-static", "--preset", "allan-test",
                         "--hours", "0.01", "--rate", "100", "--out", out, "--quiet")


def test_a_held_lock_refuses_the_second_run_before_any_work(capsys, tmp_path):
    out = tmp_path / "s.csv"
    lock = tmp_path / ".s.csv.inertialab-lock"
    fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o600)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # "the first run"
        code, _out, err = _simulate(capsys, out)
    finally:
        os.close(fd)
    assert code == 2 and "being written by another inertialab run" in err
    assert not out.exists() and err.count("error:") == 1


def test_a_stale_lock_and_temporaries_of_a_killed_run_do_not_block(capsys, tmp_path):
    out = tmp_path / "s.csv"
    (tmp_path / ".s.csv.inertialab-lock").write_text("")  # no process holds it
    (tmp_path / ".s.csv.abcd1234.tmp").write_text("partial")
    code, _out, err = _simulate(capsys, out)
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.csv", "s.meta.json"]


def test_export_and_out_may_not_overlap(capsys, tmp_path):
    f = tmp_path / "vectornav.csv"
    f.write_bytes((EXAMPLES / "vendors" / "vectornav.csv").read_bytes())
    m = tmp_path / "vectornav.map.json"
    m.write_bytes((EXAMPLES / "vendors" / "vectornav.map.json").read_bytes())
    before = sorted(p.name for p in tmp_path.iterdir())
    for export, out, needle in ((tmp_path / "X", tmp_path / "X", "name the same output"),
                                (tmp_path / "D" / "k.yaml", tmp_path / "D", "lies inside --out")):
        code, _o, err = run_inprocess(capsys, "allan", f, "--imu", "--map-file", m,
                                      "--export", "kalibr", export, "--out", out)
        assert code == 2 and needle in err, err
        assert sorted(p.name for p in tmp_path.iterdir()) == before
