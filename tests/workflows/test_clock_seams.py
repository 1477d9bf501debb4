"""Clock users' seams: a one-series text file (Stable32's .DAT) is read without
--column, and --noise-type fixes the noise type of the bias corrections and EDF as
Stable32 does (the same numbers as the API given that alpha), recorded in the JSON."""

import json

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.statistics.family import compute
from inertialab.workflows.allan import parse_noise_type
from tests.helpers import run_inprocess


@pytest.fixture
def phase_dat(tmp_path):
    x = np.cumsum(np.random.default_rng(1).normal(size=1500)) * 1e-9
    f = tmp_path / "clock.dat"
    np.savetxt(f, x, fmt="%.12e")
    return f, x


def _json(capsys, *args):
    code, out, err = run_inprocess(capsys, "allan", *args, "--json")
    assert code == 0, err
    d = json.loads(out)  # one statistic: its fields at the top; several: "results"
    d["results"] = d.get("results", [d])
    d["result"] = d["results"][0]
    return d


def test_one_series_file_needs_no_column(capsys, phase_dat):
    f, _ = phase_dat
    a = _json(capsys, f, "--input", "phase", "--rate", "1", "--unit", "s")
    b = _json(capsys, f, "--input", "phase", "--rate", "1", "--unit", "s", "--column", "col1")
    assert a["result"]["dev"] == b["result"]["dev"] and len(a["result"]["dev"]) >= 5


def test_one_series_rate_file_is_the_rate(capsys, tmp_path):
    y = np.random.default_rng(2).normal(size=2000)
    f = tmp_path / "gyro.dat"
    np.savetxt(f, y, fmt="%.8f")
    r = _json(capsys, f, "--rate", "100", "--unit", "dps", "--no-terms")["result"]
    ref = compute("oadev", np.loadtxt(f), rate_hz=100.0)
    np.testing.assert_allclose(r["dev"], ref.dev, rtol=1e-12)


def test_noise_type_per_statistic_matches_the_api(capsys, phase_dat):
    f, x = phase_dat
    d = _json(capsys, f, "--input", "phase", "--rate", "1", "--unit", "s", "--stat",
              "oadev,totdev", "--noise-type", "totdev=FFM")
    assert d["settings"]["noise_type"] == {"totdev": -1}
    tot = next(r for r in d["results"] if r["statistic"] == "totdev")
    oad = next(r for r in d["results"] if r["statistic"] == "oadev")
    assert set(tot["alpha"]) == {-1} and set(tot["alpha_source"]) == {"user"}
    assert "user" not in oad["alpha_source"]  # identified as before
    ref = compute("totdev", np.loadtxt(f), rate_hz=1.0, input="angle", alpha=-1,
                  bias_correction=True)
    np.testing.assert_allclose(tot["dev"], ref.dev, rtol=1e-9)
    np.testing.assert_allclose(tot["edf"], ref.edf, rtol=1e-9)


@pytest.mark.parametrize("text, expect", [("-1", -1), ("FFM", -1), ("white fm", 0),
                                          ("oadev=2,totdev=rwfm", {"oadev": 2, "totdev": -2})])
def test_noise_type_forms(text, expect):
    assert parse_noise_type(text, ("oadev", "totdev")) == expect


@pytest.mark.parametrize("text, needle", [("3", "alpha of"), ("mdev=0", "asked for"),
                                          ("0,1", "one type"), ("oadev=0,oadev=1", "twice"),
                                          ("oadev=0,,", "empty entry")])
def test_bad_noise_types_name_the_argument(text, needle):
    with pytest.raises(InputError, match=needle):
        parse_noise_type(text, ("oadev", "totdev"))


def test_one_named_column_of_unknown_name_is_the_series(capsys, tmp_path):
    y = np.random.default_rng(4).normal(size=2000)
    f = tmp_path / "gyro.csv"
    f.write_text("value\n" + "".join(f"{v:.8f}\n" for v in y))
    r = _json(capsys, f, "--rate", "100", "--unit", "dps", "--no-terms")["result"]
    ref = compute("oadev", np.loadtxt(f, skiprows=1), rate_hz=100.0)
    np.testing.assert_allclose(r["dev"], ref.dev, rtol=1e-12)
