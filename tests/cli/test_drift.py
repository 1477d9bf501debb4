"""CLI: drift fit, drift forecast, simulate storage-drift (spec 004)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from inertialab.cli.main import main
from tests.helpers import run_inprocess as run


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    d = tmp_path_factory.mktemp("drift")
    with pytest.raises(SystemExit) as ex:
        main(["simulate", "storage-drift", "--preset", "nav", "--units", "2", "--days", "70",
              "--seed", "3", "--out", str(d / "rec.csv")])
    assert ex.value.code == 0
    return d


def test_simulate_writes_record_and_sidecar(record):
    df = pd.read_csv(record / "rec.csv")
    side = json.loads((record / "rec.meta.json").read_text())
    assert side["seed"] == 3 and side["preset"] == "nav" and side["source"] == "virtual_lab"
    assert set(df["unit_id"]) == {"QA001", "QA002"}
    assert {"bias_mg", "sf_ma_per_g", "true_bias_mg", "is_outlier_true"} <= set(df.columns)


@pytest.mark.filterwarnings("ignore")
def test_fit_json_shape_holdout_and_forecast_roundtrip(record, capsys, tmp_path):
    code, out, err = run(capsys, "drift", "fit", record / "rec.csv", "--origin-day", "49",
                         "--restarts", "2", "--horizon", "20", "--json", "--seed", "1",
                         "--quantity", "bias",
                         "--out", tmp_path / "o")
    assert code == 0, err
    obj = json.loads(out)
    assert obj["command"] == "drift fit" and obj["settings"]["seed"] == 1
    assert obj["units"]["bias"] == "ug" and obj["units"]["sf"] == "ppm"
    assert set(obj["per_unit"]["QA001"]) == {"bias"}
    u = obj["per_unit"]["QA001"]["bias"]
    for k in ("order", "cv_scores", "fit", "forecast", "baselines", "whiteness",
              "recalibration_day"):
        assert k in u
    assert set(u["fit"]) == {"mse", "rmse", "max_ae"}
    assert set(u["forecast"]) == {"day", "value", "lo95", "hi95"}
    assert len(u["forecast"]["value"]) == 20
    assert set(u["baselines"]["persistence"]) == {"rmse", "max_ae"}
    # holdout metrics recomputed from the record (bias in ug, observed days only)
    df = pd.read_csv(record / "rec.csv")
    g = df[(df.unit_id == "QA001") & (df.day > 49) & (df.day <= 69)]
    fc = dict(zip(u["forecast"]["day"], u["forecast"]["value"]))
    e = g["bias_mg"].to_numpy() * 1000 - np.array([fc[d] for d in g["day"]])
    assert u["holdout"]["rmse"] == pytest.approx(np.sqrt(np.mean(e ** 2)), rel=1e-9)
    # the saved model forecasts the same numbers
    code, out2, err = run(capsys, "drift", "forecast", tmp_path / "o" / "model.json", "--json")
    assert code == 0, err
    again = json.loads(out2)["per_unit"]["QA001"]["bias"]["forecast"]
    np.testing.assert_allclose(again["value"], u["forecast"]["value"], rtol=0, atol=0)
    assert (tmp_path / "o" / "result.json").exists()
    assert (tmp_path / "o" / "schedule.png").exists()


def test_bad_input_exits_2_with_one_line(record, capsys, tmp_path):
    code, _, err = run(capsys, "drift", "fit", record / "rec.csv", "--quantity", "temp")
    assert code == 2 and err.count("\n") == 1 and "--quantity" in err
    code, _, err = run(capsys, "drift", "fit", record / "rec.csv", "--order", "zero")
    assert code == 2 and "--order" in err
    bad = tmp_path / "dup.csv"
    pd.DataFrame({"unit_id": ["A", "A", "A"], "timestamp": ["2025-01-01T08:00:00Z"] * 2
                  + ["2025-01-02T08:00:00Z"], "bias_mg": [1.0, 2.0, 1.5]}).to_csv(bad, index=False)
    code, _, err = run(capsys, "drift", "fit", bad)
    assert code == 2 and "appears twice" in err and err.count("\n") == 1
    code, _, err = run(capsys, "drift", "forecast", tmp_path / "missing.json")
    assert code == 2
    # a unit with too few usable values for the model is named (with its quantity)
    short = tmp_path / "short.csv"
    pd.DataFrame({"unit_id": ["A"] * 4 + ["B"] * 2,
                  "date": ["2024-03-01", "2024-03-02", "2024-03-04", "2024-03-05",
                           "2024-03-01", "2024-03-02"],
                  "bias_mg": [0.15, 0.16, 0.15, 0.17, -0.08, -0.09],
                  "valid": [True] * 5 + [False]}).to_csv(short, index=False)
    code, _, err = run(capsys, "drift", "fit", short, "--quantity", "bias", "--order", "1",
                       "--restarts", "1", "--out", tmp_path / "o")
    assert code == 2 and err.count("\n") == 1
    assert "unit B, bias: need at least 3 values to fit a NAR model, got 1 in-sample" in err


@pytest.mark.filterwarnings("ignore")
def test_unit_ids_become_safe_figure_names(record, capsys, tmp_path):
    # a unit_id with a path in it, or 300 characters long, never escapes
    # --out and never collides: figure names are safe slugs with a collision-free suffix
    df = pd.read_csv(record / "rec.csv")
    evil, long_id = "x/../../../ESCAPED", "U" * 300
    df["unit_id"] = df["unit_id"].map({"QA001": evil, "QA002": long_id})
    work = tmp_path / "deep" / "er"
    work.mkdir(parents=True)
    df.to_csv(work / "evil.csv", index=False)
    out = work / "out"
    code, _, err = run(capsys, "drift", "fit", work / "evil.csv", "--quantity", "bias",
                       "--restarts", "1", "--out", out, "--quiet")
    assert code == 0, err
    outside = [p for p in tmp_path.rglob("*") if p.is_file() and out not in p.parents
               and p.name != "evil.csv"]
    assert outside == []
    # (".inertialab" is the output transaction's own marker)
    names = sorted(p.name for p in out.iterdir() if p.name != ".inertialab")
    assert all(len(n) < 100 and "/" not in n and not n.startswith(".") for n in names)
    pngs = [n for n in names if n.endswith(".png")]
    assert len(pngs) == 2 * 3 + 1  # fit, forecast, acf per unit + the schedule
    assert any(n.startswith("fit_bias_x_") and "ESCAPED-" in n for n in pngs)
    res = json.loads((out / "result.json").read_text())
    assert set(res["per_unit"]) == {evil, long_id}  # the ids themselves stay as data


def test_horizon_is_bounded(capsys, record):
    # --horizon 100000000 ran past 120 s; now one line, exit 2, at once
    import time
    from pathlib import Path

    model = Path(__file__).parents[1] / "data" / "models" / "storage-drift-v1.json"
    t0 = time.perf_counter()
    code, out, err = run(capsys, "drift", "forecast", model, "--horizon", "100000000")
    assert code == 2 and out == "" and err.count("\n") == 1
    assert "--horizon" in err  # the CLI's generic size bound or ours
    assert time.perf_counter() - t0 < 10
    code, out, err = run(capsys, "drift", "forecast", model, "--horizon", "5000")
    assert code == 2 and "--horizon must be an integer from 1 to 1000" in err
    code, _, err = run(capsys, "drift", "fit", record / "rec.csv", "--horizon", "0")
    assert code == 2 and "--horizon" in err
    code, out, err = run(capsys, "drift", "forecast", model, "--horizon", "1000", "--json")
    assert code == 0, err
    assert len(json.loads(out)["per_unit"]["QA001"]["bias"]["forecast"]["day"]) == 1000


@pytest.mark.filterwarnings("ignore")
def test_evaluate_rolling_origin_and_hidden_grid(record, capsys, tmp_path):
    # rolling-origin evaluation in the CLI with the per-step error curve,
    # the hidden size chosen by validation from a grid
    code, out, err = run(capsys, "drift", "evaluate", record / "rec.csv", "--quantity", "bias",
                         "--unit-id", "QA001", "--first", "40", "--step", "10", "--horizon", "10",
                         "--restarts", "2", "--hidden-grid", "2,4", "--json", "--out",
                         tmp_path / "ev")
    assert code == 0, err
    r = json.loads(out)["per_unit"]["QA001"]["bias"]
    assert r["origins"] == [40, 50, 60]  # 70 days, K = 10: T <= 60
    assert len(r["rmse"]["nar"]) == 3 and len(r["step_mae"]["nar"]) == 10
    pers = np.asarray(r["rmse"]["persistence"])
    assert r["win_rate"]["persistence"] == pytest.approx(np.mean(np.asarray(r["rmse"]["nar"]) < pers))
    assert (tmp_path / "ev" / "error_curve_bias_QA001.png").exists()
    code, _, err = run(capsys, "drift", "evaluate", record / "rec.csv", "--unit-id", "NOPE")
    assert code == 2 and "no unit(s) NOPE" in err
    code, _, err = run(capsys, "drift", "fit", record / "rec.csv", "--hidden-grid", "2,x")
    assert code == 2 and "--hidden-grid" in err


@pytest.mark.filterwarnings("ignore")
def test_apply_writes_compensated_record(record, capsys, tmp_path):
    code, _, err = run(capsys, "drift", "fit", record / "rec.csv", "--origin-day", "49",
                       "--restarts", "1", "--out", tmp_path / "m", "--quiet")
    assert code == 0, err
    code, out, err = run(capsys, "drift", "apply", tmp_path / "m" / "model.json",
                         record / "rec.csv", "--out", tmp_path / "comp.csv", "--json")
    assert code == 0, err
    s = json.loads(out)["summary"]
    assert set(s) == {"QA001", "QA002"} and s["QA001"]["bias"]["n"] > 10
    df = pd.read_csv(tmp_path / "comp.csv")
    assert {"bias_hat_ug", "sf_hat_ma_per_g", "bias_residual_ug", "status"} <= set(df.columns)
    assert set(df.loc[df["day"] <= 49, "status"]) == {1}
    assert (tmp_path / "comp.meta.json").exists()
