"""``inertialab batch``: table, yield, per-unit failures, --strict, bad input."""

import json

import numpy as np
import pytest

from inertialab.sim.triaxial_poses import simulate_line
from tests.helpers import run_cli as run


def one_line_error(res, pattern):
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.stderr and pattern in lines[0], res.stderr


@pytest.fixture(scope="module")
def lot(tmp_path_factory):
    d = tmp_path_factory.mktemp("lot")
    sim = simulate_line(6, seed=3)
    for uid, frame in sim.data.groupby("unit_id", sort=True):
        frame.to_csv(d / f"{uid}.csv", index=False)
    (d / "U99999.csv").write_text("unit_id,pos_id,ax_mps2\nU99999,1,0.1\n")
    return d, sim.truth["X"]


def _json(res):
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


def test_batch_serial_json_table_yield_and_failed_unit(lot, tmp_path):
    d, X = lot
    res = run("batch", "calibrate", "triaxial", "--inputs", d / "*.csv", "--scheduler",
              "serial", "--g-local", "9.8", "--tolerance", "abs(bx)<=0.05,kx=0.98..1.02",
              "--json", "--out", tmp_path / "out")
    obj = _json(res)
    s = obj["summary"]
    assert s["n_units"] == 7 and s["n_error"] == 1 and s["n_pass"] + s["n_fail"] == 6
    units = {u["unit"]: u for u in obj["units"]}
    assert units["U99999"]["status"] == "error" and "ay" in units["U99999"]["reason"]
    assert any("U99999" in w for w in obj["warnings"])
    # the per-unit figures are the calibration: bias within ~5 sigma of the truth
    bx = np.array([units[f"U{i:05d}"]["figures"]["bx"] for i in range(6)])
    assert np.max(np.abs(bx - X[:, 0])) < 0.02
    # pass/fail follows the rules on the reported figures
    for u in obj["units"][:-1]:
        f = u["figures"]
        ok = abs(f["bx"]) <= 0.05 and 0.98 <= f["kx"] <= 1.02
        assert (u["status"] == "pass") == ok
    assert s["yield"] == pytest.approx(s["n_pass"] / 7)
    assert obj["settings"]["tolerance"] == ["abs(bx)<=0.05", "kx=0.98..1.02"]
    assert len(obj["inputs"]) == 7 and all(len(i["sha256"]) == 64 for i in obj["inputs"])
    out = tmp_path / "out"
    assert (out / "batch.png").stat().st_size > 1000
    assert (out / "units.csv").read_text().count("\n") == 8
    assert json.loads((out / "summary.json").read_text())["summary"]["n_error"] == 1


def test_batch_strict_exits_2(lot):
    d, _ = lot
    res = run("batch", "calibrate-triaxial", "--inputs", d / "*.csv", "--scheduler", "serial",
              "--g-local", "9.8", "--strict", "--quiet")
    one_line_error(res, "1 of 7 units could not be processed (--strict)")


@pytest.mark.slow  # starts a Dask LocalCluster: about 10 s
def test_batch_local_cluster_equals_serial(lot):
    d, _ = lot
    args = ("batch", "calibrate", "triaxial", "--inputs", d / "U0000*.csv", "--g-local", "9.8",
            "--json")
    par = _json(run(*args, "--workers", "2"))
    ser = _json(run(*args, "--scheduler", "serial"))
    assert par["settings"]["scheduler"] == "local" and par["settings"]["workers"] == 2
    assert [u["figures"] for u in par["units"]] == [u["figures"] for u in ser["units"]]


@pytest.mark.parametrize("extra, pattern", [
    (("--inputs", "nowhere/*.csv"), "matches no file"),
    (("--map", "ax_mps2=AccX:dps"), "angular_rate"),
    (("--map", "ax_mps2=AccX:furlong"), "unknown unit"),
    (("--tolerance", "bx<<1"), "tolerance"),
])
def test_batch_bad_input_one_line(lot, extra, pattern):
    d, _ = lot
    base = ["--inputs", d / "*.csv"] if "--inputs" not in extra else []
    res = run("batch", "calibrate-triaxial", *base, *extra, "--scheduler", "serial")
    one_line_error(res, pattern)


def test_batch_unknown_command():
    one_line_error(run("batch", "fly", "--inputs", "x"), "unknown command")


def test_batch_allan_map_missing_column_marks_unit(tmp_path):
    rng = np.random.default_rng(2)
    for i in range(2):
        with open(tmp_path / f"g{i}.csv", "w") as fh:
            fh.write("Time;GyrZ\n")
            for k, v in enumerate(rng.standard_normal(20000)):
                fh.write(f"{10 * k};{v:.6f}".replace(".", ",") + "\n")
    (tmp_path / "g2.csv").write_text("Time;Other\n0;1\n10;2\n")
    res = run("batch", "allan", "--inputs", tmp_path / "*.csv", "--scheduler", "serial",
              "--map", "t_s=Time:ms,rate_dps=GyrZ:dps", "--json", "--tolerance", "adev_1s<=1")
    obj = _json(res)
    st = {u["unit"]: u for u in obj["units"]}
    assert st["g2"]["status"] == "error" and "'GyrZ'" in st["g2"]["reason"]
    # white noise of sd 1 dps at 100 Hz: ADEV(1 s) = 1/sqrt(100) = 0.1 dps; 200 s of data
    # give an EDF of ~200 at 1 s, so 15 % is about 3 sigma
    for k in ("g0", "g1"):
        assert st[k]["status"] == "pass"
        assert st[k]["figures"]["adev_1s"] == pytest.approx(0.1, rel=0.15)
        assert st[k]["figures"]["rate_hz"] == pytest.approx(100.0)
