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
