"""workflows.thermal_imu: ``thermal fit``'s Config is the IMU fit's settings, with the IMU
fit's defaults for what the user did not give; the JSON ``settings`` it writes."""

from __future__ import annotations

import json

import pytest

from inertialab.calib.thermal_imu import FitSettings, fit_imu_model
from inertialab.errors import InputError
from inertialab.workflows.thermal import FitConfig
from inertialab.workflows.thermal_imu import fit_settings, imu_config, run_imu_fit


def test_a_setting_not_given_takes_the_imu_default():
    # the study's defaults are iafsa-scm-anfis, 150 epochs, 10 fish, 30 generations
    c = imu_config(FitConfig(seed=3, fish=2), given={"fish"})
    assert isinstance(c, FitConfig)
    assert (c.method, c.epochs, c.fish, c.generations, c.seed) == ("poly", 50, 2, 5, 3)
    c = imu_config(FitConfig(method="scm-anfis", epochs=4), {"method", "epochs"})
    assert (c.method, c.epochs, c.fish, c.generations) == ("scm-anfis", 4, 5, 5)
    with pytest.raises(InputError, match="argument 'method'"):
        imu_config(FitConfig(method="anfis"), {"method"})
    with pytest.warns(DeprecationWarning, match="imu_config"):
        assert fit_settings(FitConfig(seed=3, fish=2), {"fish"}) == FitSettings(fish=2, seed=3)


def test_run_takes_the_command_config_and_writes_the_settings_used():
    from inertialab.io.formats.thermal_logs import streams_from_frame
    from inertialab.sim.thermal_imu import simulate

    log = streams_from_frame(simulate(2, rate_hz=0.2, n_instances=1).frame)
    res = run_imu_fit(log, imu_config(FitConfig(seed=3, fish=2), {"fish"}))
    assert res.settings == {"imu": True, "method": "poly", "bin_s": 5.0, "max_order": 7,
                            "min_span_c": 10.0, "n_blocks": 6, "seed": 3}
    same = fit_imu_model(log, FitSettings(seed=3))
    assert json.dumps(res.fit.model.to_dict()) == json.dumps(same.model.to_dict())
