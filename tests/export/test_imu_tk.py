"""export.imu_tk: 21 numbers per triad, X' = T K (X - B)."""

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.export.imu_tk import read_imu_tk, to_imu_tk, write_imu_tk


def test_grammar_round_trip_gives_our_numbers(field_model, tmp_path):
    model, acc, gyr = field_model
    paths = write_imu_tk(model, str(tmp_path / "imu"))
    assert [p.rsplit("/", 1)[-1] for p in paths] == ["imu_acc.calib", "imu_gyro.calib"]
    T, K, B = read_imu_tk(open(paths[0]).read())
    assert np.allclose(np.diag(T), 1) and np.allclose(K, np.diag(np.diag(K)))
    assert np.allclose(((acc - B) @ (T @ K).T), model.apply(acc), rtol=1e-14, atol=1e-12)
    Tg, Kg, Bg = read_imu_tk(open(paths[1]).read())
    assert np.allclose(((gyr - Bg) @ (Tg @ Kg).T), model.apply_gyro(gyr), rtol=1e-14, atol=1e-14)
    # the file is two blank-line-separated 3x3 blocks and a 3-vector, as imu_tk saves it
    blocks = open(paths[0]).read().strip().split("\n\n")
    assert [len(b.splitlines()) for b in blocks] == [3, 3, 3]


def test_g_sensitivity_needs_consent(ferraris_model):
    model, acc, gyr = ferraris_model
    with pytest.raises(InputError, match="drop_g_sensitivity"):
        to_imu_tk(model)
    assert to_imu_tk(model, drop_g_sensitivity=True)["gyro"] is not None


def test_flagged_model_is_refused(field_model):
    import dataclasses

    model = dataclasses.replace(field_model[0], flags=["implausible: kx"])
    with pytest.raises(InputError, match="flagged"):
        to_imu_tk(model)
    assert to_imu_tk(model, force=True)["acc"]
