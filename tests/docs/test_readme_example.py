"""The README's Python example runs as printed, and on a log with a dropout it refuses to
splice the data across the gap (the record-aware ``rec.series``)."""

import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError

README = Path(__file__).resolve().parents[2] / "README.md"


def _example() -> str:
    block = re.search(r"## The Python API\s+```python\n(.*?)```", README.read_text(), re.S)
    return block.group(1)


def _log(path: Path, lost=()):
    rng = np.random.default_rng(5)
    t = np.arange(4000) / 100.0
    keep = np.ones(t.size, bool)
    keep[list(lost)] = False
    pd.DataFrame({"t_s": t[keep], "rate_dph": rng.standard_normal(keep.sum())}).to_csv(
        path, index=False)


def test_the_example_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _log(tmp_path / "g.csv")
    ns = {}
    exec(_example(), ns)
    assert (tmp_path / "terms.json").exists()
    assert ns["res"].taus_s.size > 5 and np.all(np.isfinite(ns["rate"]))


def test_the_example_refuses_to_splice_a_dropout(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _log(tmp_path / "g.csv", lost=range(1000, 1050))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InputError, match="NaN"):
            exec(_example(), {})
        from inertialab.io import read_record
        from inertialab.noise import gap_deviation

        rec = read_record("g.csv", "gyro_log")
    rate = rec.series("rate_dph")
    assert rate.size == 4000 and np.isnan(rate).sum() == 50  # the lost samples, not spliced
    assert gap_deviation("oadev", rate, rate_hz=rec.timebase.rate_hz).taus_s.size > 5
