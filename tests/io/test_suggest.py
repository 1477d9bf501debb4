"""Map suggestions know the spellings of imucal, PX4 (ulog2csv) and ROS exports, and
propose every column the record kind reads (the gyro of a Ferraris session too)."""

import numpy as np
import pandas as pd
import pytest

from inertialab.errors import InputError
from inertialab.io import read_record
from inertialab.io.suggest import canonical_guess, suggest_map


@pytest.mark.parametrize("name, guess", [
    ("gyr_x", ("gx", None)), ("acc_z", ("az", None)),                        # imucal
    ("gyro_rad[1]", ("gy", "rad/s")), ("accelerometer_m_s2[2]", ("az", "m/s^2")),  # PX4
    ("field.angular_velocity.x", ("gx", None)), ("%time", ("t", None)),     # rostopic -p
    ("Gyro X [deg/s]", ("gx", "deg/s")), ("w_z", ("gz", None)),
])
def test_vendor_spellings(name, guess):
    assert canonical_guess(name) == guess


def test_px4_suggestion_carries_the_units_its_names_spell():
    cols = ["timestamp"] + [f"gyro_rad[{i}]" for i in range(3)] + \
        [f"accelerometer_m_s2[{i}]" for i in range(3)]
    assert suggest_map(cols) == ("t_s=timestamp:<unit>,gx_rps=gyro_rad[0]:rps,"
                                 "gy_rps=gyro_rad[1]:rps,gz_rps=gyro_rad[2]:rps,"
                                 "ax_mps2=accelerometer_m_s2[0]:mps2,"
                                 "ay_mps2=accelerometer_m_s2[1]:mps2,"
                                 "az_mps2=accelerometer_m_s2[2]:mps2")


def test_imucal_session_error_suggests_the_gyro_too(tmp_path):
    # imucal's session layout: n_samples, gyr_x..z (deg/s), acc_x..z (m/s^2), no time
    rng = np.random.default_rng(0)
    n = 200
    df = pd.DataFrame({"n_samples": np.arange(n), **{f"gyr_{a}": rng.normal(0, 0.3, n)
                                                     for a in "xyz"},
                       **{f"acc_{a}": rng.normal(0, 0.05, n) for a in "xyz"}})
    p = tmp_path / "ferraris_session.csv"
    df.to_csv(p, index=False)
    with pytest.raises(InputError) as exc:
        read_record(p, "triaxial_raw")
    msg = str(exc.value)
    assert "needs a t_s column or argument 'rate_hz'" in msg
    assert ("gx_rps=gyr_x:<unit>,gy_rps=gyr_y:<unit>,gz_rps=gyr_z:<unit>,"
            "ax_mps2=acc_x:<unit>") in msg


def test_real_imucal_file_suggestion_units_and_read(tmp_path):
    # imucal's own 50-row Ferraris example (tests/ferraris_example.csv, MIT), read as
    # the user would: the error names the real cause and the map; the map without units
    # stops at the gyro (floats: the data decide nothing) and infers m/s^2 for the
    # accelerometer (the triad's norm is gravity)
    from pathlib import Path

    from inertialab.errors import DataQualityWarning
    from inertialab.io.mapping import ReadOptions

    f = Path(__file__).resolve().parents[1] / "data" / "imucal" / "ferraris_example.csv"
    with pytest.raises(InputError) as exc:
        read_record(f, "triaxial_raw")
    msg = str(exc.value)
    assert "needs a t_s column or argument 'rate_hz'" in msg
    assert "gx_rps=gyr_x:<unit>" in msg and "az_mps2=acc_z:<unit>" in msg
    cmap = ("gx_dps=gyr_x,gy_dps=gyr_y,gz_dps=gyr_z,"
            "ax_mps2=acc_x,ay_mps2=acc_y,az_mps2=acc_z")
    with pytest.raises(InputError, match=r"column 'gyr_x': mapped to 'gx_dps' without a unit.*"
                                         r"gx_dps=gyr_x:rps\|dps\|dph"):
        read_record(f, "triaxial_raw", options=ReadOptions.from_cli(cmap, rate=204.8))
    cmap = cmap.replace("gyr_x", "gyr_x:dps").replace("gyr_y", "gyr_y:dps") \
        .replace("gyr_z", "gyr_z:dps")
    with pytest.warns(DataQualityWarning, match=r"median norm is 9.8\d*, gravity in mps2"):
        rec = read_record(f, "triaxial_raw", options=ReadOptions.from_cli(cmap, rate=204.8))
    raw = pd.read_csv(f)
    np.testing.assert_array_equal(rec.data["ax_mps2"], raw["acc_x"])
    np.testing.assert_array_equal(rec.data["gz_dps"], raw["gyr_z"])
    assert rec.timebase.rate_hz == 204.8 and rec.n == 50
