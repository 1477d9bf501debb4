"""A two-row header whose first row names groups over merged cells (``Gyro,,,Accel,,``
over ``X,Y,Z,X,Y,Z``) is read as ``Gyro X ... Accel Z``, by name and by position."""

import numpy as np
import pytest

from inertialab.io import read_record


@pytest.fixture
def two_row(tmp_path):
    rng = np.random.default_rng(0)
    g = rng.normal(0, 0.05, (300, 3))
    a = rng.normal(0, 0.003, (300, 3)) + [0, 0, -1]
    lines = ["time,Gyro,,,Accel,,", "s,X,Y,Z,X,Y,Z"]
    lines += [",".join([f"{i / 100:.2f}", *(f"{v:.6f}" for v in g[i]),
                        *(f"{v:.6f}" for v in a[i])]) for i in range(300)]
    p = tmp_path / "two.csv"
    p.write_text("\n".join(lines) + "\n")
    return p, g, a


def test_group_row_joined_to_the_names(two_row):
    p, g, a = two_row
    by_name = read_record(p, "gyro_log", column_map="t_s=time,gx_dps=Gyro X:dps,"
                          "gy_dps=Gyro Y:dps,gz_dps=Gyro Z:dps,ax_g=Accel X:g,"
                          "ay_g=Accel Y:g,az_g=Accel Z:g")
    np.testing.assert_allclose(by_name.data["gy_dps"], g[:, 1], atol=1e-6)
    np.testing.assert_allclose(by_name.data["az_g"], a[:, 2], atol=1e-6)
    by_pos = read_record(p, "gyro_log", column_map="t_s=col1,gx_dps=col2:dps,gy_dps=col3:dps,"
                         "gz_dps=col4:dps,ax_g=col5:g,ay_g=col6:g,az_g=col7:g")
    np.testing.assert_allclose(by_pos.data["ax_g"], a[:, 0], atol=1e-6)
