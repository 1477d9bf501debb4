"""export.imucal: imucal's v2 JSON, read back by imucal itself when installed and by
its documented formulas always."""

import json

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.export.imucal import imucal_apply, to_imucal, write_imucal


def ours(model, acc, gyr):
    a = model.apply(acc)
    return a, np.rad2deg(model.apply_gyro(gyr, acc=a))


@pytest.mark.parametrize("which", ["ferraris_model", "field_model"])
def test_documented_formulas_give_our_numbers(which, request):
    model, acc, gyr = request.getfixturevalue(which)
    d = to_imucal(model)
    assert d["cal_type"] == "Ferraris" and d["_format_version"] == "2.0.0"
    assert set(d) == {"acc_unit", "gyr_unit", "from_acc_unit", "from_gyr_unit", "comment", "K_a",
                      "R_a", "b_a", "K_g", "R_g", "K_ga", "b_g", "cal_type", "_format_version"}
    K = np.asarray(d["K_a"])
    assert np.allclose(K, np.diag(np.diag(K))) and np.allclose(np.linalg.norm(d["R_a"], axis=1), 1)
    a, w = imucal_apply(d, acc, gyr)
    a0, w0 = ours(model, acc, gyr)
    assert np.allclose(a, a0, rtol=1e-12, atol=1e-12)
    assert np.allclose(w, w0, rtol=1e-10, atol=1e-10)


def test_imucal_itself_loads_and_applies_it(ferraris_model, tmp_path):
    imucal = pytest.importorskip("imucal")  # noqa: F841 - imucal 2.6 reads format 2.0.0
    from imucal.management import load_calibration_info

    model, acc, gyr = ferraris_model
    path = tmp_path / "cal.json"
    write_imucal(model, path)
    info = load_calibration_info(path)
    a, w = info.calibrate(acc, gyr, acc_unit="m/s^2", gyr_unit="deg/s")
    a0, w0 = ours(model, acc, gyr)
    assert np.allclose(a, a0, atol=1e-12) and np.allclose(w, w0, atol=1e-10)


def test_accelerometer_only_model_is_refused():
    from inertialab.calib.triaxial import calibrate
    from inertialab.calib.triaxial_session import to_model
    from inertialab.sim import triaxial_poses as tp
    from inertialab.workflows.triaxial import static_data_from_frame

    rec = tp.simulate("turntable62", seed=0)
    sd = static_data_from_frame(rec.data, rec.meta)
    m = to_model(calibrate(sd.a, ref=sd.ref, objective="scalar", g=sd.g), sd)
    with pytest.raises(InputError, match="no gyro block"):
        to_imucal(m)
    json.dumps(to_imucal.__doc__)  # documented
