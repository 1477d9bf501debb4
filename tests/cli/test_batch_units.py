"""``batch``'s units run the single commands' own workflow calls: on a batch of two
simulated files, each unit's key figures are the ones the single command gives on that
file alone (``allan FILE``, ``triaxial fit FILE``, ``thermal apply MODEL FILE``)."""

import json
import math
from pathlib import Path

import numpy as np
import pytest

from inertialab.sim.triaxial_poses import simulate_line
from tests.helpers import run_cli as run


def _json(res):
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


@pytest.fixture(scope="module")
def gyros(tmp_path_factory):
    d = tmp_path_factory.mktemp("gyros")
    for seed in (1, 2):
        _json(run("simulate", "gyro-static", "--preset", "allan-test", "--hours", "0.05",
                  "--rate", "10", "--seed", seed, "--out", d / f"g{seed}.csv", "--json"))
    return d


@pytest.mark.filterwarnings("ignore")
def test_allan_units_equal_the_single_command(gyros):
    batch = _json(run("batch", "allan", "--inputs", gyros / "g*.csv", "--scheduler", "serial",
                      "--json"))
    assert [u["status"] for u in batch["units"]] == ["pass", "pass"]
    for unit in batch["units"]:
        one = _json(run("allan", unit["path"], "--json"))
        f, taus, dev = unit["figures"], np.array(one["taus_s"]), np.array(one["dev"])
        assert one["statistic"] == "oadev" and one["settings"]["taus"] == "octave"
        k = int(np.argmin(dev))
        assert f["adev_min"] == dev[k] and f["tau_min_s"] == taus[k]
        # ADEV at 1 s: log-log interpolation of the single command's curve
        want = math.exp(np.interp(0.0, np.log(taus), np.log(dev)))
        assert f["adev_1s"] == pytest.approx(want, rel=1e-12)
        assert (f["column"], f["column_unit"]) == (one["settings"]["column"], one["unit"])
        assert (f["rate_hz"], f["n_samples"]) == (one["settings"]["rate_hz"],
                                                  one["settings"]["n_samples"])


@pytest.fixture(scope="module")
def poses(tmp_path_factory):
    d = tmp_path_factory.mktemp("poses")
    sim = simulate_line(2, seed=5)
    for uid, frame in sim.data.groupby("unit_id", sort=True):
        frame.to_csv(d / f"{uid}.csv", index=False)
    return d


@pytest.mark.filterwarnings("ignore")
def test_triaxial_units_equal_the_single_command(poses):
    batch = _json(run("batch", "triaxial", "fit", "--inputs", poses / "*.csv", "--scheduler",
                      "serial", "--g-local", "9.8", "--json"))
    assert len(batch["units"]) == 2
    for unit in batch["units"]:
        one = _json(run("triaxial", "fit", unit["path"], "--g-local", "9.8", "--json"))
        f = unit["figures"]
        assert {k: f[k] for k in one["params"]} == one["params"]
        assert f["resid_rms"] == one["residual_rms"] and f["converged"] == one["converged"]
        assert f["n_positions"] == one["n_records"]
        assert f["method"] == f"{one['method']}/{one['objective']}" == "lm/norm"


@pytest.mark.filterwarnings("ignore")
def test_units_take_every_reading_option(gyros, tmp_path):
    """A reading option beyond the five the batch once forwarded (here --time-col and
    --time-unit) reaches each unit as it reaches the single command."""
    import pandas as pd

    src = pd.read_csv(gyros / "g1.csv")
    odd = tmp_path / "odd.csv"
    src.assign(clock_ms=src["t_s"] * 1e3).drop(columns="t_s").to_csv(odd, index=False)
    flags = ["--time-col", "clock_ms", "--time-unit", "ms"]
    batch = _json(run("batch", "allan", "--inputs", odd, "--scheduler", "serial", *flags,
                      "--json"))
    one = _json(run("allan", odd, *flags, "--json"))
    f = batch["units"][0]["figures"]
    assert batch["units"][0]["status"] == "pass", batch["units"][0]["reason"]
    assert f["rate_hz"] == one["settings"]["rate_hz"] == 10.0
    assert f["adev_min"] == min(one["dev"])


MODEL = Path(__file__).resolve().parents[1] / "data" / "models" / "thermal-compensation-v1.json"


@pytest.mark.filterwarnings("ignore")
def test_thermal_units_equal_the_single_command(tmp_path):
    """Units 0 and 3 of a lot against one model: each unit's figures are those of
    ``thermal apply MODEL FILE`` (for unit 3, another unit than the model's, that is the
    transfer to its own 55 °C tumble, as the single command does by default)."""
    import pandas as pd

    for unit in (0, 3):
        _json(run("simulate", "thermal-tumble", "--unit", unit, "--out",
                  tmp_path / "lot" / f"t{unit}.csv", "--json"))
    batch = _json(run("batch", "thermal", "apply", "--model", MODEL, "--inputs",
                      tmp_path / "lot" / "t*.csv", "--scheduler", "serial", "--json"))
    assert [u["status"] for u in batch["units"]] == ["pass", "pass"]
    for unit in batch["units"]:
        out = tmp_path / f"{unit['unit']}_comp.csv"
        one = _json(run("thermal", "apply", MODEL, unit["path"], "--out", out, "--json"))
        d = pd.read_csv(out)
        err = (d["comp_a_g"].to_numpy() - d["a_in_g"].to_numpy()) * 1e6
        f = unit["figures"]
        assert f["n_clamped"] == one["n_clamped"]
        assert f["resid_rms_ug"] == pytest.approx(float(np.sqrt(np.mean(err ** 2))), rel=1e-9)
        assert f["resid_max_ug"] == pytest.approx(float(np.max(np.abs(err))), rel=1e-9)
