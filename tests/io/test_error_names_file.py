"""Every error a command prints for a bad input names the file, once, at the root: the
reading front door names the file in any message leaving it, and the command line names
the records the front door opened in front of a data error raised after reading."""

from __future__ import annotations

import shutil

import pytest
from tests.fuzz import catalogue as cat

from inertialab.errors import InputError
from inertialab.io import front_door, read_record


def test_naming_prefixes_once_and_keeps_the_class():
    from inertialab.errors import ImplausibleCalibrationError

    exc = ImplausibleCalibrationError("bias beyond range", column="gx", row=3)
    assert exc.naming("a.csv") is exc and exc.path == "a.csv"
    assert str(exc) == "a.csv: column 'gx', row 3: bias beyond range"
    exc.naming("b.csv")  # names a file already: unchanged
    assert str(exc) == "a.csv: column 'gx', row 3: bias beyond range"


def test_the_front_door_names_the_file_of_a_pathless_error(tmp_path):
    f = tmp_path / "log.csv"
    shutil.copy(cat.EXAMPLES / "gyro_log.csv", f)
    with pytest.raises(InputError) as exc:
        read_record(f, "gyro_log", unit="furlongs")  # raised below the reader, no path
    assert str(exc.value).startswith(f"{f}: ") and "furlongs" in str(exc.value)
    assert exc.value.path == str(f)


def test_the_front_door_notes_what_it_opened(tmp_path):
    f = tmp_path / "log.csv"
    shutil.copy(cat.EXAMPLES / "gyro_log.csv", f)
    mark = front_door.mark()
    read_record(f, "gyro_log")
    read_record(f, "gyro_log")
    assert front_door.since(mark) == [str(f)]


def test_a_data_error_after_reading_names_the_record():
    from inertialab.cli.main import full_command, user_error

    full_command()  # the commands register their settings' flags (as a run does first)

    assert user_error(InputError("need at least 3 values"), ["model.json", "rec.csv"],
                      ["rec.csv"]) == "rec.csv: need at least 3 values"
    # an argument error names the option, not a file
    assert user_error(InputError("argument 'order' must be >= 1"), ["rec.csv"],
                      ["rec.csv"]) == "--order must be >= 1"
    # an error naming a file already keeps it
    assert user_error(InputError("no such model file", path="m.json"), ["rec.csv"],
                      ["rec.csv"]) == "m.json: no such model file"


def test_cli_short_record_error_names_the_record(tmp_path):
    """vibration apply on a record too short for the wavelet: the workflow's message
    carries no path; the line names the record (not the model) in front."""
    rec = tmp_path / "short.csv"
    rec.write_text("t_s,rate_dph\n" + "".join(f"{i / 100:.2f},{0.1 * i:.2f}\n"
                                               for i in range(8)))
    model = shutil.copy(cat.MODELS / "vibration-compensation-v1.json", tmp_path / "m.json")
    o = cat.run_inprocess(["vibration", "apply", str(model), str(rec),
                           "--out", str(tmp_path / "o.csv")], tmp_path)
    assert o.code == 2, o.stderr
    line = [ln for ln in o.stderr.splitlines() if ln.startswith("error:")]
    assert len(line) == 1 and line[0].startswith(f"error: {rec}: "), o.stderr


def test_the_fuzz_invariant_flags_a_line_without_a_file(tmp_path):
    f = tmp_path / "in.csv"
    f.write_text("x\n")
    argv = ["validate", str(f), "--kind", "gyro_log"]
    before = cat.snapshot(tmp_path)
    bad = cat.Outcome(2, "", "error: too few samples\n")
    good = cat.Outcome(2, "", f"error: {f}: too few samples\n")
    arg = cat.Outcome(2, "", "error: --rate must be > 0\n")
    assert cat.names_its_file(bad, argv, tmp_path, before)
    assert not cat.names_its_file(good, argv, tmp_path, before)
    assert not cat.names_its_file(arg, argv, tmp_path, before)
    # no input file on the command line: not judged
    assert not cat.names_its_file(bad, ["simulate", "gyro-static"], tmp_path, before)
