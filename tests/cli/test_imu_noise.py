"""``inertialab allan --imu``: six axes of a vendor file, Kalibr export, gap handling."""

import json
import re
from pathlib import Path

import pytest

from tests.helpers import run_cli as run

VENDORS = Path(__file__).resolve().parents[2] / "docs" / "examples" / "vendors"




def test_vendor_file_six_axes_kalibr_export(tmp_path):
    y = tmp_path / "imu.yaml"
    res = run("allan", "--imu", VENDORS / "xsens.txt", "--map-file", VENDORS / "xsens.map.toml",
              "--export", "kalibr", y, "--json", "--out", tmp_path / "o")
    assert res.returncode == 0, res.stderr
    obj = json.loads(res.stdout)
    axes = obj["imu"]["axes"]
    assert [a["axis"] for a in axes] == ["gx", "gy", "gz", "ax", "ay", "az"]
    # the example's gyro is white noise of 1e-3 rad/s per sample at 100 Hz:
    # density 1e-3/sqrt(100) = 1e-4 rad/s/sqrt(Hz); 200 samples give ~10 % scatter
    for a in axes[:3]:
        assert a["noise_density"]["value"] == pytest.approx(1e-4, rel=0.3)
    text = y.read_text()
    vals = dict(re.findall(r"^([a-z_]+):\s*([-+0-9.eE]+)", text, flags=re.M))
    k = obj["imu"]["kalibr"]
    for key in ("gyroscope_noise_density", "accelerometer_noise_density",
                "gyroscope_random_walk", "accelerometer_random_walk", "update_rate"):
        assert float(vals[key]) == pytest.approx(k[key], rel=1e-6)
    assert (tmp_path / "o" / "imu_allan.png").stat().st_size > 1000
    assert obj["settings"]["map"].startswith("t_s=SampleTimeFine:100.0us")
    # the runner writes the envelope it prints (timestamps and all)
    assert json.loads((tmp_path / "o" / "result.json").read_text()) == obj


def _gappy(tmp_path):
    p = tmp_path / "gap.csv"
    lines = ["t_ms,gz_dps"]
    t = 0
    for i in range(400):
        t += 10 if i != 200 else 50          # 4 samples lost before data row 201
        lines.append(f"{t},{(-1) ** i * 0.01 + 0.001 * (i % 7)}")
    p.write_text("\n".join(lines) + "\n")
    return p


def test_gaps_analysed_or_error_and_split(tmp_path):
    # default: the 4 lost samples are gaps on the sensor's grid (gap-resistant OADEV), with
    # a warning naming them; --gaps error refuses, --gaps split needs one segment
    import json

    p = _gappy(tmp_path)
    res = run("allan", "--imu", p, "--json")
    assert res.returncode == 0, res.stderr
    allan = json.loads(res.stdout)["imu"]["axes"][0]["allan"]
    assert allan["n_missing"] == 4 and allan["n_gaps"] == 1
    # m = 1: 404 grid samples give 403 summands; the 5 that touch the 4 lost samples go
    assert allan["n_terms"][0] == 403 - 5
    res = run("allan", "--imu", p, "--gaps", "error")
    assert res.returncode == 2 and "before row 201" in res.stderr and "~4 samples" in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1
    res = run("allan", "--imu", p, "--gaps", "split")
    assert res.returncode == 2 and "several segments" in res.stderr


@pytest.mark.parametrize("extra, pattern", [
    (("--export", "matlab", "x.yaml"), "must be one of kalibr, openvins"),
    (("--map", "gz_rps=gz_dps:mps2"), "acceleration"),
    (("--map", "gx_rps=NoSuchCol"), "'NoSuchCol'"),
])
def test_bad_input_one_line(tmp_path, extra, pattern):
    res = run("allan", "--imu", _gappy(tmp_path), *extra)
    assert res.returncode == 2 and pattern in res.stderr, res.stderr
    assert len(res.stderr.strip().splitlines()) == 1


def test_allan_imu_flag_gives_the_same_export_as_allan_imu(tmp_path):
    """``inertialab allan FILE --imu --export kalibr F`` is the same
    analysis as ``allan-imu``: identical YAML on a six-axis file with canonical columns."""
    import numpy as np
    import pandas as pd

    rng = np.random.default_rng(3)
    n, fs = 4000, 100.0
    cols = {"t_s": np.arange(n) / fs}
    for ax in ("gx_rps", "gy_rps", "gz_rps"):
        cols[ax] = 1e-3 * rng.standard_normal(n)
    for ax in ("ax_mps2", "ay_mps2", "az_mps2"):  # at rest: gravity on z
        cols[ax] = 2e-3 * rng.standard_normal(n) + (9.80665 if ax == "az_mps2" else 0.0)
    f = tmp_path / "imu.csv"
    pd.DataFrame(cols).to_csv(f, index=False)
    a, b = tmp_path / "a.yaml", tmp_path / "b.yaml"
    r1 = run("allan", f, "--imu", "--export", "kalibr", a, "--json")
    r2 = run("allan-imu", f, "--export", "kalibr", b, "--json")  # the old spelling is gone
    assert r1.returncode == 0 and r2.returncode == 2, r1.stderr + r2.stderr
    assert "No such command" in r2.stderr and not b.exists()
    assert json.loads(r1.stdout)["command"] == "allan"
    # white rate noise of 1e-3 rad/s per sample at 100 Hz: density 1e-4 rad/s/sqrt(Hz);
    # 4000 samples give a few percent scatter
    vals = dict(re.findall(r"^([a-z_]+):\s*([-+0-9.eE]+)", a.read_text(), flags=re.M))
    assert float(vals["gyroscope_noise_density"]) == pytest.approx(1e-4, rel=0.15)
    assert float(vals["accelerometer_noise_density"]) == pytest.approx(2e-4, rel=0.15)
    bad = run("allan", f, "--export", "kalibr", a)
    assert bad.returncode == 2 and "--export needs --imu" in bad.stderr
