"""The thermal-imu rig: seeds, coefficient sizes, quantised lagging temperature, and the
ULog and DataFlash it writes read back by pyulog and pymavlink."""

import numpy as np
import pytest

from inertialab.sim import thermal_imu as ti


def test_same_seed_same_log_and_other_seed_other_noise():
    a = ti.simulate(1, rate_hz=0.5).frame
    b = ti.simulate(1, rate_hz=0.5).frame
    c = ti.simulate(1, rate_hz=0.5, seed=9).frame
    assert a.equals(b)
    assert not np.allclose(a["gx_rps"], c["gx_rps"])
    np.testing.assert_array_equal(a["true_off_gx"], c["true_off_gx"])  # same unit


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_coefficient_sizes_are_the_published_ones(seed):
    unit = ti.make_unit(seed)
    t = np.linspace(ti.T_LO, ti.T_HI, 2001)
    for inst in unit.instances:
        off = inst.offsets(t)
        for a in ti.AXES:
            kind = "accel" if a[0] == "a" else "gyro"
            slope = np.max(np.abs(np.gradient(off[a], t)))
            assert 0.39 * ti.MAX_SLOPE[kind] <= slope <= 1.001 * ti.MAX_SLOPE[kind], (a, slope)
            assert len(inst.coef[a]) - 1 == inst.order[a]
    assert unit.instances[0].order["gx"] == 5 and unit.instances[1].order["gx"] == 3


def test_temperature_is_quantised_lagging_and_ramps_both_ways():
    log = ti.simulate(0, rate_hz=1.0)
    g = log.frame[log.frame["instance"] == 0]
    temp = g["temp_c"].to_numpy()
    np.testing.assert_array_equal(temp, np.round(temp))  # 1 °C steps
    assert temp.min() <= -14 and temp.max() >= 55
    el = g["true_temp_c"].to_numpy()
    d = np.gradient(el)
    # the reported temperature trails the element: below it heating, above it cooling
    assert np.mean((temp - el)[d > 0.01]) < -0.2 and np.mean((temp - el)[d < -0.01]) > 0.2


def test_ulog_reads_back_with_pyulog():
    pyulog = pytest.importorskip("pyulog")
    log = ti.simulate(0, rate_hz=0.5)
    import io

    u = pyulog.ULog(io.BytesIO(ti.ulog_bytes(log)))
    got = {(d.name, d.multi_id): d.data for d in u.data_list}
    assert set(got) == {(n, i) for n in ("sensor_accel", "sensor_gyro") for i in (0, 1)}
    g = log.frame[log.frame["instance"] == 1]
    d = got[("sensor_gyro", 1)]
    assert int(d["device_id"][0]) == ti.DEVICE_IDS[1][1]
    np.testing.assert_allclose(d["x"], g["gx_rps"].to_numpy(np.float32), rtol=0, atol=0)
    np.testing.assert_array_equal(d["temperature"], g["temp_c"].to_numpy(np.float32))
    np.testing.assert_array_equal(np.diff(d["timestamp"].astype(np.int64)), 2_000_000)


def test_dataflash_reads_back_with_pymavlink(tmp_path):
    dfr = pytest.importorskip("pymavlink.DFReader")
    log = ti.simulate(0, rate_hz=0.05)
    p = tmp_path / "a.bin"
    p.write_bytes(ti.dataflash_bytes(log))
    r = dfr.DFReader_binary(str(p))
    rows = []
    while (m := r.recv_match(type="IMU")) is not None:
        rows.append((m.I, m.T, m.AccZ, m.GyrY))
    rows = np.array(rows)
    assert rows.shape[0] == len(log.frame)
    g = log.frame[log.frame["instance"] == 0]
    np.testing.assert_allclose(rows[rows[:, 0] == 0, 2], g["az_mps2"].to_numpy(np.float32))
    np.testing.assert_array_equal(rows[rows[:, 0] == 0, 1], g["temp_c"].to_numpy(np.float32))
