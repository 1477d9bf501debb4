"""CLI: thermal fit / apply / export (compensate: the old spelling of apply) and simulate
thermal-tumble (spec 000)."""

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


def test_compensate_is_gone_apply_stays(records, fitted, capsys):
    code, out, _ = run(capsys, "thermal", "--help")
    assert code == 0 and "apply" in out and "compensate" not in out
    code, out, err = run(capsys, "thermal", "compensate", fitted / "model.json",
                         records / "b.csv", "--out", records / "b_comp2.csv")
    assert code == 2 and "No such command" in err
    assert not (records / "b_comp2.csv").exists()
    code, out, _ = run(capsys, "thermal", "apply", fitted / "model.json", records / "b.csv",
                       "--out", records / "b_comp3.csv", "--json")
    assert code == 0
    obj = json.loads(out)
    assert obj["command"] == "thermal apply" and obj["reference"] == "record"


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


def test_fit_all_saves_the_proposed_model_and_export_works(records, tmp_path, capsys):
    """The documented fit -> export sequence with --method all."""
    out = tmp_path / "all"
    code, _, err = run(capsys, "thermal", "fit", records / "a.csv", "--method", "all",
                       "--fish", "3", "--generations", "1", "--search-epochs", "3",
                       "--epochs", "10", "--out", out, "--quiet")
    assert code == 0, err
    res = json.loads((out / "result.json").read_text())
    assert res["model_method"] == "iafsa-scm-anfis"
    assert list(res["models"])[0] == "ann"  # the table keeps the paper's order
    saved = json.loads((out / "model.json").read_text())
    assert saved["payload"]["method"] == "iafsa-scm-anfis"
    assert res["drift"]["comp_max_drift_ug"] < res["drift"]["raw_max_drift_ug"] / 10
    code, _, err = run(capsys, "thermal", "export", out / "model.json", "--c", tmp_path / "c")
    assert code == 0, err
    assert (tmp_path / "c" / "qfa_comp.c").exists()


def test_fit_writes_the_papers_tables_and_figures_from_user_data(fitted):
    """Table 2 (CSV and Markdown), Table 1, Figs. 3/4 and their data."""
    res = json.loads((fitted / "result.json").read_text())
    t2 = pd.read_csv(fitted / "table2.csv")
    assert list(t2.method) == list(res["models"])
    for _, row in t2.iterrows():
        m = res["models"][row.method]
        for k in ("me_ug", "ae_ug", "maxe_ppm", "mare_ppm", "rmse_ug"):
            assert row[k] == pytest.approx(m[k], rel=1e-12)
        for k in ("me", "ae", "rmse"):
            assert row[f"{k}_mg"] == pytest.approx(m[f"{k}_ug"] / 1e3, rel=1e-12)
    iafsa = t2[t2.method == "iafsa-scm-anfis"].iloc[0]
    assert iafsa.squash == pytest.approx(res["search"]["params"]["squash"])
    md = (fitted / "table2.md").read_text()
    assert "| model | ME (µg) | AE (µg) | MAXE (ppm) | MARE (ppm) | RMSE (µg) |" in md
    assert md.count("\n| ") == 1 + len(t2)
    t1 = pd.read_csv(fitted / "table1.csv")
    table1 = dict(zip(t1.quantity, t1.value))
    assert table1["n_fish"] == 3 and table1["try_number"] == 5
    assert table1["crowd"] == pytest.approx(0.618) and table1["visual"] == pytest.approx(0.3)
    assert res["fish"]["step"] == pytest.approx(0.1)
    # Figs. 3/4: spec 000 §8.1.2 magnitudes of the paper preset's unit 0
    b = res["bias_scale_factor"]
    assert 1.4 <= b["max_bias_drift_mg"] <= 2.0
    data = pd.read_csv(fitted / "bias_scale_factor.csv")
    assert len(data) == 23 * 12 and data.a_in_g.nunique() == 12
    assert np.nanmax(np.abs(data.bias_drift_mg)) == pytest.approx(b["max_bias_drift_mg"])
    for name in ("thermal_bias", "thermal_scale_factor", "thermal_drift", "thermal_residuals"):
        assert (fitted / f"{name}.png").stat().st_size > 1000


def test_fish_swarm_parameters_are_settable_and_checked(records, capsys):
    args = ["thermal", "fit", records / "a.csv", "--method", "iafsa-scm-anfis", "--fish", "3",
            "--generations", "2", "--search-epochs", "3", "--epochs", "5", "--json"]
    code, out, _ = run(capsys, *args, "--visual", "0.05", "--step", "0.02", "--try-number",
                       "2", "--crowd", "0.3")
    assert code == 0
    obj = json.loads(out)
    assert obj["fish"] | {"visual": 0.05, "step": 0.02, "try_number": 2,
                          "crowd": 0.3} == obj["fish"]
    assert obj["settings"]["crowd"] == 0.3
    code, out2, _ = run(capsys, *args)
    assert code == 0
    # the swarm moved differently: a different number of objective evaluations or result
    a, b = obj["search"], json.loads(out2)["search"]
    assert (a["nfev"], a["params"]) != (b["nfev"], b["params"])
    code, _, err = run(capsys, *args, "--crowd", "1.5")
    assert code == 2 and "crowd" in err and "(0, 1]" in err


def test_apply_writes_the_transfer_figure(records, fitted, tmp_path, capsys):
    """The seed's Fig. 9 from thermal apply."""
    fig = tmp_path / "figs" / "fig9.png"
    code, _, err = run(capsys, "thermal", "apply", fitted / "model.json", records / "b.csv",
                       "--out", tmp_path / "b.csv", "--figure", fig)
    assert code == 0, err
    assert fig.stat().st_size > 1000
    code, _, err = run(capsys, "thermal", "apply", fitted / "model.json", records / "b.csv",
                       "--out", tmp_path / "c.csv", "--figure", tmp_path / "fig9.pdf")
    assert code == 2 and ".png" in err and not (tmp_path / "c.csv").exists()


def test_export_for_another_unit_carries_its_mapping(records, fitted, tmp_path, capsys):
    code, out, err = run(capsys, "thermal", "export", fitted / "model.json", "--c",
                         tmp_path / "cb", "--unit-record", records / "b.csv", "--json")
    assert code == 0, err
    obj = json.loads(out)
    b_id = pd.read_csv(records / "b.csv").unit_id.iloc[0]
    assert obj["mapped_unit"] == b_id
    src = (tmp_path / "cb" / "qfa_comp.c").read_text()
    assert "MAP_UNIT = 1" in src


def test_export_of_a_hostile_model_file(fitted, tmp_path, capsys):
    """Through the CLI: an injected unit_id stays inside a comment; a
    NaN coefficient (JSON NaN) is refused (on load) with exit 2 and
    nothing written."""
    env = json.loads((fitted / "model.json").read_text())
    env["payload"]["unit_id"] = "U */ int evil(void){return 1;} /*"
    (tmp_path / "evil.json").write_text(json.dumps(env))
    code, _, err = run(capsys, "thermal", "export", tmp_path / "evil.json", "--c", tmp_path / "c")
    assert code == 0, err
    src = (tmp_path / "c" / "qfa_comp.h").read_text()
    assert src.count("/*") == src.count("*/") and "*/ int evil" not in src
    env["payload"]["ref"]["k1"] = float("nan")
    (tmp_path / "nan.json").write_text(json.dumps(env))  # writes NaN, as the fuzz did
    code, _, err = run(capsys, "thermal", "export", tmp_path / "nan.json", "--c",
                       tmp_path / "c2")
    assert code == 2 and "finite" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "c2").exists()


def test_a_1e308_cell_and_nan_models_exit_2_and_write_nothing(records, fitted, tmp_path,
                                                               capsys):
    """Thermal fit with one 1e308 cell wrote a model with null metrics;
    thermal compensate with a NaN model wrote all-NaN outputs. Both are bad input now."""
    f = pd.read_csv(records / "a.csv")
    f.loc[200, "output_mv"] = 1e308
    f.to_csv(tmp_path / "big.csv", index=False)
    code, _, err = run(capsys, "thermal", "fit", tmp_path / "big.csv", "--method", "fis",
                       "--out", tmp_path / "fit_big")
    assert code == 2 and "row 201" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "fit_big").exists()
    env = json.loads((fitted / "model.json").read_text())
    env["payload"]["regressor"]["y_span"] = float("nan")
    (tmp_path / "nan.json").write_text(json.dumps(env))
    code, _, err = run(capsys, "thermal", "apply", tmp_path / "nan.json", records / "b.csv",
                       "--out", tmp_path / "nan_out.csv")
    assert code == 2 and ("not finite" in err or "non-finite" in err)
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "nan_out.csv").exists()
