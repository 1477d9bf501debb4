"""ROS 1 and ROS 2 bags (sqlite3 and MCAP storage) with ``sensor_msgs/Imu`` topics.

Read with ``rosbags`` (pure Python, no ROS install; the ``[formats]`` extra). The topic
is the one named (``topic``) or the only ``sensor_msgs/Imu`` topic of the bag; several
IMU topics without a name, or a name that is not there, are an
:class:`~inertialab.errors.InputError` listing the IMU topics.

Time is the message's ``header.stamp`` (the sensor's time, not the recorder's); when
every stamp is zero the bag's receive time is used and ``meta["bag"]["stamp"]`` says so.
Stamps are audited in the order recorded: out-of-order and duplicate stamps (which
allan_variance_ros needs a separate script to find) are counted in ``meta["bag"]``,
with a :class:`~inertialab.errors.DataQualityWarning`; the samples are then sorted by
stamp and exact duplicate stamps dropped (first kept), so the record is a valid
continuous log.

Memory and speed: raw messages are gathered in blocks of :data:`BLOCK` and decoded with
numpy at the fixed offsets of ``sensor_msgs/Imu`` (ROS 1 serialisation or little-endian
CDR; the offsets follow the ``frame_id`` length), each block checked against rosbags'
own deserialiser on its first message; a message of another length or layout falls back
to the deserialiser. Only the 7 decoded numbers per message are kept (typed arrays), so
a long bag needs about twice the decoded IMU arrays plus one block of raw messages.
"""

from __future__ import annotations

import warnings
from array import array
from pathlib import Path

import numpy as np
import pandas as pd

from inertialab.errors import DataQualityWarning, InputError
from inertialab.io.formats.dispatch import Loaded, need

__all__ = ["IMU_TYPES", "read_bag"]

IMU_TYPES = ("sensor_msgs/msg/Imu", "sensor_msgs/Imu")
#: Raw messages decoded together by the numpy fast path.
BLOCK = 1 << 13
_N_DOUBLES = 37  # orientation 4 + cov 9 + angular_velocity 3 + cov 9 + linear_acc 3 + cov 9
COLUMNS = ("gx_rps", "gy_rps", "gz_rps", "ax_mps2", "ay_mps2", "az_mps2")


def _bag_path(p: Path) -> Path:
    """A ROS 2 storage file (.db3/.mcap) is read through its bag folder when it has one."""
    if p.is_file() and p.suffix.lower() in (".db3", ".mcap") \
            and (p.parent / "metadata.yaml").is_file():
        return p.parent
    return p


def _choose(connections, topic: str | None, p: Path):
    imu = [c for c in connections if c.msgtype in IMU_TYPES]
    topics = sorted({c.topic for c in imu})
    if topic is not None:
        chosen = [c for c in imu if c.topic == topic]
        if not chosen:
            alltopics = sorted({f"{c.topic} ({c.msgtype})" for c in connections})
            raise InputError(f"no sensor_msgs/Imu topic '{topic}' (IMU topics: "
                             f"{', '.join(topics) or 'none'}; all topics: "
                             f"{', '.join(alltopics) or 'none'})", path=p)
        return chosen, topic
    if not topics:
        alltopics = sorted({f"{c.topic} ({c.msgtype})" for c in connections})
        raise InputError(f"no sensor_msgs/Imu topic in the bag (topics: "
                         f"{', '.join(alltopics) or 'none'})", path=p)
    if len(topics) > 1:
        raise InputError(f"{len(topics)} IMU topics ({', '.join(topics)}); choose one "
                         "(argument 'topic')", path=p)
    return imu, topics[0]


def read_bag(path, *, topic: str | None = None) -> Loaded:
    """Read the IMU topic of a ROS 1 bag, a ROS 2 bag folder or its .db3/.mcap file."""
    hl = need("rosbags.highlevel", "ROS bags", path=path)
    typesys = need("rosbags.typesys", "ROS bags", path=path)
    p = Path(path)
    src = _bag_path(p)
    store = typesys.get_typestore(typesys.Stores.LATEST)
    stamps = array("q")
    recv = array("q")
    vals = array("d")
    k = 0
    try:
        with hl.AnyReader([src], default_typestore=store) as reader:
            conns, name = _choose(reader.connections, topic, p)
            block: list = []
            layout = None
            for conn, t_recv, raw in reader.messages(connections=conns):
                ros1 = _is_ros1(conn)
                lay = _layout(raw, ros1)
                if lay is None:
                    _flush(block, layout, reader, conn, stamps, vals)
                    block, layout = [], None
                    _slow(raw, reader, conn, stamps, vals)
                elif layout is not None and lay != layout:
                    _flush(block, layout, reader, conn, stamps, vals)
                    block, layout = [raw], lay
                else:
                    layout = lay
                    block.append(raw)
                    if len(block) >= BLOCK:
                        _flush(block, layout, reader, conn, stamps, vals)
                        block = []
                recv.append(int(t_recv))
                k += 1
            if block:
                _flush(block, layout, reader, conn, stamps, vals)
    except InputError:
        raise
    except Exception as exc:  # rosbags raises its own error types for damaged bags
        text = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise InputError(f"not a readable ROS bag: {type(exc).__name__} after {k} IMU "
                         f"messages ({text})", path=p) from None
    if k == 0:
        raise InputError(f"IMU topic '{name}' holds no messages", path=p)
    t_ns = np.frombuffer(stamps, dtype=np.int64)
    stamp_kind = "header.stamp"
    if not t_ns.any():
        t_ns = np.frombuffer(recv, dtype=np.int64)
        stamp_kind = "receive time (header stamps are all zero)"
    v = np.frombuffer(vals, dtype=np.float64).reshape(k, 6)
    return _to_loaded(t_ns, v, p, topic=name, stamp_kind=stamp_kind, source="ros bag")


def _is_ros1(conn) -> bool:
    fmt = getattr(conn, "ext", None)
    return type(fmt).__name__ == "ConnectionExtRosbag1"


def _layout(raw, ros1: bool):
    """``(length, stamp offset, stamp signed, doubles offset)`` of a serialised Imu, or
    None when the fast path does not apply (big-endian CDR, odd length)."""
    b = bytes(raw[:16])
    if len(b) < 16:
        return None
    if ros1:  # seq u32, secs u32, nsecs u32, frame_id (u32 length + bytes), no padding
        flen = int.from_bytes(b[12:16], "little")
        d0 = 16 + flen
        st, signed = 4, False
    else:  # CDR: 4-byte encapsulation, then sec i32, nanosec u32, frame_id with NUL
        if b[0:2] != b"\x00\x01":
            return None
        flen = int.from_bytes(b[12:16], "little")
        pos = 16 + flen
        d0 = pos + (-(pos - 4)) % 8
        st, signed = 4, True
    if len(raw) != d0 + 8 * _N_DOUBLES:
        return None
    return len(raw), st, signed, d0


def _slow(raw, reader, conn, stamps, vals):
    msg = reader.deserialize(raw, conn.msgtype)
    st = msg.header.stamp
    sec = getattr(st, "sec", None)
    nsec = getattr(st, "nanosec", None)
    stamps.append(int(sec) * 1_000_000_000 + int(nsec))
    w, a = msg.angular_velocity, msg.linear_acceleration
    vals.extend((w.x, w.y, w.z, a.x, a.y, a.z))


def _flush(block, layout, reader, conn, stamps, vals):
    """Decode a block of same-layout raw messages with numpy; check the first against the
    deserialiser (a mismatch decodes the block one by one)."""
    if not block:
        return
    length, st, signed, d0 = layout
    buf = np.frombuffer(b"".join(bytes(r) for r in block), dtype=np.uint8).reshape(-1, length)
    sec = np.ascontiguousarray(buf[:, st:st + 4]).view("<i4" if signed else "<u4")[:, 0]
    nsec = np.ascontiguousarray(buf[:, st + 4:st + 8]).view("<u4")[:, 0]
    w = np.ascontiguousarray(buf[:, d0 + 104:d0 + 128]).view("<f8")
    a = np.ascontiguousarray(buf[:, d0 + 200:d0 + 224]).view("<f8")
    ns = sec.astype(np.int64) * 1_000_000_000 + nsec.astype(np.int64)
    v = np.column_stack([w, a])
    ref = reader.deserialize(block[0], conn.msgtype)
    rs = ref.header.stamp
    ok = (int(rs.sec) * 1_000_000_000 + int(rs.nanosec) == int(ns[0])
          and np.array_equal(v[0], [ref.angular_velocity.x, ref.angular_velocity.y,
                                    ref.angular_velocity.z, ref.linear_acceleration.x,
                                    ref.linear_acceleration.y, ref.linear_acceleration.z],
                             equal_nan=True))
    if not ok:
        for r in block:
            _slow(r, reader, conn, stamps, vals)
        return
    stamps.frombytes(ns.tobytes())
    vals.frombytes(np.ascontiguousarray(v, dtype=np.float64).tobytes())


def _to_loaded(t_ns: np.ndarray, v: np.ndarray, p: Path, *, topic: str, stamp_kind: str,
               source: str, columns=COLUMNS, extra: dict | None = None) -> Loaded:
    """Audit the stamps as recorded, sort, drop duplicate stamps, build the frame."""
    dt = np.diff(t_ns)
    n_back = int(np.count_nonzero(dt < 0))
    order = np.argsort(t_ns, kind="stable")
    ts = t_ns[order]
    keep = np.r_[True, np.diff(ts) != 0]
    n_dup = int(np.count_nonzero(~keep))
    info = {"format": source, "topic": topic, "n_messages": int(t_ns.size), "stamp": stamp_kind,
            "n_out_of_order": n_back, "n_duplicate_stamps": n_dup,
            "sorted": bool(n_back), "duplicates_dropped": n_dup}
    if extra:
        info.update(extra)
    if n_back or n_dup:
        warnings.warn(f"{p}: {topic}: {n_back} out-of-order and {n_dup} duplicate time stamps "
                      "among the messages; sorted by stamp and kept the first of each "
                      "duplicate", DataQualityWarning, stacklevel=3)
    idx = order[keep]
    t0 = int(t_ns[idx[0]])
    data = {"t_s": (t_ns[idx] - t0).astype(np.float64) * 1e-9}
    for j, c in enumerate(columns):
        data[c] = v[idx, j]
    meta = {"bag" if source == "ros bag" else "ulog": info,
            "time_origin": {"column": stamp_kind.split(" ")[0], "unit": "ns", "value": t0}}
    return Loaded(pd.DataFrame(data), meta)
