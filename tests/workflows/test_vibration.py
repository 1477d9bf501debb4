"""Tests of the vibration workflow (spec 001 §3.7-3.11, §4)."""


import numpy as np
import pandas as pd
import pytest

from inertialab.errors import DataQualityWarning, InputError
from inertialab.sensors.gyro_vibration import bias_shift_dph
from inertialab.workflows.vibration import (
    VibrationModel,
    apply,
    prepare,
    run_from_frame,
)


def _frame(n1=400, n2=300, n3=300, fs=100.0, f=50.0, rate=None):
    n = n1 + n2 + n3
    on = np.zeros(n, dtype=np.int8)
    on[n1:n1 + n2] = 1
    fr = np.where(on == 1, f, 0.0)
    ph = np.where(np.arange(n) < n1, 1, np.where(on == 1, 2, 3)).astype(np.int8)
    x = np.zeros(n) if rate is None else rate
    return pd.DataFrame({"t_s": np.arange(n) / fs, "rate_dph": x, "vib_on": on,
                         "vib_freq_hz": fr, "vib_acc_g": 5.0 * on, "phase": ph})


# ------------------------------------------------------------------ loader checks (issue §6)

def test_run_from_frame_segments_phases():
    r = run_from_frame(_frame(), {"experiment": "fixed"})
    assert (r.k_on, r.k_off) == (400, 699) and r.fs_hz == pytest.approx(100.0, rel=1e-12)
    assert r.p1 == slice(0, 400) and r.p2 == slice(400, 700) and r.p3 == slice(700, 1000)
    assert r.experiment == "fixed"


def test_dtheta_input_and_unit_conversion():
    # dtheta in arcsec per sample: rate = dtheta/tau0 (1 (deg/h) s = 1 arcsec exactly)
    df = _frame().drop(columns=["rate_dph"])
    df["dtheta_arcsec"] = 0.01  # at 100 Hz -> 1 deg/h
    np.testing.assert_allclose(run_from_frame(df).rate_dph, 1.0)
    df = _frame().rename(columns={"rate_dph": "rate_dps"})
    df["rate_dps"] = 1.0 / 3600
    np.testing.assert_allclose(run_from_frame(df).rate_dph, 1.0, rtol=1e-12)


@pytest.mark.parametrize("mutate, match", [
    (lambda d: d.drop(columns=["vib_on"]), "no vibration phases"),
    (lambda d: d.assign(vib_on=0, vib_freq_hz=0.0, phase=1), "never 1"),
    (lambda d: d.drop(columns=["vib_freq_hz"]), "vib_freq_hz"),
    (lambda d: d.assign(vib_freq_hz=np.where(np.arange(len(d)) == 450, 0.0, d.vib_freq_hz)),
     "while vibrating"),
    (lambda d: d.assign(t_s=d.t_s + np.where(np.arange(len(d)) > 500, 0.02, 0.0)),
     r"2 sample\(s\) lost.*contiguous log"),
    (lambda d: d.assign(phase=np.where(np.arange(len(d)) == 10, 3, d.phase)), "phase"),
    (lambda d: d.assign(vib_on=np.where(np.arange(len(d)) == 500, 0, d.vib_on)), "contiguous"),
    (lambda d: d.drop(columns=["rate_dph"]), "rate column"),
])
def test_bad_records_are_input_errors(mutate, match):
    with pytest.raises(InputError, match=match):
        run_from_frame(mutate(_frame()), path="bad.csv")


def test_jitter_is_the_time_base_warning_not_an_error():
    # one jitter policy for every command: a warning with the figures, the mean rate
    from inertialab.errors import DataQualityWarning

    d = _frame()
    d["t_s"] = d["t_s"] + np.where(np.arange(len(d)) > 500, 0.003, 0.0)
    with pytest.warns(DataQualityWarning, match=r"jitter .* rows 502"):
        run = run_from_frame(d, path="jit.csv")
    t = d["t_s"].to_numpy()
    assert run.fs_hz == pytest.approx((t.size - 1) / (t[-1] - t[0]), rel=1e-12)


def test_vibration_from_the_first_sample_is_an_error():
    d = _frame()
    d["vib_on"] = np.where(np.arange(len(d)) < 700, 1, 0)
    d["vib_freq_hz"] = np.where(d["vib_on"] == 1, 50.0, 0.0)
    d = d.drop(columns=["phase"])
    with pytest.raises(InputError, match="P1 is empty"):
        run_from_frame(d)


def test_record_ending_in_vibration_warns():
    d = _frame(n3=0)
    with pytest.warns(DataQualityWarning, match="no P3"):
        r = run_from_frame(d.drop(columns=["phase"]))
    assert "P3" not in r.phase_slices()




# ------------------------------------------------------------------ verbs prepare / apply

def test_prepare_and_apply_on_a_record(tmp_path):
    # a sweep-like record with a known bias curve in P2; the model fitted on the exact
    # curve compensates the raw rate to the P1 level; apply() equals model.compensate()
    from inertialab.io import read_record, write_record

    fs, n1, n2, n3 = 100.0, 500, 4000, 500
    n = n1 + n2 + n3
    f = np.zeros(n)
    f[n1:n1 + n2] = np.linspace(5.0, 45.0, n2)
    on = (f > 0).astype(np.int8)
    rate = 3.0 + np.where(on == 1, bias_shift_dph(f), 0.0)
    df = pd.DataFrame({"t_s": np.arange(n) / fs, "rate_dph": rate, "vib_on": on,
                       "vib_freq_hz": f})
    write_record(df, tmp_path / "rec.csv", {"fs_hz": fs})
    rec = read_record(tmp_path / "rec.csv", "gyro_log")
    run = prepare(rec)
    assert (run.k_on, run.k_off, run.fs_hz) == (n1, n1 + n2 - 1, fs)
    grid = np.linspace(5.0, 45.0, 41)
    model = VibrationModel(poly_degree=4).fit(grid, bias_shift_dph(grid))
    out = apply(model, rec, apply_to="raw", model_path="m.json")
    assert list(out.data.columns) == ["t_s", "rate_dph", "rate_comp_dph", "vib_on",
                                      "vib_freq_hz"]
    np.testing.assert_array_equal(out.data["rate_comp_dph"].to_numpy(),
                                  model.compensate(rate, on, f, apply_to="raw"))
    # the RBF interpolates the exact curve: the compensated P2 sits at the P1 level
    assert abs(out.residual["delta_b"]) < 0.05
    assert out.meta["compensated_with"] == "m.json" and out.meta["apply_to"] == "raw"
    assert out.meta["compensation_model"] == "rbf"


def test_the_study_in_one_module_and_the_old_name_warns():
    """workflows/vibration.py holds the commands' settings and calls and starts without
    PyWavelets; vibration_run still answers, with a DeprecationWarning."""
    import importlib
    import subprocess
    import sys
    import warnings

    from inertialab.workflows import vibration

    code = ("import sys, inertialab.workflows.vibration; "
            "print(sorted(m for m in ('pywt', 'pandas', 'scipy') if m in sys.modules))")
    assert subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          check=True).stdout.strip() == "[]"
    sys.modules.pop("inertialab.workflows.vibration_run", None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = importlib.import_module("inertialab.workflows.vibration_run")
    assert old.run_fit is vibration.run_fit and old.FitConfig is vibration.FitConfig
    assert any(issubclass(w.category, DeprecationWarning) for w in caught)


def test_one_settings_class_with_the_flags_names():
    """FitConfig is the pipeline's settings too: the seed reaches the RBF by that name,
    level and spread are read as the flags give them; VibrationConfig (rng) warns and
    gives the same settings; a bad level or spread is one error naming the argument."""
    from inertialab.workflows import vibration

    cfg = vibration.FitConfig(level="auto", spread="validate", seed=4)
    assert (cfg.level_choice, cfg.spread_choice) == ("auto", "validate")
    assert vibration.FitConfig(level=7, spread=0.8).validate().level_choice == 7
    with pytest.warns(DeprecationWarning, match="FitConfig"):
        old = vibration.VibrationConfig(level="auto", spread="validate", rng=4)
    assert old == cfg
    for kw, name in (({"level": "12"}, "'level'"), ({"spread": "wide"}, "'spread'")):
        with pytest.raises(InputError, match=name):
            vibration.FitConfig(**kw).validate()
