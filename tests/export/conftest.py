"""Calibrations to export: a Ferraris model (gyro with g-sensitivity, deg/s raw) and a
field-calibration model (rad/s raw, no g-sensitivity)."""

import numpy as np
import pytest

from inertialab.sim import triaxial_poses as tp
from inertialab.sim.ferraris_session import simulate_ferraris


@pytest.fixture(scope="package")
def ferraris_model():
    from inertialab.calib import ferraris as fr

    rec = simulate_ferraris(seed=5, placement_deg=0.5)
    d = rec.data
    acc = d[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy()
    gyr = d[["gx_dps", "gy_dps", "gz_dps"]].to_numpy()
    fit = fr.fit_ferraris(acc, gyr, 102.4, fr.detect_sections(acc, gyr, 102.4).sections, g=9.81)
    return fr.to_model(fit, acc_unit="mps2", gyro_unit="dps", g=9.81), acc[::97], gyr[::97]


@pytest.fixture(scope="package")
def field_model():
    from inertialab.workflows import triaxial as wt

    raw = tp.simulate("rawlog62-gyro", seed=1)
    d = raw.data
    data = wt.raw_log_data(d["t_s"].to_numpy(), d[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy(),
                           raw.meta, suffix="mps2")
    run = wt.calibrate_record_data(data, gyro_raw=d[["gx_rps", "gy_rps", "gz_rps"]].to_numpy(),
                                   t=d["t_s"].to_numpy(), gyro_suffix="rps", meta=raw.meta)
    rng = np.random.default_rng(0)
    return run.model, rng.normal(0, 5, (20, 3)), rng.normal(0, 0.5, (20, 3))
