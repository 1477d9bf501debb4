"""Temperature-ramp logs of drone IMUs: PX4 ULog (every instance, device ids), ArduPilot
DataFlash (IMU messages with T) and the plain table read into the same streams; NaN
temperatures refused with one line naming the instance."""

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.io.formats.thermal_logs import read_imu_thermal_log
from inertialab.sim import thermal_imu as ti


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("imu_logs")
    log = ti.simulate(4, rate_hz=0.2)
    (d / "a.ulg").write_bytes(ti.ulog_bytes(log))
    (d / "a.bin").write_bytes(ti.dataflash_bytes(log))
    log.frame.to_csv(d / "a.csv", index=False)
    return d, log


@pytest.mark.parametrize("name", ["a.ulg", "a.bin", "a.csv"])
def test_every_format_gives_every_instance(logs, name):
    if name == "a.ulg":
        pytest.importorskip("pyulog")
    if name == "a.bin":
        pytest.importorskip("pymavlink")
    d, log = logs
    r = read_imu_thermal_log(d / name)
    got = {(s.kind, s.instance): s for s in r.streams}
    assert set(got) == {(k, i) for k in ("accel", "gyro") for i in (0, 1)}
    g = log.frame[log.frame["instance"] == 1]
    s = got[("gyro", 1)]
    np.testing.assert_allclose(s.values[:, 2], g["gz_rps"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(s.temp_c, g["temp_c"])
    np.testing.assert_allclose(s.t_s - s.t_s[0], g["t_s"] - g["t_s"].iloc[0], atol=1e-6)
    if name == "a.ulg":
        assert s.device_id == ti.DEVICE_IDS[1][1] and got[("accel", 0)].device_id == \
            ti.DEVICE_IDS[0][0]


def test_nan_temperature_is_refused_naming_the_instance(logs, tmp_path):
    _, log = logs
    f = log.frame.copy()
    f.loc[f.index[f["instance"] == 1][7], "temp_c"] = np.nan
    f.to_csv(tmp_path / "nan.csv", index=False)
    with pytest.raises(InputError, match=r"accel 1 \(device 0\): temperature is NaN") as e:
        read_imu_thermal_log(tmp_path / "nan.csv")
    assert "\n" not in str(e.value)


def test_missing_column_names_it(logs, tmp_path):
    _, log = logs
    log.frame.drop(columns=["gy_rps"]).to_csv(tmp_path / "m.csv", index=False)
    with pytest.raises(InputError, match="gy_rps"):
        read_imu_thermal_log(tmp_path / "m.csv")
