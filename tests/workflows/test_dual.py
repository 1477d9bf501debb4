"""workflows.dual: records to reduced tumbles, prior files (spec 003 §2.3, CONTRACTS)."""

import json

import numpy as np
import pytest

from inertialab.calib.dual_prior import certificate_prior
from inertialab.errors import InputError
from inertialab.io import read_record, write_record
from inertialab.sensors.dual_meter import COEF_NAMES
from inertialab.sim.dual import scenario_config, simulate_run
from inertialab.studies.dual import reduce_run
from inertialab.workflows.dual import load_prior
from inertialab.workflows.dual import prepare as reduce_record


def _write(tmp_path, run, df=None, meta=None, name="r.csv"):
    return read_record(write_record(run.to_frame() if df is None else df, tmp_path / name,
                                    run.meta if meta is None else meta), "dual_tumble")


def test_record_path_equals_array_path(tmp_path):
    run = simulate_run(scenario_config("S1"), 9)
    p = write_record(run.to_frame(), tmp_path / "r.csv", run.meta)
    red_f = reduce_record(read_record(p, "dual_tumble"))
    red_a = reduce_run(run)
    np.testing.assert_allclose(red_f.u_a, red_a.u_a, rtol=0, atol=1e-15)
    np.testing.assert_allclose(red_f.theta, red_a.theta)


def test_bad_inputs(tmp_path):
    run = simulate_run(scenario_config("S1"), 1)
    df = run.to_frame()
    # CCW and CW with different position sets
    bad = df[~((df.direction == "CW") & (df.pos_index == 5))]
    with pytest.raises(InputError, match=r"different position sets.*only CCW: \[5\]"):
        reduce_record(_write(tmp_path, run, bad, name="a.csv"))
    # fewer than 7 distinct positions
    few = df[df.pos_index.isin([0, 3, 6, 9, 12, 15])]
    with pytest.raises(InputError, match=r"6 distinct positions.*unidentifiable here: .*sin3t"):
        reduce_record(_write(tmp_path, run, few, name="b.csv"))
    # a quarter circle: 7 positions 0..90 deg, harmonic cond ~1.7e4
    r24 = simulate_run(scenario_config("S1", n_positions=24), 1)
    d24 = r24.to_frame()
    with pytest.raises(InputError, match="cover only 90 deg.*practically unidentifiable"):
        reduce_record(_write(tmp_path, r24, d24[d24.pos_index <= 6], name="c.csv"))
    # a half circle (0..180 by 30 deg) is accepted with a warning (cond ~122)
    r12 = simulate_run(scenario_config("S1", n_positions=12), 1)
    d12 = r12.to_frame()
    red = reduce_record(_write(tmp_path, r12, d12[d12.pos_index <= 6], name="f.csv"))
    assert any("poorly resolved" in w for w in red.warnings)
    # voltage outside the DMM range
    over = df.copy()
    over.loc[3, "v_b_v"] = 10.5
    with pytest.raises(InputError, match="DMM range"):
        reduce_record(_write(tmp_path, run, over, name="d.csv"))
    # missing required sidecar key
    meta = json.loads(json.dumps(run.meta))
    del meta["meter_b"]["oa_sign"]
    with pytest.raises(InputError, match="oa_sign"):
        reduce_record(_write(tmp_path, run, meta=meta, name="e.csv"))


def test_prior_files(tmp_path):
    good = certificate_prior().to_json()
    p = tmp_path / "prior.json"
    p.write_text(json.dumps(good))
    pr = load_prior(str(p))
    np.testing.assert_allclose(pr.sd, certificate_prior().sd)
    wrong = json.loads(json.dumps(good))
    wrong["coef"]["ka2"] = wrong["coef"].pop("KA2")
    p.write_text(json.dumps(wrong))
    with pytest.raises(InputError, match="case-sensitive"):
        load_prior(str(p))
    wrong = json.loads(json.dumps(good))
    wrong["coef"]["eta"]["unit"] = "deg"
    p.write_text(json.dumps(wrong))
    with pytest.raises(InputError, match="unit 'deg'"):
        load_prior(str(p))


def test_prior_from_history_csv(tmp_path):
    import pandas as pd

    from inertialab.sim.dual import draw_unit

    _, hist = draw_unit(np.random.default_rng(1))
    p = tmp_path / "history.csv"
    pd.DataFrame(hist, columns=COEF_NAMES).to_csv(p, index=False)
    pr = load_prior(str(p))
    np.testing.assert_allclose(pr.mean, hist.mean(axis=0), rtol=1e-12)
    assert np.all(pr.sd >= hist.std(axis=0, ddof=1) * (1 - 1e-12))
    pd.DataFrame(hist[:, :4], columns=COEF_NAMES[:4]).to_csv(p, index=False)
    with pytest.raises(InputError, match="history lacks columns"):
        load_prior(str(p))


def test_unsorted_rows_are_sorted_with_warning(tmp_path):
    run = simulate_run(scenario_config("S1"), 2)
    df = run.to_frame()
    shuffled = df.sample(frac=1.0, random_state=0)
    red_s = reduce_record(_write(tmp_path, run, shuffled, name="s.csv"))
    red = reduce_run(run)
    np.testing.assert_allclose(red_s.u_a, red.u_a, rtol=0, atol=1e-15)
    assert any("not in time order" in w for w in red_s.warnings)


def test_the_study_in_one_module_and_the_old_name_warns():
    """workflows/dual.py holds the commands' settings and calls; dual_run still answers,
    with a DeprecationWarning; the default methods are calib's; FitConfig is the fit's
    settings too and DualConfig (methods) its deprecated former spelling."""
    import importlib
    import sys
    import warnings

    from inertialab.calib.dual import METHODS
    from inertialab.workflows import dual

    assert dual.FitConfig().methods == METHODS == dual.parse_methods("all")
    with pytest.warns(DeprecationWarning, match="FitConfig"):
        old = dual.DualConfig(methods=("ls", "ebr"), prior="certificate")
    assert old == dual.FitConfig(method=("ls", "ebr"), prior="certificate")
    assert old.methods == ("ls", "ebr")
    with pytest.raises(InputError, match="'method'"):
        dual.FitConfig(method="lsq").validate()
    sys.modules.pop("inertialab.workflows.dual_run", None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = importlib.import_module("inertialab.workflows.dual_run")
    assert old.run_fit is dual.run_fit and old.FitConfig is dual.FitConfig
    assert any(issubclass(w.category, DeprecationWarning) for w in caught)
