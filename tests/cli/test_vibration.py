"""CLI: inertialab vibration fit|apply (and the bare ``vibration SWEEP`` spelling),
simulate fog-vibration."""

import json

import numpy as np
import pandas as pd
import pytest

from inertialab.cli.main import main
from tests.helpers import run_inprocess as run

SHORT = ["--p1-s", "150", "--p3-s", "150", "--p2-s", "150"]




@pytest.fixture(scope="module")
def records(tmp_path_factory):
    d = tmp_path_factory.mktemp("vib")
    for args in (["simulate", "fog-vibration", "--experiment", "sweep", "--seed", "2",
                  "--sweep-oct-per-min", "8", "--out", d / "sweep.csv", *SHORT],
                 ["simulate", "fog-vibration", "--experiment", "fixed", "--seed", "2",
                  "--out", d / "fixed.csv", "--truth", d / "truth.csv", *SHORT]):
        with pytest.raises(SystemExit) as ex:
            main([str(a) for a in args])
        assert ex.value.code == 0
    return d


def test_simulate_writes_record_and_sidecar(records):
    side = json.loads((records / "fixed.meta.json").read_text())
    assert side["experiment"] == "fixed" and side["seed"] == 2 and side["fs_hz"] == 200.0
    df = pd.read_csv(records / "fixed.csv")
    assert len(df) == 3 * 150 * 200
    assert list(df.columns) == ["t_s", "rate_dph", "vib_on", "vib_freq_hz", "vib_acc_g", "phase"]
    truth = pd.read_csv(records / "truth.csv")
    assert "true_bias_vib_dph" in truth.columns and len(truth) == len(df)


@pytest.fixture(scope="module")
def json_result(records):
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), pytest.raises(SystemExit) as ex:
        main([str(a) for a in ["vibration", records / "sweep.csv", records / "fixed.csv",
                               "--json", "--quiet"]])
    assert ex.value.code == 0
    return json.loads(buf.getvalue())


def test_vibration_json_has_the_issue_keys(json_result):
    d = json_result
    for k in ("command", "schema_version", "inputs", "settings", "units", "warnings"):
        assert k in d
    assert {"level", "delta_j", "tables", "residual_bias_dph", "fit"} <= set(d)
    assert d["level"] == 6
    assert set(d["tables"]) == {"phases", "decomposition", "compensation"}
    units = {"Q": "arcsec", "N": "deg/sqrt(h)", "B": "deg/h", "K": "deg/h/sqrt(h)",
             "R": "deg/h^2"}
    for table in d["tables"].values():
        for row in table.values():
            assert set(row) == set(units)
            for k, t in row.items():
                assert t["unit"] == units[k]
    assert set(d["residual_bias_dph"]) == {"rbf", "poly"}
    assert set(d["fit"]["rbf"]) >= {"neurons", "train_rmse", "heldout_rmse"}
    assert set(d["fit"]["poly"]) >= {"train_rmse", "heldout_rmse"}
    assert len(d["inputs"]) == 2 and all(len(i["sha256"]) == 64 for i in d["inputs"])


def test_vibration_json_numbers(json_result):
    # the simulated ARW is 0.01 deg/sqrt(h); P1 of 150 s recovers it within 10 %;
    # the residual bias after RBF compensation is well below b_v(500 Hz) = 9.18 deg/h
    d = json_result
    assert d["tables"]["phases"]["fixed/P1"]["N"]["value"] == pytest.approx(0.01, rel=0.1)
    assert abs(d["residual_bias_dph"]["rbf"]) < 2.5
    assert d["fit"]["rbf"]["train_rmse"] <= 1e-2 + 1e-12  # goal 1e-4 MSE


@pytest.mark.slow  # a fit with figures and a compensation: about 30 s
def test_out_dir_and_model_applies_to_a_new_record(records, tmp_path, capsys):
    out = tmp_path / "res"
    code, text, err = run(capsys, "vibration", records / "sweep.csv", records / "fixed.csv",
                          "--out", out, "--quiet")
    assert code == 0, err
    for name in ("record", "scalogram", "levels", "bias_curve", "compensated"):
        assert (out / f"{name}.png").stat().st_size > 1000
    assert json.loads((out / "result.json").read_text())["level"] == 6
    comp = tmp_path / "comp.csv"
    code, text, err = run(capsys, "vibration", "apply", out / "model.json",
                          records / "fixed.csv", "--out", comp, "--json")
    assert code == 0, err
    summary = json.loads(text)
    df = pd.read_csv(comp)
    # independent: the model loaded in Python and applied to the same record
    from inertialab.calib.model_types import load_model
    from inertialab.workflows.vibration import load_run

    m = load_model(out / "model.json")
    run_ = load_run(records / "fixed.csv")
    ref = m.compensate(run_.rate_dph, run_.vib_on, run_.freq_hz)
    np.testing.assert_allclose(df["rate_comp_dph"].to_numpy(), ref, rtol=0, atol=1e-9)
    assert summary["residual"]["delta_b"] == pytest.approx(
        json.loads((out / "result.json").read_text())["residual_bias_dph"]["rbf"], abs=1e-9)


def test_sweep_alone_omits_compensation(records, capsys):
    code, text, err = run(capsys, "vibration", records / "sweep.csv", "--json", "--quiet",
                          "--level", "auto")
    assert code == 0, err
    d = json.loads(text)
    assert d["residual_bias_dph"] is None and d["tables"]["compensation"] == {}


def test_bad_input_exits_2_with_one_line(records, tmp_path, capsys):
    df = pd.read_csv(records / "fixed.csv").drop(columns=["vib_on", "phase"])
    bad = tmp_path / "novib.csv"
    df.to_csv(bad, index=False)
    code, text, err = run(capsys, "vibration", bad, "--json")
    assert code == 2 and text == "" and err.count("\n") == 1 and "vib_on" in err
    code, text, err = run(capsys, "vibration", records / "sweep.csv", "--level", "12")
    assert code == 2 and "--level" in err
    code, text, err = run(capsys, "vibration", records / "sweep.csv", "--spread", "wide")
    assert code == 2 and "--spread" in err
    code, text, err = run(capsys, "simulate", "fog-vibration", "--experiment", "up",
                          "--out", tmp_path / "x.csv")
    assert code == 2 and "--experiment" in err


@pytest.mark.slow  # the vibration study of the demo: about 30 s
def test_demo_section_renders(tmp_path, capsys):
    # the study's quick demo runs and its report section (tables + figures) renders
    code, text, err = run(capsys, "demo", "--study", "vibration", "--quick", "--out",
                          tmp_path / "rep", "--json", "--quiet")
    assert code == 0, err
    d = json.loads(text)
    labels = {row["figure"]: row["ours"] for row in d["summary"]}
    assert labels["level L (rule / used)"].endswith("/ 6")
    html = (tmp_path / "rep" / "index.html").read_text()
    assert "Table 1 analogue" in html and "data:image/png;base64" in html


@pytest.mark.slow  # a fit with figures, then apply: about 15 s
def test_canonical_verbs_and_the_old_spelling_gone(records, tmp_path, capsys):
    out = tmp_path / "fit"
    code, text, err = run(capsys, "vibration", "fit", records / "sweep.csv", "--out", out,
                          "--quiet", "--map", "rate_dph=rate_dph:dph")
    assert code == 0, err
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    code, _, err = run(capsys, "vibration", "apply", out / "model.json", records / "fixed.csv",
                       "--out", a, "--model", "poly")
    assert code == 0, err
    code, _, err = run(capsys, "vibration-compensate", out / "model.json",
                       records / "fixed.csv", "--out", b, "--model", "poly")
    assert code == 2 and "No such command" in err and not b.exists()  # the old spelling
    assert "rate_comp_dph" in pd.read_csv(a).columns
    code, text, _ = run(capsys, "--help")
    assert "vibration-compensate" not in text and "vibration" in text
    code, text, _ = run(capsys, "vibration", "--help")
    assert "fit" in text and "apply" in text
