"""Noise-parameter exports: what we write, an independent YAML parser
(PyYAML and ruamel.yaml, both reading the documented grammar) reads back to the same
numbers, exactly."""

import math

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.export import NoiseParams, yaml_number
from inertialab.export.gtsam import gtsam_params, gtsam_preintegration_yaml
from inertialab.export.imu_utils import imu_utils_yaml, vins_imu_yaml, write_vins_imu
from inertialab.export.kalibr import kalibr_imu_yaml, write_kalibr_imu
from inertialab.export.openvins import openvins_imu_chain_yaml

# an ADIS-class MEMS IMU, continuous-time SI values (awkward digits on purpose)
P = dict(gyro_noise_density=1.8745e-04, gyro_random_walk=2.663e-05,
         accel_noise_density=1.8604e-03, accel_random_walk=4.3309e-04, rate_hz=200.0)


def _parsers():
    out = []
    try:
        import yaml

        out.append(("pyyaml", yaml.safe_load))
    except ImportError:
        pass
    try:
        from ruamel.yaml import YAML

        out.append(("ruamel", YAML(typ="safe", pure=True).load))
    except ImportError:
        pass
    if not out:
        pytest.skip("no YAML parser installed (PyYAML or ruamel.yaml, the latter comes with "
                    "the [formats] extra)")
    return out


def _load(text):
    """Parse with every parser; OpenCV's '%YAML:1.0' first line is not YAML, drop it as
    the tools' Python readers do."""
    if text.startswith("%YAML:1.0"):
        text = text.split("\n", 1)[1]
    docs = [load(text) for _, load in _parsers()]
    for d in docs[1:]:
        assert d == docs[0]
    return docs[0]


def test_yaml_numbers_round_trip_exactly():
    for x in (1e-05, 2.663e-05, 200.0, 1.0, 0.1 + 0.2, 123456789.123, 5e-324):
        s = yaml_number(x)
        for _, load in _parsers():
            assert load(f"v: {s}")["v"] == x


def test_kalibr_imu_yaml(tmp_path):
    d = _load(kalibr_imu_yaml(**P, rostopic="/imu/data"))
    assert d == {"accelerometer_noise_density": P["accel_noise_density"],
                 "accelerometer_random_walk": P["accel_random_walk"],
                 "gyroscope_noise_density": P["gyro_noise_density"],
                 "gyroscope_random_walk": P["gyro_random_walk"],
                 "rostopic": "/imu/data", "update_rate": 200.0}
    f = tmp_path / "imu.yaml"
    write_kalibr_imu(f, **P)
    assert _load(f.read_text())["gyroscope_random_walk"] == P["gyro_random_walk"]
    with pytest.raises(InputError, match="rostopic"):
        kalibr_imu_yaml(**P, rostopic="/imu\nevil: 1")


def test_vins_and_imu_utils_yaml(tmp_path):
    d = _load(vins_imu_yaml(**P, g_norm=9.80511))
    assert (d["acc_n"], d["acc_w"], d["gyr_n"], d["gyr_w"], d["g_norm"]) == (
        P["accel_noise_density"], P["accel_random_walk"], P["gyro_noise_density"],
        P["gyro_random_walk"], 9.80511)
    per = {ax: {"gyr_n": 1e-4 * (i + 1), "gyr_w": 1e-5 * (i + 1), "acc_n": 1e-3 * (i + 1),
                "acc_w": 1e-4 * (i + 1)} for i, ax in enumerate("xyz")}
    u = _load(imu_utils_yaml(**P, name="adis16448", per_axis=per))
    assert u["type"] == "IMU" and u["name"] == "adis16448"
    assert u["Gyr"]["avg-axis"] == {"gyr_n": P["gyro_noise_density"],
                                    "gyr_w": P["gyro_random_walk"]}
    assert u["Acc"]["avg-axis"] == {"acc_n": P["accel_noise_density"],
                                    "acc_w": P["accel_random_walk"]}
    assert u["Acc"]["z-axis"] == {"acc_n": per["z"]["acc_n"], "acc_w": per["z"]["acc_w"]}
    assert u["Gyr"]["x-axis"] == {"gyr_n": 1e-4, "gyr_w": 1e-5}
    f = tmp_path / "vins.yaml"
    write_vins_imu(f, **P)
    assert f.read_text().startswith("%YAML:1.0\n")


def test_openvins_imu_chain_with_intrinsics():
    rng = np.random.default_rng(4)
    Tw = np.eye(3) + 1e-3 * np.triu(rng.normal(size=(3, 3)))   # upper-triangular, as OpenVINS
    Ta = np.eye(3) + 2e-3 * np.tril(rng.normal(size=(3, 3)))
    Tg = 1e-4 * rng.normal(size=(3, 3))
    c, s = math.cos(0.01), math.sin(0.01)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    d = _load(openvins_imu_chain_yaml(**P, Tw=Tw, Ta=Ta, Tg=Tg, R_IMUtoGYRO=R,
                                      time_offset_s=-0.0025, model="kalibr"))["imu0"]
    np.testing.assert_array_equal(np.array(d["Tw"]), Tw)
    np.testing.assert_array_equal(np.array(d["Ta"]), Ta)
    np.testing.assert_array_equal(np.array(d["Tg"]), Tg)
    np.testing.assert_array_equal(np.array(d["R_IMUtoGYRO"]), R)
    np.testing.assert_array_equal(np.array(d["R_IMUtoACC"]), np.eye(3))
    np.testing.assert_array_equal(np.array(d["T_i_b"]), np.eye(4))
    assert d["gyroscope_noise_density"] == P["gyro_noise_density"]
    assert d["update_rate"] == 200.0 and d["time_offset"] == -0.0025 and d["model"] == "kalibr"
    with pytest.raises(InputError, match="R_IMUtoACC' must be a rotation"):
        openvins_imu_chain_yaml(**P, R_IMUtoACC=2 * np.eye(3))
    with pytest.raises(InputError, match="NaN"):
        openvins_imu_chain_yaml(**P, Tw=np.full((3, 3), np.nan))


def test_gtsam_preintegration_params():
    d = _load(gtsam_preintegration_yaml(**P, g=9.81))
    ref = gtsam_params(**P, g=9.81)
    for k, v in ref.items():
        np.testing.assert_array_equal(np.array(d[k]), v)
    # covariance = density^2 (continuous time), independent of the rate
    assert d["gyroscopeCovariance"][1][1] == P["gyro_noise_density"] ** 2
    assert d["biasAccCovariance"][2][2] == P["accel_random_walk"] ** 2
    assert d["gyroscopeCovariance"][0][1] == 0.0 and d["n_gravity"] == [0.0, 0.0, -9.81]


@pytest.mark.parametrize("bad", [dict(rate_hz=0.0), dict(gyro_noise_density=float("nan")),
                                 dict(accel_random_walk=-1.0), dict(gyro_random_walk="x")])
def test_non_finite_or_non_positive_numbers_are_refused(bad):
    with pytest.raises(InputError, match="argument '"):
        kalibr_imu_yaml(**{**P, **bad})


def test_discretisation_follows_kalibr():
    n = NoiseParams(**P)
    d = n.discrete()
    assert d["gyro_sigma_d"] == pytest.approx(P["gyro_noise_density"] * math.sqrt(200.0))
    assert d["accel_sigma_bd"] == pytest.approx(P["accel_random_walk"] / math.sqrt(200.0))
