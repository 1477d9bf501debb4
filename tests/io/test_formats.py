"""The formats robots, drones and lab tools log in, each read through the one front
door from a file written by the format's own library."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from inertialab.errors import DataQualityWarning, InputError
from inertialab.io import read_record
from inertialab.io.mapping import ReadOptions

#: real PX4 ULogs cut to a few seconds from pyulog's test logs (BSD-3-Clause, the licence
#: beside them; tests/data/README.md says how they were cut)
PX4 = Path(__file__).resolve().parents[1] / "data" / "px4"


def _imu_truth(n, seed=7):
    rng = np.random.default_rng(seed)
    t_ns = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 2_500_000  # 400 Hz
    g = rng.normal(0.0, 0.01, size=(n, 3))
    a = rng.normal(0.0, 0.05, size=(n, 3)) + [0.0, 0.0, 9.81]
    return t_ns, g, a


# ----------------------------------------------------------------------------- ROS bags

rosbags = pytest.importorskip("rosbags", reason="rosbags ([formats] extra) not installed")


def _imu_msg(store, t_ns, g, a, ros1=False):
    T = store.types
    Imu = T["sensor_msgs/msg/Imu"]
    hdr = dict(stamp=T["builtin_interfaces/msg/Time"](sec=int(t_ns // 10**9),
                                                       nanosec=int(t_ns % 10**9)),
               frame_id="imu_link")
    if ros1:
        hdr["seq"] = 0
    V3, Q = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    return Imu(header=T["std_msgs/msg/Header"](**hdr),
               orientation=Q(x=0.0, y=0.0, z=0.0, w=1.0), orientation_covariance=np.zeros(9),
               angular_velocity=V3(x=g[0], y=g[1], z=g[2]),
               angular_velocity_covariance=np.zeros(9),
               linear_acceleration=V3(x=a[0], y=a[1], z=a[2]),
               linear_acceleration_covariance=np.zeros(9))


def write_bag(path, kind, topics, *, extra_string_topic=True):
    """Write a bag with rosbags' own writers. ``topics``: name -> (t_ns, g, a)."""
    from rosbags.typesys import Stores, get_typestore

    if kind == "ros1":
        from rosbags.rosbag1 import Writer

        store = get_typestore(Stores.ROS1_NOETIC)
        ser = store.serialize_ros1
        writer = Writer(path)
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        store = get_typestore(Stores.ROS2_HUMBLE)
        ser = store.serialize_cdr
        writer = Writer(path, version=9, storage_plugin=StoragePlugin.SQLITE3 if kind == "sqlite3"
                        else StoragePlugin.MCAP)
    imu_type = "sensor_msgs/msg/Imu"
    with writer as w:
        if extra_string_topic:
            sc = w.add_connection("/status", "std_msgs/msg/String", typestore=store)
            w.write(sc, 1, ser(store.types["std_msgs/msg/String"](data="ok"), "std_msgs/msg/String"))
        for name, (t_ns, g, a) in topics.items():
            c = w.add_connection(name, imu_type, typestore=store)
            for k in range(len(t_ns)):
                msg = _imu_msg(store, int(t_ns[k]), g[k], a[k], ros1=kind == "ros1")
                # receive time: write order at the nominal rate, 1 ms after the first stamp
                # (the reader uses the header stamps, which may disagree with it)
                w.write(c, int(t_ns[0]) + 1_000_000 + k * 2_500_000, ser(msg, imu_type))
    return path


@pytest.mark.parametrize("kind", ["ros1", "sqlite3", "mcap"])
def test_bag_imu_topic_read_with_header_stamps(tmp_path, kind):
    t_ns, g, a = _imu_truth(400)
    p = write_bag(tmp_path / ("run.bag" if kind == "ros1" else "run"), kind,
                  {"/imu/data": (t_ns, g, a)})
    rec = read_record(p, "gyro_log")
    d = rec.data
    np.testing.assert_array_equal(d[["gx_rps", "gy_rps", "gz_rps"]].to_numpy(), g)
    np.testing.assert_array_equal(d[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy(), a)
    np.testing.assert_allclose(d["t_s"], (t_ns - t_ns[0]) * 1e-9, rtol=0, atol=1e-15)
    assert rec.meta["bag"]["topic"] == "/imu/data" and rec.meta["bag"]["n_messages"] == 400
    assert rec.topic == "/imu/data"  # the exporters' rostopic default
    assert rec.meta["time_origin"]["value"] == int(t_ns[0])
    assert rec.meta["timestamps"]["mean_rate_hz"] == pytest.approx(400.0, rel=1e-12)
    if kind != "ros1":  # the storage file inside the folder reads the same
        store_file = next(p.glob("*.db3" if kind == "sqlite3" else "*.mcap"))
        assert read_record(store_file, "gyro_log").sha256 == rec.sha256


def test_bag_topic_by_name_and_the_only_imu_topic(tmp_path):
    t1, g1, a1 = _imu_truth(50, seed=1)
    t2, g2, a2 = _imu_truth(60, seed=2)
    p = write_bag(tmp_path / "two.bag", "ros1", {"/imu0": (t1, g1, a1), "/imu1": (t2, g2, a2)})
    with pytest.raises(InputError, match=r"2 IMU topics \(/imu0, /imu1\); choose one"):
        read_record(p, "gyro_log")
    rec = read_record(p, "gyro_log", options=ReadOptions(topic="/imu1"))
    np.testing.assert_array_equal(rec.data["gz_rps"], g2[:, 2])
    with pytest.raises(InputError, match=r"no sensor_msgs/Imu topic '/imu9' \(IMU topics: "
                                         r"/imu0, /imu1"):
        read_record(p, "gyro_log", options=ReadOptions(topic="/imu9"))


def test_bag_out_of_order_and_duplicate_stamps_are_reported(tmp_path):
    t_ns, g, a = _imu_truth(100)
    order = np.arange(100)
    order[[40, 41]] = [41, 40]            # two messages swapped in the bag
    t_rec = t_ns[order].copy()
    t_rec[70] = t_rec[69]                 # a driver republished a stamp
    p = write_bag(tmp_path / "ooo", "mcap", {"/imu": (t_rec, g[order], a[order])})
    with pytest.warns(DataQualityWarning, match="1 out-of-order and 1 duplicate"):
        rec = read_record(p, "gyro_log")
    b = rec.meta["bag"]
    assert (b["n_out_of_order"], b["n_duplicate_stamps"], b["n_messages"]) == (1, 1, 100)
    assert len(rec.data) == 99 and np.all(np.diff(rec.data["t_s"]) > 0)
    # sorted back: the swapped pair is in stamp order again, values follow their stamps
    np.testing.assert_array_equal(rec.data["gx_rps"].to_numpy()[40:42], g[40:42, 0])
    assert rec.meta["timestamps"]["n_gaps"] == 1 and rec.meta["timestamps"]["n_dropped"] == 1


def test_corrupt_bag_is_one_line_naming_the_file(tmp_path):
    t_ns, g, a = _imu_truth(200)
    p = write_bag(tmp_path / "ok.bag", "ros1", {"/imu": (t_ns, g, a)})
    bad = tmp_path / "cut.bag"
    bad.write_bytes(p.read_bytes()[: p.stat().st_size // 2])
    with pytest.raises(InputError) as exc:
        read_record(bad, "gyro_log")
    msg = str(exc.value)
    assert str(bad) in msg and "\n" not in msg and "ROS bag" in msg
    # a damaged record length inside the file: the error names its byte position
    import struct

    data = bytearray(p.read_bytes())
    hl, = struct.unpack_from("<i", data, 13)
    dl, = struct.unpack_from("<i", data, 17 + hl)
    chunk_at = 13 + 8 + hl + dl
    struct.pack_into("<i", data, chunk_at, 2**31 - 1)
    dam = tmp_path / "damaged.bag"
    dam.write_bytes(bytes(data))
    with pytest.raises(InputError, match=f"damaged ROS bag record at byte {chunk_at}"):
        read_record(dam, "gyro_log")


def test_missing_extra_is_one_line_naming_it(tmp_path, monkeypatch):
    p = tmp_path / "x.bag"
    p.write_bytes(b"#ROSBAG V2.0\n")
    monkeypatch.setitem(sys.modules, "rosbags.highlevel", None)
    with pytest.raises(InputError, match=r"pip install 'inertialab\[formats\]'"):
        read_record(p, "gyro_log")
    monkeypatch.setitem(sys.modules, "pyulog", None)
    u = tmp_path / "y.ulg"
    u.write_bytes(b"ULog\x01\x12\x35")
    with pytest.raises(InputError, match=r"PX4 ULog.*pip install 'inertialab\[formats\]'"):
        read_record(u, "gyro_log")


# ----------------------------------------------------------------------------- PX4 ULog

def test_ulog_sensor_combined_real_log():
    pyulog = pytest.importorskip("pyulog")
    f = PX4 / "px4_events_4s.ulg"
    rec = read_record(f, "gyro_log")
    d = pyulog.ULog(str(f), ["sensor_combined"]).get_dataset("sensor_combined").data
    assert len(rec.data) == 944 == len(d["timestamp"])
    np.testing.assert_array_equal(rec.data["gy_rps"], d["gyro_rad[1]"].astype(float))
    np.testing.assert_array_equal(rec.data["az_mps2"], d["accelerometer_m_s2[2]"].astype(float))
    np.testing.assert_allclose(rec.data["t_s"], (d["timestamp"] - d["timestamp"][0]) * 1e-6,
                               rtol=0, atol=1e-12)
    ts = rec.meta["timestamps"]
    assert ts["mean_rate_hz"] == pytest.approx(943 / ((d["timestamp"][-1] - d["timestamp"][0])
                                                      * 1e-6), rel=1e-12)
    assert rec.meta["ulog"]["topic"] == "sensor_combined"


def test_ulog_raw_gyro_instance_chosen():
    pyulog = pytest.importorskip("pyulog")
    f = PX4 / "px4_tagged_6s.ulg"
    rec = read_record(f, "gyro_log", options=ReadOptions(topic="sensor_gyro", instance=2))
    d = pyulog.ULog(str(f), ["sensor_gyro"]).get_dataset("sensor_gyro", 2).data
    np.testing.assert_array_equal(rec.data["gx_rps"], d["x"].astype(float))
    assert "temp_c" in rec.data.columns and rec.meta["ulog"]["instances"] == [0, 1, 2]
    with pytest.raises(InputError, match=r"no instance 5 \(instances: 0, 1, 2"):
        read_record(f, "gyro_log", options=ReadOptions(topic="sensor_accel", instance=5))


def test_corrupt_ulog_is_refused_and_stdout_stays_clean(tmp_path, capsys):
    pytest.importorskip("pyulog")
    data = bytearray((PX4 / "px4_events_4s.ulg").read_bytes())
    rng = np.random.default_rng(0)
    mid = len(data) // 2
    data[mid:mid + 2000] = rng.integers(0, 256, 2000, dtype=np.uint8).tobytes()
    bad = tmp_path / "bad.ulg"
    bad.write_bytes(bytes(data))
    with pytest.raises(InputError, match="corrupt PX4 ULog") as exc:
        read_record(bad, "gyro_log")
    assert str(bad) in str(exc.value) and "\n" not in str(exc.value)
    assert capsys.readouterr().out == ""
    junk = tmp_path / "junk.ulg"
    junk.write_bytes(b"not a ulog at all" * 10)
    with pytest.raises(InputError, match="not a readable PX4 ULog"):
        read_record(junk, "gyro_log")


# ----------------------------------------------------------------------------- MATLAB, HDF5

def test_mat_v5_struct_and_matrix_by_dataset_path(tmp_path):
    sio = pytest.importorskip("scipy.io")
    t_ns, g, a = _imu_truth(120)
    t = (t_ns - t_ns[0]) * 1e-9
    p = tmp_path / "xsens.mat"
    sio.savemat(p, {"imu": {"t": t, "gyro": g, "acc": a}, "raw": np.vstack([t, g.T])})
    with pytest.raises(InputError, match=r"2 numeric variables .*argument 'dataset'"):
        read_record(p, "gyro_log")
    rec = read_record(p, "gyro_log", options=ReadOptions.from_cli(
        "t_s=t,gx_rps=gyro_1:rps,gy_rps=gyro_2:rps,gz_rps=gyro_3:rps,ax_mps2=acc_1:mps2",
        dataset="imu"))
    np.testing.assert_array_equal(rec.data[["gx_rps", "gy_rps", "gz_rps"]], g)
    np.testing.assert_array_equal(rec.data["ax_mps2"], a[:, 0])
    # a 4 x n matrix (row per channel) is turned into columns
    rec2 = read_record(p, "gyro_log", options=ReadOptions.from_cli(
        "t_s=col1,gz_dps=col4:rps", dataset="raw"))
    np.testing.assert_allclose(rec2.data["gz_dps"], g[:, 2] * 180 / math.pi, rtol=1e-15)
    assert rec2.meta["transposed"] is True
    with pytest.raises(InputError, match="no variable or field 'gyr' in imu"):
        read_record(p, "gyro_log", options=ReadOptions(dataset="imu.gyr"))


def _mat73(path, groups):
    """A MATLAB v7.3 file as MATLAB writes it: HDF5 with a 512-byte user block holding the
    'MATLAB 7.3 MAT-file' text header, matrices stored transposed (column-major)."""
    h5py = pytest.importorskip("h5py")
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, value in groups.items():
            if isinstance(value, dict):
                grp = f.create_group(name)
                for k, v in value.items():
                    grp.create_dataset(k, data=np.asarray(v).T)
            else:
                f.create_dataset(name, data=np.asarray(value).T)
    with open(path, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Nov 23 2026 HDF5 "
                 b"schema 1.00 .".ljust(116) + b"\0" * 8 + b"\x00\x02IM")
    return path


def test_mat_v73_and_hdf5_datasets_by_path(tmp_path):
    t_ns, g, a = _imu_truth(90)
    t = (t_ns - t_ns[0]) * 1e-9
    p = _mat73(tmp_path / "log73.mat", {"imu": {"t": t[:, None], "gyro": g}})
    rec = read_record(p, "gyro_log", options=ReadOptions.from_cli(
        "t_s=t,gx_rps=gyro_1:rps,gz_rps=gyro_3:rps", dataset="imu"))
    np.testing.assert_array_equal(rec.data["gz_rps"], g[:, 2])
    h5py = pytest.importorskip("h5py")
    h = tmp_path / "flight.h5"
    with h5py.File(h, "w") as f:
        f.create_dataset("sensors/imu/data", data=np.column_stack([t, g]))
        f.create_dataset("sensors/baro", data=np.arange(10.0))
    with pytest.raises(InputError, match=r"2 numeric datasets"):
        read_record(h, "gyro_log")
    rec2 = read_record(h, "gyro_log", options=ReadOptions.from_cli(
        "t_s=col1,gy_rps=col3:rps", dataset="sensors/imu/data"))
    np.testing.assert_array_equal(rec2.data["gy_rps"], g[:, 1])
    cut = tmp_path / "cut.h5"
    cut.write_bytes(h.read_bytes()[:3000])
    with pytest.raises(InputError, match="not a readable HDF5") as exc:
        read_record(cut, "gyro_log")
    assert str(cut) in str(exc.value)


def test_corrupt_mat_is_one_line(tmp_path):
    sio = pytest.importorskip("scipy.io")
    p = tmp_path / "ok.mat"
    sio.savemat(p, {"x": np.arange(1000.0).reshape(250, 4)})
    bad = tmp_path / "bad.mat"
    bad.write_bytes(p.read_bytes()[:400])
    with pytest.raises(InputError, match="not a readable MATLAB file") as exc:
        read_record(bad, "gyro_log")
    assert "\n" not in str(exc.value) and str(bad) in str(exc.value)


# ----------------------------------------------------------------------------- imu_tk text

def test_imu_tk_accel_and_gyro_files_joined_on_time(tmp_path):
    t_ns, g, a = _imu_truth(300)
    t = 1000.0 + np.arange(300) * 0.01
    acc = tmp_path / "xsens_acc.mat"
    gyr = tmp_path / "xsens_gyro.mat"
    acc.write_text("".join(f"{ti:.6f} {x:.9f} {y:.9f} {z:.9f}\n" for ti, (x, y, z) in zip(t, a)))
    # the gyro file starts two samples later and its stamps jitter by 0.1 ms
    jit = np.random.default_rng(5).uniform(-1e-4, 1e-4, 300)
    gyr.write_text("".join(f"{ti + j:.6f}   {x:.9f}   {y:.9f}   {z:.9f}\n"
                           for ti, j, (x, y, z) in list(zip(t, jit, g))[2:]))
    rec = read_record(acc, "triaxial_raw", options=ReadOptions.from_cli(
        unit="mps2,rps", join=[gyr]))
    assert rec.meta["join"]["roles"] == ["a", "g"]
    assert rec.meta["join"]["unmatched"] == {str(gyr): 2} and len(rec.data) == 298
    np.testing.assert_allclose(rec.data["ax_mps2"], np.round(a[2:, 0], 9), rtol=0, atol=1e-15)
    np.testing.assert_allclose(rec.data["gz_rps"], np.round(g[2:, 2], 9), rtol=0, atol=1e-15)
    np.testing.assert_allclose(rec.data["t_s"], t[2:] - t[2], atol=1e-9)


@pytest.mark.slow
def test_long_bag_reads_in_bounded_memory(tmp_path):
    """Memory of a long bag grows by the decoded arrays (7 numbers x 8 bytes per message)
    times at most 2, whatever the bag's length: the marginal tracemalloc peak between a
    30,000- and a 120,000-message bag (after a warm-up read that builds rosbags' type
    store) is below twice the marginal decoded arrays. Holding the raw messages (324 bytes
    each, 5.8x) would fail. The 1M-message RSS figures are in docs/vendor-files.md."""
    import tracemalloc

    def peak_of(n):
        t_ns, g, a = _imu_truth(n)
        p = write_bag(tmp_path / f"b{n}.bag", "ros1", {"/imu": (t_ns, g, a)},
                      extra_string_topic=False)
        del t_ns, g, a
        tracemalloc.start()
        try:
            rec = read_record(p, "gyro_log")
            _, peak = tracemalloc.get_traced_memory()
        finally:
            tracemalloc.stop()
        assert len(rec.data) == n
        return peak

    peak_of(1000)  # warm-up: imports, type store, code generation
    p1, p2 = peak_of(30_000), peak_of(120_000)
    slope = (p2 - p1) / ((120_000 - 30_000) * 7 * 8)
    assert slope < 2.0, slope


@pytest.mark.parametrize("kind, suffix", [("sqlite3", ".db3"), ("mcap", ".mcap")])
def test_corrupt_ros2_bag_is_one_line(tmp_path, kind, suffix):
    t_ns, g, a = _imu_truth(200)
    p = write_bag(tmp_path / "run", kind, {"/imu": (t_ns, g, a)})
    f = next(p.glob(f"*{suffix}"))
    f.write_bytes(f.read_bytes()[: f.stat().st_size // 2])
    with pytest.raises(InputError, match="not a readable ROS bag") as exc:
        read_record(p, "gyro_log")
    assert str(p) in str(exc.value) and "\n" not in str(exc.value)
