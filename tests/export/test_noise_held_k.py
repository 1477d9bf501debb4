"""A bias random walk held by a Gauss-Markov correlation time: every noise export keeps
the random-walk density as the value and says so, with the time, in its comments."""

from types import SimpleNamespace

import pytest
import yaml

import inertialab.export as ex
from inertialab.export.noise_params import noise_params


def _axis(name, kind, rw, t_s=None):
    return SimpleNamespace(axis=name, kind=kind, noise_density=1e-3, random_walk=rw,
                           random_walk_bound=False, random_walk_t_s=t_s)


@pytest.fixture
def imu():
    axes = [_axis("gx", "gyro", 2e-6), _axis("gy", "gyro", 3e-6), _axis("gz", "gyro", 1e-6),
            _axis("ax", "accel", 3e-4, 414.0), _axis("ay", "accel", 5e-4, 73.7),
            _axis("az", "accel", 2e-4)]
    return SimpleNamespace(axes=tuple(axes), rate_hz=100.0)


def test_params_carry_the_held_axes(imu):
    p = noise_params(imu)
    assert p.accel_random_walk == 5e-4 and p.gyro_random_walk == 3e-6
    assert p.accel_random_walk_t_s == (("ax", 414.0), ("ay", 73.7))
    assert p.gyro_random_walk_t_s == ()


@pytest.mark.parametrize("target", ex.targets("noise"))
def test_every_noise_file_names_the_time(imu, target, tmp_path):
    path = tmp_path / "n.yaml"
    ex.export_noise(imu, target, path)
    text = path.read_text()
    assert ("accelerometer bias random walk is held by a first-order Gauss-Markov "
            "correlation time (ax T = 414 s, ay T = 73.7 s)") in " ".join(
                line.lstrip("# ") for line in text.splitlines())
    assert "gyroscope bias random walk is held" not in text
    body = text.split("\n", 1)[1] if text.startswith("%YAML:1.0") else text
    assert yaml.safe_load(body)  # the comments leave the document readable


def test_an_analysis_without_the_attribute_exports_as_before():
    axes = tuple(SimpleNamespace(axis=a, kind=k, noise_density=1e-3, random_walk=1e-5,
                                 random_walk_bound=False)
                 for a, k in (("gx", "gyro"), ("ax", "accel")))
    p = noise_params(SimpleNamespace(axes=axes, rate_hz=100.0))
    assert p.bound_comments() == []
