"""Unit conversions against hand-computed values."""

import math

import numpy as np
import pytest

from inertialab import InputError
from inertialab import units as u


def test_rate_conversions():
    assert u.convert(1.0, "dph", "rps") == pytest.approx(math.pi / 180 / 3600, rel=1e-15)
    assert u.convert(1.0, "dps", "dph") == pytest.approx(3600.0, rel=1e-15)
    assert u.rps_to_dph(u.dph_to_rps(7.5)) == pytest.approx(7.5, rel=1e-15)


def test_gravity_units_use_local_g():
    assert u.convert(1.0, "g", "mps2") == 9.80665
    assert u.convert(1.0, "g", "mps2", g_local=9.8) == 9.8
    assert u.convert(1000.0, "ug", "mg") == pytest.approx(1.0)
    assert u.convert(1.0, "mg", "mps2", g_local=9.8) == pytest.approx(9.8e-3)
    # ppm is a ratio, not an acceleration
    with pytest.raises(InputError, match="cannot convert"):
        u.convert(1.0, "ppm", "ug")


def test_noise_units():
    # 1 deg/sqrt(h) = (pi/180)/60 rad/sqrt(s)
    assert u.convert(1.0, "deg/sqrt(h)", "rad/s/sqrt(Hz)") == pytest.approx(math.pi / 180 / 60)
    # 1 ug/sqrt(Hz) with standard g = 9.80665e-6 m/s^2/sqrt(Hz) = 9.80665e-6*60 m/s/sqrt(h)
    assert u.convert(1.0, "ug/sqrt(Hz)", "m/s/sqrt(h)") == pytest.approx(9.80665e-6 * 60)
    assert u.convert(1.0, "deg/h/sqrt(h)", "rad/s/sqrt(s)") == pytest.approx(
        math.pi / 180 / 3600 / 60)
    assert u.convert(3600.0, "arcsec", "deg") == pytest.approx(1.0)


def test_lsb_round_trip_and_arrays():
    x = np.array([0.0, 16384.0, -16384.0]) + 32768
    g = u.lsb_to(x, 16384.0, offset_lsb=32768)
    np.testing.assert_allclose(g, [0.0, 1.0, -1.0])
    np.testing.assert_allclose(u.to_lsb(g, 16384.0, offset_lsb=32768), x)
    with pytest.raises(InputError):
        u.lsb_to(x, 0.0)


def test_suffixes_and_unknown_units():
    assert u.split_suffix("sf_ma_per_g") == ("sf", "ma_per_g")
    assert u.split_suffix("temp_meas_C") == ("temp_meas", "c")
    assert u.split_suffix("pos_index") == ("pos_index", None)
    with pytest.raises(InputError, match="unknown unit"):
        u.lookup("furlong")
    with pytest.raises(InputError, match="expected a angular_rate"):
        u.unit_suffix_or_error("rate_mps2", dimension_="angular_rate")


def test_normal_gravity_matches_published_values():
    # WGS-84 normal gravity: equator 9.7803253359, pole 9.8321849378 (NIMA TR8350.2)
    assert u.normal_gravity(0.0) == pytest.approx(9.7803253359, abs=1e-9)
    assert u.normal_gravity(90.0) == pytest.approx(9.8321849378, abs=1e-9)
    # free-air gradient about -3.086e-6 s^-2
    assert u.normal_gravity(45.0, 1000.0) - u.normal_gravity(45.0) == pytest.approx(-3.086e-3, rel=2e-3)
