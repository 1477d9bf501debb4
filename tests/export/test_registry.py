"""The exporter registry: every noise target written from one six-axis analysis and read
back by a YAML parser to the worst-axis numbers; upper-bound random walks said in the
comments; no value or comment can inject a key; every calibration target reachable."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

import inertialab.export as ex
from inertialab.errors import InputError
from inertialab.export.yaml_text import comment_lines, dump_yaml


def _axis(name, kind, nd, rw, bound=False):
    return SimpleNamespace(axis=name, kind=kind, noise_density=nd, random_walk=rw,
                           random_walk_bound=bound)


@pytest.fixture
def imu():
    """A six-axis analysis as the workflow returns it (attributes only)."""
    axes = [_axis("gx", "gyro", 1.1e-4, 2.0e-6), _axis("gy", "gyro", 1.3e-4, 2.5e-6, True),
            _axis("gz", "gyro", 1.2e-4, 2.2e-6), _axis("ax", "accel", 1.6e-3, 3.1e-4),
            _axis("ay", "accel", 1.9e-3, 2.9e-4), _axis("az", "accel", 1.7e-3, 3.3e-4)]
    return SimpleNamespace(axes=tuple(axes), rate_hz=200.0)


def _load(text):
    if text.startswith("%YAML:1.0"):
        text = text.split("\n", 1)[1]
    return yaml.safe_load(text)


def test_targets_are_declared_once_per_kind():
    assert ex.targets("noise") == ("kalibr", "openvins", "vins", "imu_utils", "gtsam", "ros")
    assert ex.targets("calibration") == ("imucal", "imu_tk", "kalibr")
    assert ex.targets("thermal") == ("c99",)
    keys = [(e.kind, e.target) for e in ex.EXPORTERS]
    assert len(keys) == len(set(keys))
    for e in ex.EXPORTERS:
        assert (e.text is None) != (e.write is None) and e.tool and e.suffix.startswith(".")
    with pytest.raises(InputError, match="one of kalibr, openvins, vins, imu_utils, gtsam, ros"):
        ex.get("noise", "matlab")


@pytest.mark.parametrize("target", ["kalibr", "openvins", "vins", "imu_utils", "gtsam", "ros"])
def test_every_noise_target_reads_back_the_worst_axis(imu, target, tmp_path):
    path = tmp_path / f"{target}.yaml"
    assert ex.export_noise(imu, target, path) == [str(path)]
    text = path.read_text()
    d = _load(text)
    gn, gw, an, aw = 1.3e-4, 2.5e-6, 1.9e-3, 3.3e-4   # largest of each sensor's axes
    got = {"kalibr": lambda: (d["gyroscope_noise_density"], d["gyroscope_random_walk"],
                              d["accelerometer_noise_density"], d["accelerometer_random_walk"]),
           "openvins": lambda: tuple(d["imu0"][k] for k in (
               "gyroscope_noise_density", "gyroscope_random_walk",
               "accelerometer_noise_density", "accelerometer_random_walk")),
           "vins": lambda: (d["gyr_n"], d["gyr_w"], d["acc_n"], d["acc_w"]),
           "imu_utils": lambda: (d["Gyr"]["avg-axis"]["gyr_n"], d["Gyr"]["avg-axis"]["gyr_w"],
                                 d["Acc"]["avg-axis"]["acc_n"], d["Acc"]["avg-axis"]["acc_w"]),
           "gtsam": lambda: tuple(math.sqrt(d[k][0][0]) for k in (
               "gyroscopeCovariance", "biasOmegaCovariance", "accelerometerCovariance",
               "biasAccCovariance")),
           "ros": lambda: tuple(d["imu"][k] for k in (
               "gyroscope_noise_density", "gyroscope_random_walk",
               "accelerometer_noise_density", "accelerometer_random_walk"))}[target]()
    assert got == pytest.approx((gn, gw, an, aw), rel=1e-15)
    # gy's random walk is an upper bound: the file says so for the gyro, not the accel
    assert "gyroscope random walk is an upper bound" in text
    assert "accelerometer random walk is an upper bound" not in text
    assert "Continuous-time" in text


def test_ros_per_axis_and_imu_utils_per_axis(imu):
    d = _load(ex.noise_text(imu, "ros", namespace="imu0"))["imu0"]
    assert d["per_axis"]["gy"] == {"noise_density": 1.3e-4, "random_walk": 2.5e-6,
                                   "random_walk_bound": True}
    u = _load(ex.noise_text(imu, "imu_utils", name="adis"))
    assert u["name"] == "adis" and u["Acc"]["y-axis"] == {"acc_n": 1.9e-3, "acc_w": 2.9e-4}


@pytest.mark.parametrize("topic", ["/imu\nevil: 1", "/imu{a: 1}", "/imu: x", "", "a b"])
def test_a_hostile_rostopic_is_refused(imu, topic, tmp_path):
    for target in ("kalibr", "openvins", "vins"):
        with pytest.raises(InputError, match="argument 'rostopic'|argument 'imu_topic'"):
            ex.export_noise(imu, target, tmp_path / "x.yaml", rostopic=topic)
    assert not (tmp_path / "x.yaml").exists()


def test_the_serialiser_keeps_any_text_one_value():
    hostile = "/imu\nevil: 1\n{x: [1, 2]}\n# c"
    text = dump_yaml({"rostopic": hostile, "n": 1.5}, comments=["method x\nimu1: injected"])
    assert yaml.safe_load(text) == {"rostopic": hostile, "n": 1.5}
    assert all(line.startswith("#") for line in comment_lines(["a\nb: 1"]))


def test_gyro_only_log_kalibr_writes_null_others_refuse(tmp_path):
    only = SimpleNamespace(axes=(_axis("gz", "gyro", 1e-4, 2e-6, True),), rate_hz=100.0)
    d = _load(ex.noise_text(only, "kalibr"))
    assert d["accelerometer_noise_density"] is None and d["gyroscope_noise_density"] == 1e-4
    with pytest.raises(InputError, match="GTSAM needs gyro and accelerometer"):
        ex.noise_text(only, "gtsam")


@pytest.mark.parametrize("target", ["imucal", "imu_tk", "kalibr"])
def test_every_calibration_target_writes(ferraris_model, target, tmp_path):
    model, acc, gyr = ferraris_model
    paths = ex.export_calibration(model, target, tmp_path / "cal", drop_g_sensitivity=True)
    assert paths and all(np.size(open(p).read()) for p in paths)


def test_method_text_in_a_kalibr_comment_cannot_inject(ferraris_model, tmp_path):
    import dataclasses

    model = dataclasses.replace(ferraris_model[0], method="ferraris\nimu1: {x: 1}")
    ex.export_calibration(model, "kalibr", tmp_path / "k.yaml")
    assert set(yaml.safe_load((tmp_path / "k.yaml").read_text())) == {"imu0"}
