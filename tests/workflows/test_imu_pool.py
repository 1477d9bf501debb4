"""allan --imu --pool's reading: logs of different units, column names and rates each
read with their own and pooled; a log that cannot join is refused naming it before any
fit; a pooled axis carries each log's own terms, the between-log test and the model
choice, and predicts a log not in the fit."""

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError
from inertialab.io import read_record
from inertialab.sim.mems_presets import simulate
from inertialab.units import convert
from inertialab.workflows.imu_pool import analyse_pool


def _write(path, seed, *, unit="dph", rate=None, axes=("gx", "gy"), hours=0.3, rename=None,
           moving=False):
    cols = {}
    for j, ax in enumerate(axes):
        r = simulate("consumer-100hz", hours=hours, seed=seed + j, rate_hz=rate)
        y = convert(r.y, r.unit, unit)
        if moving and j == 0:
            t = np.arange(y.size) / r.rate_hz
            y = y + convert(30.0, "dps", unit) * np.sin(2 * np.pi * t / 20.0)
        cols[(rename or {}).get(ax, f"{ax}_{unit}")] = y
    t = np.arange(y.size) / r.rate_hz
    pd.DataFrame({"t_s": t, **cols}).to_csv(path, index=False)
    return str(path)


def _recs(*paths):
    """The logs' records, read as the command runner reads them for ``allan --imu``."""
    return [read_record(p, "gyro_log") for p in paths]


def test_logs_of_other_units_and_rates_pool_with_each_own_terms(tmp_path):
    one = dict(axes=("gx",), hours=0.2)
    a = _write(tmp_path / "a.csv", 0, **one)
    b = _write(tmp_path / "b.csv", 10, unit="rps", **one)
    c = _write(tmp_path / "c.csv", 20, rate=200.0, **one)
    chk = _write(tmp_path / "chk.csv", 30, **one)
    res = analyse_pool(_recs(a, b, c), candidates=("wls",), predict_drift="1,10",
                       check=_recs(chk)[0], warmup="0")
    d = res.to_dict()
    assert d["pooled"] and d["pool_kind"] == "runs" and len(d["logs"]) == 3
    assert d["between_log_dof"] == 2
    assert "Student's t = 4.3" in res.tables()[-1][0]
    assert d["logs"][1]["units"] == {"gx": "rps"}
    assert d["logs"][2]["rate_hz"] == pytest.approx(200.0)
    for ax in d["axes"]:
        logs = ax["logs"]
        assert [lg["qn_pooled"] for lg in logs] == [True, True, False]
        # the rps log's N, read in the pool's unit, is of the truth's size (0.30 deg/sqrt h)
        assert 0.27 < logs[1]["N"]["value"] < 0.33
        assert ax["between_logs"]["verdict"] in ("near-stationary", "differ beyond sampling")
        assert ax["model_choice"]["chosen"] == "wls"
        n = ax["terms"]["N"]
        assert n["ci"][0] <= ax["ci_fit"]["N"][0] and n["ci"][1] >= ax["ci_fit"]["N"][1]
        assert len(ax["drift_prediction"]["check"]["inside_rms_ci"]) == 2
        # the pooled interval carries the measured between-log spread: no one-log caveat
        assert "between_logs" not in ax["drift_prediction"]["check"]


def test_a_log_missing_axes_is_refused_naming_it(tmp_path):
    a = _write(tmp_path / "a.csv", 0, hours=0.05)
    b = _write(tmp_path / "b.csv", 10, hours=0.05, axes=("gx",))
    with pytest.raises(InputError, match="axes gy missing") as e:
        analyse_pool(_recs(a, b), candidates=("wls",))
    assert str(e.value.path).endswith("b.csv")


def test_a_column_of_another_quantity_is_refused_naming_it(tmp_path):
    a = _write(tmp_path / "a.csv", 0, hours=0.05)
    b = _write(tmp_path / "b.csv", 10, hours=0.05, rename={"gy": "gy_mps2"})
    with pytest.raises(InputError, match="gy_mps2.*expected a angular_rate") as e:
        analyse_pool(_recs(a, b), candidates=("wls",))
    assert str(e.value.path).endswith("b.csv")


def test_a_log_that_is_not_static_is_refused_before_any_fit(tmp_path):
    a = _write(tmp_path / "a.csv", 0, hours=0.1)
    b = _write(tmp_path / "b.csv", 10, hours=0.1, moving=True)
    with pytest.raises(InputError, match="cannot join the pool: column 'gx_dph'") as e:
        analyse_pool(_recs(a, b), candidates=("wls",), warmup="0")
    assert str(e.value.path).endswith("b.csv")


def test_a_term_read_nowhere_keeps_a_finite_pooled_bound(tmp_path):
    """Two short logs of white noise alone: K is read on neither (a bound at 0 with no
    read range), yet the pooled K is a finite bound at least the pooled fit's own (its
    prior then the most within-log spread of any tested tau), never a bare '<='; the
    random walk a filter takes from it is finite too."""
    paths = []
    for seed in (1, 2):
        y = np.random.default_rng(seed).normal(0.0, 0.02, 30_000)
        p = tmp_path / f"w{seed}.csv"
        pd.DataFrame({"t_s": np.arange(y.size) / 100.0, "gx_rps": y}).to_csv(p, index=False)
        paths.append(str(p))
    res = analyse_pool(_recs(*paths), candidates=("wls",), warmup="0")
    ax = res.to_dict()["axes"][0]
    k = ax["terms"]["K"]
    assert k["bound"] == "upper" and np.isfinite(k["value"]) and k["value"] > 0
    assert k["value"] >= ax["ci_fit"]["K"][1] > 0
    assert ax["random_walk"]["bound"] == "upper" and ax["random_walk"]["value"] > 0


def test_a_check_log_too_short_for_a_horizon_is_named_and_that_horizon_not_judged(tmp_path):
    """A check log of 36 s holds no 10-s bias window plus 60-s horizon: a warning names
    it, and that horizon's inside/outside is None (not a miss), as for one log; a horizon
    past the longest pooled log is refused."""
    from inertialab.errors import DataQualityWarning

    one = dict(axes=("gx",), hours=0.2)
    a, b = _write(tmp_path / "a.csv", 0, **one), _write(tmp_path / "b.csv", 10, **one)
    short = _write(tmp_path / "short.csv", 30, axes=("gx",), hours=0.01)
    with pytest.warns(DataQualityWarning, match="short.csv .* no window .* 60 s"):
        res = analyse_pool(_recs(a, b), candidates=("wls",), predict_drift="1,60",
                           check=_recs(short)[0], warmup="0")
    chk = res.to_dict()["axes"][0]["drift_prediction"]["check"]
    assert chk["n_windows"][1] == 0 and chk["inside_rms_ci"][1] is None
    assert chk["inside_rms_ci"][0] in (True, False)
    with pytest.raises(InputError, match="horizon 1000 s"):
        analyse_pool(_recs(a, b), candidates=("wls",), predict_drift="1000", warmup="0")
