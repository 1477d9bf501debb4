"""The ``clock_log`` record kind: clock records through the one front
door ``read_record``, then ``workflows.allan.read_clock`` on top of it."""

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError
from inertialab.io import read_record
from inertialab.io.schemas import SCHEMAS
from inertialab.workflows import allan as W


def _x(n=64, seed=5):
    return np.cumsum(np.random.default_rng(seed).standard_normal(n)) * 1e-9  # s


def test_schema_registered():
    s = SCHEMAS["clock_log"]
    assert s.time_column == "t_s" and s.keep_unknown and s.min_rows == 3


def test_read_record_keeps_any_column_and_gaps(tmp_path):
    x = _x()
    p = tmp_path / "clk.csv"
    df = pd.DataFrame({"t_s": np.arange(x.size) * 2.0, "TIC reading": x * 1e9,
                       "phase": x})
    df.loc[10, "phase"] = np.nan  # an empty cell is a missing sample, not an error
    df.to_csv(p, index=False)
    rec = read_record(p, "clock_log")
    assert rec.kind == "clock_log" and rec.n == x.size
    assert "tic reading" in rec.data.columns and np.isnan(rec.data["phase"][10])
    assert "timestamps" in rec.meta  # the front door's time-stamp audit ran


@pytest.mark.parametrize("unit, scale, nominal", [("ppm", 1e6, None), ("ppb", 1e9, None),
                                                  ("hz", None, 10e6), ("1", 1.0, None)])
def test_frequency_units_end_to_end(tmp_path, unit, scale, nominal):
    y = np.random.default_rng(2).standard_normal(200) * 1e-11
    vals = (nominal * (1 + y)) if unit == "hz" else y * scale
    p = tmp_path / "f.csv"
    pd.DataFrame({"Counter A": vals}).to_csv(p, index=False)
    log = W.read_clock(p, input="frequency", column="counter a", unit=unit, rate_hz=1.0,
                       nominal_hz=nominal)
    assert log.kind == "clock" and log.unit == "1" and log.input == "rate"
    np.testing.assert_allclose(log.values, y, rtol=0, atol=1e-15)  # Hz: 1e-16 rounding


def test_phase_units_suffix_and_sidecar_rate(tmp_path):
    x = _x(50)
    p = tmp_path / "ph.csv"
    pd.DataFrame({"phase_ns": x * 1e9}).to_csv(p, index=False)
    (tmp_path / "ph.meta.json").write_text('{"fs_hz": 0.5}')
    log = W.read_clock(p, input="phase")
    assert log.rate_hz == pytest.approx(0.5) and log.column == "phase_ns"
    np.testing.assert_allclose(log.values, x, rtol=1e-12)


def test_bad_inputs_name_file_column_row(tmp_path):
    p = tmp_path / "bad.csv"
    pd.DataFrame({"t_s": [0.0, 1.0, 1.0, 3.0], "phase": [0, 1e-9, 2e-9, 3e-9]}).to_csv(
        p, index=False)
    with pytest.raises(InputError, match="t_s") as e:
        W.read_clock(p, input="phase")
    assert "bad.csv" in str(e.value)
    short = tmp_path / "short.csv"
    pd.DataFrame({"phase": [0.0, 1e-9]}).to_csv(short, index=False)
    with pytest.raises(InputError, match="too few samples"):
        W.read_clock(short, input="phase", rate_hz=1.0)
    with pytest.raises(InputError, match="no such file"):
        W.read_clock(tmp_path / "none.csv", input="phase")
    t = tmp_path / "t.csv"
    pd.DataFrame({"t_s": [0.0, 1.0, float("nan"), 3.0], "phase": [0.0, 1.0, 2.0, 3.0]}
                 ).to_csv(t, index=False)
    with pytest.raises(InputError, match="row"):
        W.read_clock(t, input="phase")
