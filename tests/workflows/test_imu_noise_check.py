"""``--check-on half`` says which samples the terms were fitted on, and ``--plan`` gives
a length for K on every axis with its 95 % interval (a K bound: the length at which a K
at its bound would be resolved), on simulated records of known truth."""

import json
import math

import numpy as np
import pandas as pd
import pytest

from inertialab.workflows.imu_drift import PLAN_REL, PLAN_Z, DriftOptions, axis_plan
from inertialab.workflows.imu_noise import analyse_imu
from inertialab.workflows.imu_noise_plan import _with_k
from tests.helpers import run_inprocess

FS = 10.0
TARGET = math.log(1 + PLAN_REL) / PLAN_Z


def test_check_on_half_reports_the_fitted_samples(tmp_path, capsys):
    rng = np.random.default_rng(7)
    n = 20_000
    y = 2e-3 * math.sqrt(FS) * rng.standard_normal(n)
    f = tmp_path / "g.csv"
    pd.DataFrame({"t_s": np.arange(n) / FS, "gx_rps": y}).to_csv(f, index=False,
                                                                 float_format="%.17g")
    code, out, err = run_inprocess(capsys, "allan", str(f), "--imu", "--predict-drift", "10",
                                   "--check-on", "half", "--json")
    assert code in (0, None), err
    imu = json.loads(out)["imu"]
    assert imu["fitted_on"] == {"first_sample": 0, "n_samples": n // 2}
    assert imu["n_samples"] == n
    # the terms are those of the first half alone, to the last digit
    half = analyse_imu({"gx": ("gx_rps", y[: n // 2], "rps")}, rate_hz=FS)
    assert imu["axes"][0]["noise_density"]["value"] == pytest.approx(
        half.axes[0].noise_density, rel=1e-12)
    code, out, _ = run_inprocess(capsys, "allan", str(f), "--imu", "--predict-drift", "10",
                                 "--check-on", "half")
    assert "fitted on samples 0 to 9999 (10000 of 20000: checked on the second half)" in out


def test_plan_gives_k_at_its_bound_and_an_interval():
    rng = np.random.default_rng(8)
    n = 20_000
    white = 2e-3 * math.sqrt(FS) * rng.standard_normal(n)           # no random walk
    walk = white + np.cumsum(4e-4 / math.sqrt(FS) * rng.standard_normal(n))
    opts = DriftOptions(horizons_s=(10.0,), bias_window_s=10.0, plan=True)
    res = analyse_imu({"gx": ("gx_rps", white, "rps"), "gy": ("gy_rps", walk, "rps")},
                      rate_hz=FS, drift=opts)
    gx, gy = res.axis("gx"), res.axis("gy")
    assert {"upper_bound", "not_observable"} & set(gx.terms.K.flags)
    p = gx.plan
    assert p["k_at_bound"] and p["needed_h"] > 0 and p["needed_h_95"] == [p["needed_h"], None]
    # at that length a K at its bound is read within +-20 % at 95 %
    ub = gx.terms.K.upper_bound
    at = axis_plan(_with_k(gx, ub, 1 / FS), FS, int(p["needed_h"] * 3600 * FS))
    assert at["long_enough"] or at["k_rel_95_now"] <= 1.1 * PLAN_Z * TARGET
    q = gy.plan
    assert not q["k_at_bound"]
    short, long_ = q["needed_h_95"]
    assert short is not None and short <= q["needed_h"] <= (long_ or math.inf)
    # the table says both: gx's length at K's bound as ">=", gy's with its interval
    from inertialab.workflows.imu_drift import display_tables

    rows = {r[0]: r[1] for t, _, rs in display_tables(res, "x") if t.startswith("Record")
            for r in rs}
    assert rows["gx"] == f">= {p['needed_h']:.3g}"
    assert rows["gy"] == (f"{q['needed_h']:.3g} [{short:.3g}, {long_:.3g}]" if long_
                          else f"{q['needed_h']:.3g}")
