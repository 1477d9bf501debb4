"""CLI: thermal fit / apply / export (compensate: the old spelling of apply) and simulate
thermal-tumble (spec 000, issue 5, issue 13)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from inertialab.cli.main import main
from tests.helpers import run_inprocess as run


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    d = tmp_path_factory.mktemp("thermal")
    for args in (["simulate", "thermal-tumble", "--preset", "paper", "--lot-seed", "0",
                  "--unit", "0", "--out", d / "a.csv"],
                 ["simulate", "thermal-tumble", "--lot-seed", "0", "--unit", "1", "--seed",
                  "1000", "--out", d / "b.csv"]):
        with pytest.raises(SystemExit) as ex:
            main([str(a) for a in args])
        assert ex.value.code == 0
    return d


@pytest.fixture(scope="module")
def fitted(records):
    out = records / "fit"
    with pytest.raises(SystemExit) as ex:
        main([str(a) for a in ["thermal", "fit", records / "a.csv", "--method",
                               "iafsa-scm-anfis,scm-anfis,fis,poly-sep", "--fish", "3",
                               "--generations", "1", "--search-epochs", "3", "--epochs", "20",
                               "--out", out, "--quiet"]])
    assert ex.value.code == 0
    return out


def test_simulate_writes_record_and_sidecar_with_seeds(records):
    side = json.loads((records / "a.meta.json").read_text())
    assert side["lot_seed"] == 0 and side["seed"] == 0 and side["preset"] == "paper"
    side_b = json.loads((records / "b.meta.json").read_text())
    assert side_b["seed"] == 1000 and side_b["unit_index"] == 1
    f = pd.read_csv(records / "a.csv")
    assert len(f) == 552 and "true_output_mv" in f.columns


def test_fit_json_has_the_issue_keys(records, capsys):
    code, out, _ = run(capsys, "thermal", "fit", records / "a.csv", "--method", "fis,poly-2d",
                       "--split", "interp_T", "--json")
    assert code == 0
    obj = json.loads(out)
    assert obj["command"] == "thermal fit"
    assert obj["settings"]["split"] == "interp_T" and obj["settings"]["seed"] == 0
    for m in ("fis", "poly-2d"):
        assert set(obj["models"][m]) >= {"rmse_ug", "me_ug", "ae_ug", "maxe_ppm", "mare_ppm",
                                         "rules", "wall_s"}
    assert obj["models"]["fis"]["rules"] >= 2
    assert obj["models"]["poly-2d"]["rules"] is None
    # the FIS reduces the ~1.5 mg raw drift by more than 10x on interpolated temperatures
    assert obj["models"]["fis"]["rmse_ug"] < obj["raw_rms_ug"] / 10
    assert obj["scm"]["fis"] == {"radius": 0.5, "squash": 1.25, "accept": 0.5, "reject": 0.15}


def test_fit_out_dir_and_search_parameters(fitted):
    res = json.loads((fitted / "result.json").read_text())
    assert res["model_method"] == "iafsa-scm-anfis"
    s = res["search"]
    assert s["fun"] <= s["f_default"]
    assert set(s["params"]) == {"radius", "squash", "accept", "reject"}
    assert (fitted / "model.json").exists() and (fitted / "models" / "poly-sep.json").exists()
    assert (fitted / "thermal_drift.png").stat().st_size > 1000


def test_compensate_transfers_to_another_unit(records, fitted, capsys):
    code, out, _ = run(capsys, "thermal", "apply", fitted / "model.json", records / "b.csv",
                       "--out", records / "b_comp.csv", "--json")
    assert code == 0
    obj = json.loads(out)
    assert obj["command"] == "thermal apply"
    assert obj["reference"] == "record"  # another unit: its own 55 °C tumble (§3.7)
    assert obj["drift"]["raw_max_drift_ug"] > 3000
    assert obj["drift"]["comp_max_drift_ug"] < 100  # short search here; >= 50x reduction
    f = pd.read_csv(records / "b_comp.csv")
    assert set(np.unique(f.status)) <= {0, 1, 2, 3}
    assert (records / "b_comp.meta.json").exists()
    ok = f.status == 0
    # compensated acceleration close to the true input (tens of µg at most)
    assert np.sqrt(np.mean((f.comp_a_g[ok] - f.true_a_in_g[ok]) ** 2)) * 1e6 < 50


def test_export_writes_c_pair(fitted, tmp_path, capsys):
    code, out, _ = run(capsys, "thermal", "export", fitted / "model.json", "--c", tmp_path / "c",
                       "--json")
    assert code == 0
    obj = json.loads(out)
    assert obj["n_rules"] == obj["exp_calls"] >= 2
    assert (tmp_path / "c" / "qfa_comp.c").read_text().count("#include") == 2


def test_export_refuses_a_polynomial_model(fitted, tmp_path, capsys):
    code, _, err = run(capsys, "thermal", "export", fitted / "models" / "poly-sep.json", "--c",
                       tmp_path / "c2")
    assert code == 2 and "fuzzy models" in err and "Traceback" not in err


def test_bad_inputs_exit_2_with_one_line(records, fitted, tmp_path, capsys):
    f = pd.read_csv(records / "a.csv")
    f[f.temp_set_c != 55.0].to_csv(tmp_path / "no55.csv", index=False)
    code, _, err = run(capsys, "thermal", "fit", tmp_path / "no55.csv", "--method", "fis")
    assert code == 2 and "reference temperature 55" in err and len(err.strip().splitlines()) == 1
    g = f.copy()
    g = g[~((g.temp_set_c == 0.0) & (g.pos_index == 3))]
    g.to_csv(tmp_path / "few.csv", index=False)
    code, _, err = run(capsys, "thermal", "fit", tmp_path / "few.csv", "--method", "fis")
    assert code == 2 and "23 distinct positions" in err
    h = f.copy()
    h["temp_meas_c"] = h["temp_meas_c"] + 200.0
    h["temp_set_c"] = h["temp_set_c"] + 200.0
    h.to_csv(tmp_path / "hot.csv", index=False)
    code, _, err = run(capsys, "thermal", "apply", fitted / "model.json",
                       tmp_path / "hot.csv", "--out", tmp_path / "hot_comp.csv")
    assert code == 2 and "outside the model's calibrated range" in err
    assert not (tmp_path / "hot_comp.csv").exists()
    code, _, err = run(capsys, "thermal", "fit", records / "a.csv", "--method", "magic")
    assert code == 2 and "--method" in err


def test_compensate_is_a_hidden_alias_of_apply(records, fitted, capsys):
    code, out, _ = run(capsys, "thermal", "--help")
    assert code == 0 and "apply" in out and "compensate" not in out
    code, out, _ = run(capsys, "thermal", "compensate", fitted / "model.json", records / "b.csv",
                       "--out", records / "b_comp2.csv", "--json")
    assert code == 0
    obj = json.loads(out)
    assert obj["command"] == "thermal compensate" and obj["reference"] == "record"
    a = pd.read_csv(records / "b_comp2.csv")
    code, _, _ = run(capsys, "thermal", "apply", fitted / "model.json", records / "b.csv",
                     "--out", records / "b_comp3.csv")
    assert code == 0
    b = pd.read_csv(records / "b_comp3.csv")
    np.testing.assert_array_equal(a.comp_a_g.to_numpy(), b.comp_a_g.to_numpy())


def test_fit_reads_through_the_mapping_front_door(records, tmp_path, capsys):
    # a file whose output column has a foreign name loads with --map
    f = pd.read_csv(records / "a.csv").rename(columns={"output_mv": "Vout"})
    f.to_csv(tmp_path / "renamed.csv", index=False)
    code, _, err = run(capsys, "thermal", "fit", tmp_path / "renamed.csv", "--method", "fis")
    assert code == 2
    code, out, _ = run(capsys, "thermal", "fit", tmp_path / "renamed.csv", "--method", "fis",
                       "--map", "output_mv=Vout", "--json")
    assert code == 0
    assert json.loads(out)["models"]["fis"]["rules"] >= 2
