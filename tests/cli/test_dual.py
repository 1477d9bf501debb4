"""CLI: dual fit, dual design (and their hidden old spellings calibrate dual, design dual),
simulate dual-tumble (spec 003)."""

import json

import numpy as np
import pytest

from tests.helpers import run_inprocess as run


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    d = tmp_path_factory.mktemp("dual")
    from inertialab.cli.main import main as m

    for args in (["simulate", "dual-tumble", "--out", d / "s1.csv", "--seed", "3", "--draw-unit"],
                 ["simulate", "dual-tumble", "--scenario", "S5", "--out", d / "s5.csv",
                  "--seed", "4"]):
        with pytest.raises(SystemExit) as ex:
            m([str(a) for a in args])
        assert ex.value.code == 0
    return d


def test_simulate_writes_record_sidecar_and_prior(records):
    side = json.loads((records / "s1.meta.json").read_text())
    assert side["seed"] == 3 and side["meter_a"]["oa_sign"] == 1 and "truth" in side
    prior = json.loads((records / "s1.prior.json").read_text())
    assert prior["schema"] == "inertialab.prior/1" and set(prior["coef"]) >= {"KA2", "KBx"}
    assert (records / "s5_orient2.csv").exists()


def test_calibrate_json_shape_and_accuracy(records, capsys):
    code, out, err = run(capsys, "dual", "fit", records / "s1.csv", "--prior",
                         records / "s1.prior.json", "--json")
    assert code == 0, err
    d = json.loads(out)
    truth = json.loads((records / "s1.meta.json").read_text())["truth"]
    for m in ("single-ls", "ls", "ebr", "ridge-hkb", "ridge-gcv"):
        r = d["methods"][m]
        assert {"coef", "sd", "residual", "rank", "estimable", "warnings"} <= set(r)
    ls, ebr = d["methods"]["ls"], d["methods"]["ebr"]
    assert ls["rank"] == 7 and ls["sd"]["KA2"] is None and "KA2" in ls["non_estimable"]
    names = {c["name"] for c in ls["estimable"]}
    assert {"kA1", "kB1", "eta", "KA2+KBx", "KB2-KAx", "KA0+KA2", "KB0+KB2"} == names
    # kA1 to the noise level (SD ~0.3 ppm; 2 ppm is > 6 SD); EBR K2 near truth with the
    # historical prior (prior SD ~ 5 ug/g^2; 20 ug/g^2 is 4 SD)
    assert abs(ls["coef"]["kA1"] - truth["kA1"]) < 2e-6
    assert abs(ebr["coef"]["KA2"] - truth["KA2"]) < 2e-5
    assert d["units"]["KA2"] == "g/g^2"
    assert d["paper_aliases"] == {"KAx": "KAip_paper", "KBx": "KBip_paper"}  # spec §1.3
    err = d["errors_vs_truth"]["ebr"]["coef"]["KA2"]
    assert err == pytest.approx(ebr["coef"]["KA2"] - truth["KA2"], abs=1e-15)
    assert any("not estimable" in w for w in d["warnings"])


def test_calibrate_two_orientation_and_out_dir(records, capsys, tmp_path):
    code, out, err = run(capsys, "dual", "fit", records / "s5.csv",
                         records / "s5_orient2.csv", "--method", "ls", "--json", "--out",
                         tmp_path / "o")
    assert code == 0, err
    d = json.loads(out)
    two = d["two_orientation"]
    truth = json.loads((records / "s5.meta.json").read_text())["truth"]
    assert two["rank"] == 14
    for n in ("KA2", "KB2", "KAx", "KBx"):
        assert abs(two["coef"][n] - truth[n]) < 5e-6  # ~0.7e-6 RMS (spec AC-11)
    files = {p.name for p in (tmp_path / "o").iterdir()}
    assert {"model.json", "result.json", "dual_residuals.png", "dual_coefficients.png",
            "dual_head_sensitivity.png"} <= files
    model = json.loads((tmp_path / "o" / "model.json").read_text())
    assert model["type"] == "dual-calibration"


@pytest.mark.parametrize("extra, pattern", [
    (["--method", "magic"], "--method must be one of"),
    (["--prior", "nope.json"], "no such prior file"),
])
def test_bad_options_exit_2_one_line(records, capsys, extra, pattern):
    code, out, err = run(capsys, "dual", "fit", records / "s1.csv", *extra)
    assert code == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and pattern in lines[0]


def test_bad_prior_names(records, capsys, tmp_path):
    prior = json.loads((records / "s1.prior.json").read_text())
    prior["coef"]["k_A2"] = prior["coef"].pop("KA2")
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(prior))
    code, _, err = run(capsys, "dual", "fit", records / "s1.csv", "--prior", p)
    assert code == 2 and "unknown coefficient name(s) k_A2" in err


def test_design_dual_json(capsys):
    code, out, err = run(capsys, "dual", "design", "--positions", "12", "--json")
    assert code == 0, err
    d = json.loads(out)
    np.testing.assert_allclose(d["positions_deg"], np.arange(12) * 30.0, atol=1e-9)
    assert d["criteria"]["cond"] == pytest.approx(np.sqrt(2), abs=1e-9)
    code, _, err = run(capsys, "dual", "design", "--positions", "5")
    assert code == 2 and "at least 7" in err


def test_old_spellings_are_gone(records, capsys):
    # calibrate dual / design dual were aliases for one release: now unknown commands
    for old in (("design", "dual", "--positions", "12"), ("calibrate", "dual", records / "s1.csv")):
        code, out, err = run(capsys, *old)
        assert code == 2 and out == "" and "No such command" in err
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "dual" in out and "calibrate" not in out
    code, out, _ = run(capsys, "dual", "--help")
    assert "fit" in out and "design" in out


@pytest.mark.parametrize("args, pattern", [
    (["--positions", "100000000"], "--positions"),  # main's size bound or ours
    (["--positions", "1000"], "--positions must be an integer from 7 to 360"),
    (["--positions", "20", "--step-deg", "1e-9"], "--step-deg = 1e-09 gives"),
    (["--range-deg", "0", "inf"], "--range-deg must be from -720 to 720, got inf"),
    (["--positions", "300", "--range-deg", "0", "90"], "exceeds the 91 candidate angles"),
])
def test_design_sizes_are_bounded(capsys, args, pattern):
    # --positions 1e8 was a MemoryError (exit 1)
    code, out, err = run(capsys, "dual", "design", *args)
    assert code == 2 and out == "" and err.count("\n") == 1 and pattern in err, err


def _prior_cases(tmp_path):
    cases = {
        "latin1.json": ("bytes", "{\"schema\": \"caf\xe9\"}".encode("latin-1"), "not UTF-8"),
        "utf16.json": ("bytes", "{}".encode("utf-16"), "not UTF-8"),
        "deep.json": ("text", "[" * 100000 + "]" * 100000, "nested too deeply"),
        "digits.json": ("text", "{\"schema\": " + "9" * 5000 + "}", "cannot be read as JSON"),
        "empty.json": ("text", "", "not JSON"),
        "text.csv": ("text", "KA0,KB0\nx,y\n", "history lacks columns"),
        "nonnum.csv": ("text", ",".join(["KA0", "KB0", "kA1", "kB1", "eta", "KA2", "KB2", "KAx",
                                         "KBx"]) + "\n" + "1," * 8 + "x\n" + "2," * 8 + "3\n",
                       "numbers only"),
        "binary.csv": ("bytes", bytes(range(256)) * 4, "calibration history"),
    }
    return cases


def test_hostile_prior_files_exit_2_one_line(records, capsys, tmp_path):
    # a non-UTF-8 prior JSON (and its kin) was exit 1
    for name, (kind, content, pattern) in _prior_cases(tmp_path).items():
        p = tmp_path / name
        if kind == "bytes":
            p.write_bytes(content)
        else:
            p.write_text(content)
        code, out, err = run(capsys, "dual", "fit", records / "s1.csv", "--method", "ebr",
                             "--prior", p)
        assert code == 2 and out == "" and err.count("\n") == 1, (name, err)
        assert pattern in err, (name, err)
    code, _, err = run(capsys, "dual", "fit", records / "s1.csv", "--prior", tmp_path)
    assert code == 2 and "is a directory" in err
