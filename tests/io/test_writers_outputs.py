"""Output safety: non-regular targets refused, transactional
directory outputs (replaced whole, merged into foreign directories, locked), rollback
leaves the filesystem as it was, names from data never leave the output directory."""

import os
import stat

import numpy as np
import pandas as pd
import pytest

from inertialab import InputError
from inertialab.io import outputs
from inertialab.io.outputs import (
    MARKER,
    OutputError,
    ensure_finite,
    file_target,
    output_dir,
    stage_dir,
    transaction,
)
from inertialab.io.writers import atomic_write_text, write_record


def _tree(root):
    """Every path under root with its kind and bytes (the filesystem 'as it was')."""
    out = {}
    for dirpath, dirs, files in os.walk(root):
        for d in dirs:
            out[os.path.relpath(os.path.join(dirpath, d), root)] = "dir"
        for f in files:
            p = os.path.join(dirpath, f)
            st = os.lstat(p)
            out[os.path.relpath(p, root)] = (open(p, "rb").read()
                                             if stat.S_ISREG(st.st_mode) else st.st_mode)
    return out


def test_file_target_refuses_non_regular(tmp_path):
    os.mkfifo(tmp_path / "fifo")
    (tmp_path / "d").mkdir()
    os.symlink("/dev/null", tmp_path / "null")
    os.symlink(tmp_path / "nothing", tmp_path / "dangling")
    for name, kind in [("fifo", "a FIFO"), ("d", "a directory"), ("null", "a device"),
                       ("dangling", "link to nothing")]:
        with pytest.raises(OutputError, match=kind):
            file_target(tmp_path / name)
    with pytest.raises(OutputError, match="a device"):
        atomic_write_text("/dev/null", "x")
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert stat.S_ISFIFO(os.lstat(tmp_path / "fifo").st_mode)
    (tmp_path / "f").write_text("x")
    with pytest.raises(OutputError, match="(?i)not a directory"):
        file_target(tmp_path / "f" / "below.csv")


def test_link_to_regular_file_replaces_the_file(tmp_path):
    (tmp_path / "real.txt").write_text("old")
    os.symlink(tmp_path / "real.txt", tmp_path / "link.txt")
    atomic_write_text(tmp_path / "link.txt", "new")
    assert os.path.islink(tmp_path / "link.txt")
    assert (tmp_path / "real.txt").read_text() == "new"


def test_transaction_commits_together_and_rolls_back_to_nothing(tmp_path):
    before = _tree(tmp_path)
    df = pd.DataFrame({"a": [1.0, 2.0]})
    with pytest.raises(RuntimeError), transaction():
        write_record(df, tmp_path / "new" / "deep" / "r.csv", {"k": 1})
        atomic_write_text(tmp_path / "x.txt", "x")
        assert not (tmp_path / "x.txt").exists()  # not before the commit
        raise RuntimeError("boom")
    assert _tree(tmp_path) == before  # parents created for the output removed too
    with transaction():
        write_record(df, tmp_path / "r.csv", {"k": 1})
        assert not (tmp_path / "r.csv").exists()
    assert (tmp_path / "r.csv").exists() and (tmp_path / "r.meta.json").exists()
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]


def test_directory_output_is_built_aside_and_replaced_whole(tmp_path):
    out = tmp_path / "o"
    with transaction():
        d = stage_dir(out)
        assert not out.exists()  # nothing created before the first write
        atomic_write_text(d / "models" / "stale.json", "{}")
        (d / "sub").mkdir(exist_ok=True)  # command code that mkdirs keeps working
        assert not out.exists()
        assert str(d) == str(out)
    assert (out / MARKER).exists() and (out / "models" / "stale.json").exists()
    assert (out / "sub").is_dir()
    with transaction():
        atomic_write_text(stage_dir(out) / "model.json", "{}")
    assert sorted(os.listdir(out)) == [MARKER, "model.json"]  # stale models/ gone
    assert sorted(os.listdir(tmp_path)) == ["o"]  # no staging, no lock left


def test_foreign_directory_is_merged_never_deleted(tmp_path):
    out = tmp_path / "firmware"
    out.mkdir()
    (out / "main.c").write_text("int main;")
    (out / "x.h").mkdir()  # a directory where an output file would go
    with transaction():
        atomic_write_text(stage_dir(out) / "comp.h", "h")
    assert (out / "main.c").read_text() == "int main;" and (out / "comp.h").read_text() == "h"
    assert not (out / MARKER).exists()
    before = _tree(tmp_path)
    with pytest.raises(OutputError, match="a directory"), transaction():
        atomic_write_text(stage_dir(out) / "x.h", "h")
    assert _tree(tmp_path) == before


def test_directory_holding_an_input_is_not_replaced(tmp_path):
    out = tmp_path / "o"
    with transaction():
        atomic_write_text(stage_dir(out) / "a.json", "{}")
    (out / "input.csv").write_text("t_s\n0\n")
    with transaction(protect=[out / "input.csv"]):
        atomic_write_text(stage_dir(out) / "b.json", "{}")
    assert (out / "input.csv").exists() and (out / "b.json").exists()


def test_failed_directory_output_leaves_nothing(tmp_path):
    before = _tree(tmp_path)
    with pytest.raises(ValueError), transaction():
        d = stage_dir(tmp_path / "a" / "b" / "o")
        atomic_write_text(d / "model.json", "{}")
        raise ValueError("bad input found late")
    assert _tree(tmp_path) == before
    with pytest.raises(OutputError, match="this output is a directory"), transaction():
        (tmp_path / "file").write_text("keep")
        stage_dir(tmp_path / "file")
    assert (tmp_path / "file").read_text() == "keep"


def test_concurrent_writer_is_locked_out(tmp_path):
    out = tmp_path / "o"
    with transaction():
        d = stage_dir(out)
        atomic_write_text(d / "a.json", "{}")  # holds the lock from here
        other = outputs._DirOutput(out, ())
        with pytest.raises(OutputError, match="another inertialab run"):
            other.materialize()
    other = outputs._DirOutput(out, ())  # released after the commit
    other.materialize()
    other.rollback()
    assert sorted(os.listdir(tmp_path)) == ["o"]


def test_stale_staging_of_a_killed_run_is_removed(tmp_path):
    stale = tmp_path / f".o{outputs._TMP_TAG}999-dead"
    stale.mkdir()
    (stale / "half.png").write_bytes(b"x" * 100)
    with transaction():
        atomic_write_text(stage_dir(tmp_path / "o") / "a.json", "{}")
    assert sorted(os.listdir(tmp_path)) == ["o"]


def test_names_leaving_the_output_directory_are_refused(tmp_path):
    out = tmp_path / "o"
    with pytest.raises(OutputError, match="outside the output directory"), transaction():
        d = stage_dir(out)
        atomic_write_text(d / "x" / ".." / ".." / "ESCAPED.png", "x")
    assert sorted(os.listdir(tmp_path)) == []


def test_write_figures_slugs_names_from_data(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from inertialab.cli.common import write_figures

    out = tmp_path / "o"
    with transaction():
        d = stage_dir(out)
        paths = write_figures([("x/../../../ESCAPED", plt.figure()),
                               ("U" * 300, plt.figure()), ("ok_name", plt.figure())], d)
    names = sorted(os.listdir(out))
    assert "ok_name.png" in names and len(names) == 4  # three figures + marker
    assert all(len(n) < 100 and "/" not in n for n in names)
    assert sorted(os.listdir(tmp_path)) == ["o"] and len(paths) == 3


def test_output_dir_context(tmp_path):
    with output_dir(tmp_path / "o") as tmp:
        assert tmp.name.startswith(".o.inertialab-tmp-")
        (tmp / "a.txt").write_text("a")
    assert (tmp_path / "o" / "a.txt").read_text() == "a"
    with pytest.raises(KeyError), output_dir(tmp_path / "o") as tmp:
        (tmp / "b.txt").write_text("b")
        raise KeyError("x")
    assert sorted(os.listdir(tmp_path / "o")) == [MARKER, "a.txt"]


def test_write_error_is_one_line_naming_the_path(tmp_path, monkeypatch):
    import errno

    def full(self, *a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(pd.DataFrame, "to_csv", full)
    before = _tree(tmp_path)
    with pytest.raises(OutputError, match=r"r\.csv: cannot write output \(No space left"):
        write_record(pd.DataFrame({"a": [1.0]}), tmp_path / "r.csv")
    assert _tree(tmp_path) == before


def test_ensure_finite_names_column_and_row():
    ensure_finite(np.arange(3.0), "x")
    with pytest.raises(InputError, match=r"column 'b', row 2: compensated output is not"):
        ensure_finite(pd.DataFrame({"a": [1.0, 2.0], "b": [0.0, np.nan]}),
                      "compensated output")
    ensure_finite(pd.DataFrame({"b": [np.nan]}), "x", allow_nan_in={"b"})
    with pytest.raises(InputError, match=r"2 values\) \(first at index 1\)"):
        ensure_finite(np.array([1.0, np.inf, np.nan]), "forecast")
