"""CLI: inertialab allan and simulate gyro-static."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from inertialab.cli.main import main
from inertialab.noise.statistics.allan import oadev
from tests.helpers import run_inprocess as run

ISSUE_KEYS = {"statistic", "tau0_s", "taus_s", "dev", "ci_low", "ci_high", "n_terms", "alpha",
              "alpha_source", "edf", "unit", "noise_terms"}
ENVELOPE = {"command", "schema_version", "inertialab_version", "inputs", "settings", "units",
            "warnings", "meta"}




@pytest.fixture(scope="module")
def rec(tmp_path_factory):
    d = tmp_path_factory.mktemp("allan")
    with pytest.raises(SystemExit) as ex:
        main(["simulate", "gyro-static", "--preset", "allan-test", "--hours", "1", "--rate",
              "10", "--seed", "2", "--out", str(d / "g.csv")])
    assert ex.value.code == 0
    return d / "g.csv"


def test_simulate_sidecar(rec):
    side = json.loads(rec.with_name("g.meta.json").read_text())
    assert side["seed"] == 2 and side["preset"] == "allan-test" and side["fs_hz"] == 10.0
    assert side["truth_terms"]["B"]["value"] == 0.1


def test_json_single_stat(rec, capsys):
    code, out, err = run(capsys, "allan", rec, "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert ENVELOPE <= set(obj)
    assert set(obj) - ENVELOPE - {"dependencies", "non_estimable"} == ISSUE_KEYS
    assert obj["command"] == "allan" and obj["statistic"] == "oadev" and obj["unit"] == "dph"
    # numbers equal the library on the same column (the CSV round trip is exact)
    y = pd.read_csv(rec)["rate_dph"].to_numpy()
    np.testing.assert_allclose(obj["dev"], oadev(y, rate_hz=10.0).dev, rtol=1e-12)
    nt = obj["noise_terms"]
    assert set(nt) == set("QNBKR")
    assert nt["N"]["unit"] == "deg/sqrt(h)" and len(nt["N"]["ci"]) == 2
    assert nt["N"]["value"] == pytest.approx(0.01, rel=0.05)  # 1 h, edf > 1000 at N's taus
    assert nt["Q"]["value"] == pytest.approx(0.5, rel=0.05)


@pytest.mark.slow  # every statistic with figures: about 12 s
def test_json_several_stats_and_out(rec, capsys, tmp_path):
    code, out, err = run(capsys, "allan", rec, "--stat", "oadev,mdev,totdev", "--taus",
                         "decade", "--confidence", "0.95", "--json", "--out", tmp_path / "o")
    assert code == 0, err
    obj = json.loads(out)
    assert [r["statistic"] for r in obj["results"]] == ["oadev", "mdev", "totdev"]
    for r in obj["results"]:
        assert set(r) == ISSUE_KEYS
        assert r["taus_s"][:3] == [0.1, 0.2, 0.4]
    assert (tmp_path / "o" / "allan.png").stat().st_size > 1000
    res = json.loads((tmp_path / "o" / "result.json").read_text())
    assert [r["statistic"] for r in res["results"]] == ["oadev", "mdev", "totdev"]
    model = json.loads((tmp_path / "o" / "model.json").read_text())
    assert model["type"] == "noise-terms"


def test_table_output(rec, capsys):
    code, out, err = run(capsys, "allan", rec, "--method", "slope")
    assert code == 0, err
    assert "OADEV" in out and "Noise terms" in out and "deg/sqrt(h)" in out


def test_npy_needs_rate_and_unit(tmp_path, capsys):
    y = np.random.default_rng(0).normal(0, 1, 5000)
    p = tmp_path / "r.npy"
    np.save(p, y)
    code, out, err = run(capsys, "allan", p, "--rate", "100", "--unit", "dps", "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert obj["unit"] == "dps" and obj["tau0_s"] == 0.01
    np.testing.assert_allclose(obj["dev"], oadev(y, rate_hz=100.0).dev, rtol=1e-12)
    code, out, err = run(capsys, "allan", p)
    assert code == 2 and err.startswith("error:") and len(err.strip().splitlines()) == 1


def _bad(tmp_path, name, df):
    p = tmp_path / name
    df.to_csv(p, index=False)
    return p


@pytest.mark.parametrize("case, match", [
    ("few", "too few samples"),
    ("nan", "NaN"),
    ("constant", "constant"),
    ("repeat", "time stamps repeat"),
    ("unit", "unit"),
])
def test_bad_input_exit_2_one_line(tmp_path, capsys, case, match):
    n = 400
    t = np.arange(n) / 10.0
    y = np.random.default_rng(1).normal(0, 1, n)
    if case == "few":
        p = _bad(tmp_path, "few.csv", pd.DataFrame({"t_s": t[:3], "rate_dph": y[:3]}))
        args = ["--taus", "5.0,10"]  # seconds: m = 50 > the largest valid m = 1
    elif case == "nan":
        y[17] = np.nan
        p = _bad(tmp_path, "nan.csv", pd.DataFrame({"t_s": t, "rate_dph": y}))
        args = []
    elif case == "constant":
        p = _bad(tmp_path, "c.csv", pd.DataFrame({"t_s": t, "rate_dph": np.full(n, 3.0)}))
        args = []
    elif case == "repeat":
        t2 = t.copy()
        t2[100] = t2[99]
        p = _bad(tmp_path, "j.csv", pd.DataFrame({"t_s": t2, "rate_dph": y}))
        args = []
    else:
        p = _bad(tmp_path, "u.csv", pd.DataFrame({"t_s": t, "rate_furlong": y}))
        args = []
    code, out, err = run(capsys, "allan", p, *args)
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:") and match in lines[0], err
    assert "Traceback" not in err and out == ""


def test_jitter_names_rows(tmp_path, capsys):
    t = np.arange(300) / 10.0
    t[100:] += 0.01
    p = _bad(tmp_path, "j.csv", pd.DataFrame({"t_s": t, "rate_dph": np.random.default_rng(0)
                                               .normal(size=300)}))
    code, _, err = run(capsys, "allan", p)
    # a jittering stamp loses no sample: the analysis runs on the mean rate and the
    # warning names the row (the later stamp of the bad step, 1-based)
    assert code == 0 and "rows 101" in err and "jitter" in err


def test_bad_options(rec, capsys):
    for args in (["--stat", "xdev"], ["--method", "guess"], ["--input", "bogus"],
                 ["--confidence", "2"], ["--taus", "sometimes"]):
        code, out, err = run(capsys, "allan", rec, *args)
        assert code == 2 and len(err.strip().splitlines()) == 1, (args, err)


@pytest.mark.slow  # a clock record with every figure: about 18 s
def test_clock_phase_file_json_and_figure(tmp_path, capsys):
    # NBS14 phase in ns with an arbitrary column name, read with --column
    x = [0.0, 103.11111, 123.22222, 157.33333, 166.44444, 48.55555, -96.33333, -2.22222,
         111.88889, 0.0]
    p = tmp_path / "clk.csv"
    p.write_text("MJD;Time error\n" + "".join(f"{i};{v}\n" for i, v in enumerate(x)))
    code, out, err = run(capsys, "allan", p, "--input", "phase", "--column", "time error",
                         "--unit", "ns", "--rate", "1", "--sep", ";", "--stat",
                         "adev,mtotdev,tdev", "--taus", "1,2", "--json", "--out",
                         tmp_path / "o")
    assert code == 0, err
    d = json.loads(out)
    res = {r["statistic"]: r for r in d["results"]}
    assert res["adev"]["unit"] == "1" and res["tdev"]["unit"] == "s"
    assert res["adev"]["noise_terms"] is None
    assert res["adev"]["dev"][0] == pytest.approx(91.22945e-9, rel=1e-6)
    assert d["settings"]["bias_correction"] is True and d["settings"]["input"] == "phase"
    assert (tmp_path / "o" / "allan.png").stat().st_size > 1000
    code, out, err = run(capsys, "allan", p, "--input", "frequency", "--column", "time error",
                         "--unit", "hz", "--rate", "1", "--sep", ";")
    assert code == 2 and "nominal" in err


def test_clock_unit_without_clock_input_says_which_input(tmp_path, capsys):
    p = tmp_path / "f.csv"
    p.write_text("t_s,y\n" + "".join(f"{i},{(-1) ** i * 1e-3}\n" for i in range(50)))
    code, _, err = run(capsys, "allan", p, "--unit", "ppm")
    assert code == 2 and "--input frequency" in err
    code, _, err = run(capsys, "allan", p, "--input", "frequency", "--column", "y", "--unit",
                       "ppm", "--json")
    assert code == 0, err
