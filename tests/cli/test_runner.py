"""The one runner: --json and --out DIR/result.json carry the same envelope (command,
inputs with hashes, settings, units, warnings, meta.timestamps); settings declared on a
workflow Config reject out-of-bounds values with one line naming the flag."""

from __future__ import annotations

import hashlib
import json

import pandas as pd
import pytest

from inertialab.cli.main import main
from inertialab.result import ResultBase
from tests.helpers import run_inprocess as run


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    d = tmp_path_factory.mktemp("runner")
    with pytest.raises(SystemExit) as ex:
        main(["simulate", "storage-drift", "--preset", "nav", "--units", "1", "--days", "60",
              "--seed", "2", "--out", str(d / "rec.csv")])
    assert ex.value.code == 0
    return d / "rec.csv"


@pytest.mark.filterwarnings("ignore")
def test_json_and_result_json_are_one_envelope(record, capsys, tmp_path):
    code, out, err = run(capsys, "drift", "fit", record, "--quantity", "bias", "--order", "1",
                         "--restarts", "1", "--horizon", "5", "--json", "--out", tmp_path / "o")
    assert code == 0, err
    printed = json.loads(out)
    written = json.loads((tmp_path / "o" / "result.json").read_text())
    assert printed == written
    assert printed["command"] == "drift fit"
    assert printed["inputs"] == [{"path": str(record), "sha256":
                                  hashlib.sha256(record.read_bytes()).hexdigest()}]
    ts = printed["meta"]["timestamps"]
    assert ts["started_utc"] <= ts["finished_utc"] and ts["wall_s"] > 0
    assert isinstance(printed["warnings"], list)
    assert printed["settings"]["horizon"] == 5 and printed["settings"]["seed"] == 0
    assert (tmp_path / "o" / "model.json").is_file()


@pytest.mark.parametrize("flag, value", [("--horizon", "nan"), ("--horizon", "1e9"),
                                         ("--tol-bias-ug", "-1"), ("--tol-sf-ppm", "inf"),
                                         ("--restarts", "0"), ("--hidden", "1000000000"),
                                         ("--max-gap", "-3"), ("--preset", "fast")])
def test_out_of_bounds_settings_are_one_line_naming_the_flag(record, capsys, tmp_path,
                                                             flag, value):
    code, out, err = run(capsys, "drift", "fit", record, flag, value, "--out", tmp_path / "x")
    assert code == 2 and err.count("\n") == 1 and flag in err, err
    assert not (tmp_path / "x").exists() and out == ""


class _OneRecord(ResultBase):
    """A result of a one-record command: a frame and a side file to write."""

    settings, units, warnings = {"k": 1}, {}, ()

    def __init__(self, out):
        self.out = out
        self.frame = pd.DataFrame({"t_s": [0.0, 0.1, 0.2], "x": [1.5, -2.25, 3.125]})

    def to_json(self):
        return {"rows": len(self.frame)}

    def artifacts(self):
        return {"records": [(self.out, self.frame, {"source": "test"})],
                "files": {self.out.with_name("note.txt"): "beside\n"}}

    def summary_rows(self):
        return [f"written: {self.out}"]


def test_one_record_mode_writes_the_records_and_refuses_a_directory(tmp_path, capsys):
    from inertialab.cli.runner import Run
    from inertialab.errors import InputError

    out = tmp_path / "r.csv"
    env = Run(out=out, as_json=True, out_kind="file").execute("t", lambda bar: _OneRecord(out))
    printed = json.loads(capsys.readouterr().out)
    assert printed == env and env["rows"] == 3 and env["settings"] == {"k": 1}
    pd.testing.assert_frame_equal(pd.read_csv(out), _OneRecord(out).frame)
    assert json.loads((tmp_path / "r.meta.json").read_text())["source"] == "test"
    assert (tmp_path / "note.txt").read_text() == "beside\n"
    with pytest.raises(InputError, match="--out must be a file"):
        Run(out=tmp_path, out_kind="file").execute("t", lambda bar: _OneRecord(tmp_path))
