"""Six-axis noise and Kalibr/ROS export against a simulated IMU of known densities."""

import math
import re

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError
from inertialab.io import validate_frame
from inertialab.workflows.imu_noise import analyse_imu, analyse_record, export_yaml

FS = 100.0
N_SAMPLES = 200_000          # 2000 s
# truth, continuous time, SI: white-noise density and bias random walk
NG, KG = 2e-3, 2e-4          # rad/s/sqrt(Hz), rad/s^2/sqrt(Hz)
NA, KA = 3e-3, 4e-4          # m/s^2/sqrt(Hz), m/s^3/sqrt(Hz)
G = 9.80665


def _axis(rng, n_density, k_rw):
    # discrete: white sd = N sqrt(fs); bias steps sd = K sqrt(dt)
    return (n_density * math.sqrt(FS) * rng.standard_normal(N_SAMPLES)
            + np.cumsum(k_rw / math.sqrt(FS) * rng.standard_normal(N_SAMPLES)))


@pytest.fixture(scope="module")
def imu():
    rng = np.random.default_rng(2024)
    data = {"t_s": np.arange(N_SAMPLES) / FS}
    for a in "xyz":   # gyro written in deg/h, accelerometer in mg: conversions exercised
        data[f"g{a}_dph"] = _axis(rng, NG, KG) * 180 / math.pi * 3600
    for a in "xyz":
        # at rest: gravity (1000 mg) on z; a constant offset leaves every deviation as is
        data[f"a{a}_mg"] = _axis(rng, NA, KA) / G * 1000 + (1000.0 if a == "z" else 0.0)
    rec = validate_frame(pd.DataFrame(data), "gyro_log", path="imu.csv")
    return analyse_record(rec)


def test_six_axes_against_truth(imu):
    assert [a.axis for a in imu.axes] == ["gx", "gy", "gz", "ax", "ay", "az"]
    assert imu.rate_hz == pytest.approx(FS, rel=1e-9)
    for a in imu.axes:
        n_true, k_true = (NG, KG) if a.kind == "gyro" else (NA, KA)
        # the white-noise level is fitted over taus with EDF in the 1e4-1e5 range: 3 %
        assert a.noise_density == pytest.approx(n_true, rel=0.03)
        # the random walk rests on the few longest taus (EDF ~ 5-20): a factor 1.6
        assert not a.random_walk_bound
        assert k_true / 1.6 < a.random_walk < k_true * 1.6


def test_numbers_are_the_noise_terms_converted_by_hand(imu):
    gx = imu.axis("gx")
    c = gx.terms.coefficients
    # N^2 = c_-1 in (deg/h)^2 s -> rad/s/sqrt(Hz): times pi/180/3600
    assert gx.noise_density == pytest.approx(math.sqrt(c[1]) * math.pi / 180 / 3600, rel=1e-12)
    # K^2 / 3 = c_1 in (deg/h)^2 / s -> rad/s^2/sqrt(Hz)
    assert gx.random_walk == pytest.approx(math.sqrt(3 * c[3]) * math.pi / 180 / 3600,
                                           rel=1e-12)
    # and the noise core's own N.density (rad/s/sqrt(Hz)) is the same number
    assert gx.noise_density == pytest.approx(gx.terms.N.density["value"], rel=1e-12)
    ax = imu.axis("ax")
    ca = ax.terms.coefficients
    # mg -> m/s^2: times g/1000
    assert ax.noise_density == pytest.approx(math.sqrt(ca[1]) * G / 1000, rel=1e-12)
    assert ax.random_walk == pytest.approx(math.sqrt(3 * ca[3]) * G / 1000, rel=1e-12)
    # ug/sqrt(Hz) in the noise core: 1e-6 g
    assert ax.noise_density == pytest.approx(ax.terms.N.density["value"] * 1e-6 * G, rel=1e-12)


def _yaml_numbers(text):
    return {k: float(v) for k, v in re.findall(r"^\s*([a-z_]+):\s*([-+0-9.eE]+)", text,
                                               flags=re.M)}


def test_kalibr_and_ros_export(imu):
    k = export_yaml(imu, "kalibr", rostopic="/imu/data")
    v = _yaml_numbers(k)
    assert v["gyroscope_noise_density"] == pytest.approx(
        max(imu.axis(a).noise_density for a in ("gx", "gy", "gz")), rel=1e-6)
    assert v["accelerometer_random_walk"] == pytest.approx(
        max(imu.axis(a).random_walk for a in ("ax", "ay", "az")), rel=1e-6)
    assert v["update_rate"] == 100.0 and "rostopic: /imu/data" in k
    assert "Continuous-time" in k and "sqrt(update_rate)" in k
    r = export_yaml(imu, "ros", namespace="imu0")
    assert "\nimu0:\n" in r
    rv = _yaml_numbers(r)
    for key in ("gyroscope_noise_density", "gyroscope_random_walk",
                "accelerometer_noise_density", "accelerometer_random_walk", "update_rate"):
        assert rv[key] == pytest.approx(v[key], rel=1e-12)
    assert "gx: {noise_density:" in r
    yaml = pytest.importorskip("yaml")
    assert yaml.safe_load(k)["gyroscope_random_walk"] == pytest.approx(v["gyroscope_random_walk"])
    assert yaml.safe_load(r)["imu0"]["per_axis"]["az"]["noise_density"] > 0
    with pytest.raises(InputError, match="must be one of kalibr, openvins"):
        export_yaml(imu, "matlab")


def test_short_record_flags_random_walk_bound():
    rng = np.random.default_rng(5)
    y = NG * math.sqrt(FS) * rng.standard_normal(5000)    # white only, 50 s
    res = analyse_imu({"gz": ("gz_rps", y, "rps")}, rate_hz=FS)
    gz = res.axis("gz")
    assert gz.random_walk_bound and np.isfinite(gz.random_walk)
    assert "upper bound" in export_yaml(res)
    assert gz.noise_density == pytest.approx(NG, rel=0.05)


def test_bad_input():
    with pytest.raises(InputError, match="no IMU axis"):
        analyse_imu({}, rate_hz=1.0)
    with pytest.raises(InputError, match="expected a angular_rate|angular_rate"):
        analyse_imu({"gx": ("gx_mps2", np.ones(100), "mps2")}, rate_hz=1.0)
    rec = validate_frame(pd.DataFrame({"t_s": np.arange(10.0), "rate_dph": np.arange(10.0)}),
                         "gyro_log")
    with pytest.raises(InputError, match="no IMU axis columns"):
        analyse_record(rec)


def _turning_rig(rng, n=60_000, fs=FS, tc=2.0):
    """A quiet gyro (white noise 5e-5 rad/s/sqrt(Hz), 0.17 deg/sqrt(h)) on a rig that
    turns: a rate of a few deg/s that changes with a 2-s correlation time (first-order
    Gauss-Markov), which dominates the curve from the first tau, as motion does in a
    flight log (a noisier gyro's white noise would hide the rise at the short taus, and
    the check, which reads the rising start of the curve, would not see it)."""
    a = math.exp(-1.0 / (fs * tc))
    e = rng.standard_normal(n) * 0.05 * math.sqrt(1 - a * a)   # 0.05 rad/s = 2.9 deg/s
    from scipy.signal import lfilter

    motion = lfilter([1.0], [1.0, -a], e)
    return 5e-5 * math.sqrt(fs) * rng.standard_normal(n) + motion


def test_moving_record_is_flagged_and_a_static_one_is_not(imu):
    # the static simulated IMU of the fixture gives no not-static warning; a turning rig
    # rises up to ~2 s and is named as not static, per column, by both entry points
    from inertialab.errors import DataQualityWarning
    from inertialab.noise.statistics.allan import oadev
    from inertialab.noise.terms.fit import not_static_reason
    from inertialab.workflows.allan import analyze, prepare_log

    for a in imu.axes:
        assert not_static_reason(a.deviation.taus_s, a.deviation.dev) is None
    rng = np.random.default_rng(5)
    y = _turning_rig(rng)
    r = oadev(y, rate_hz=FS)
    why = not_static_reason(r.taus_s, r.dev)
    assert why is not None and "not static" in why
    tau_p = float(re.search(r"tau = ([0-9.e+-]+) s", why).group(1))
    # a Gauss-Markov process peaks at 1.89 Tc (3.8 s here); the reported tau is where the
    # curve has begun to fall by slope -1/4, within two octaves after the peak
    assert 1.89 * 2.0 <= tau_p <= 4 * 1.89 * 2.0
    data = {"t_s": np.arange(y.size) / FS, "gx_rps": y}
    rec = validate_frame(pd.DataFrame(data), "gyro_log", path="rig.csv")
    with pytest.warns(DataQualityWarning, match="column 'gx_rps'.*not static"):
        analyze(prepare_log(rec))
    with pytest.warns(DataQualityWarning, match="column 'gx_rps'.*not static"):
        analyse_record(rec)


def test_axis_that_is_not_static_is_reported_not_refused():
    from inertialab.errors import DataQualityWarning

    # motion slower than the record: the axis gets status "not static" with the reason
    # and keeps its deviation; the other axes of the log are still analysed (one axis
    # does not abort the run)
    n = 20_000
    rng = np.random.default_rng(6)
    y = _turning_rig(rng, n=n, tc=20.0)   # 20-s turns, 200-s record
    quiet = rng.standard_normal(n) * 1e-3
    rec = validate_frame(pd.DataFrame({"t_s": np.arange(n) / FS, "gx_rps": y,
                                       "gy_rps": quiet}), "gyro_log", path="sway.csv")
    with pytest.warns(DataQualityWarning, match=r"column 'gx_rps'.*not static"):
        res = analyse_record(rec)
    gx, gy = res.axis("gx"), res.axis("gy")
    assert gx.status == "not static" and gx.terms is None
    assert "rises up to" in gx.reason or "white-noise floor" in gx.reason
    assert gx.deviation.dev.size > 3
    assert gy.status == "ok" and gy.terms is not None
    d = res.to_dict()["axes"][0]
    assert d["status"] == "not static" and "terms" not in d and "allan" in d
    # --no-terms: deviations only, every axis
    res = analyse_record(rec, terms=False)
    assert [a.status for a in res.axes] == ["no terms", "no terms"]
