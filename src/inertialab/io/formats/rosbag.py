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
from pathlib import Path

import numpy as np
import pandas as pd

from inertialab.errors import DataQualityWarning, InputError
from inertialab.io.formats.base import Loaded, need
from inertialab.limits import check_budget

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
    counter = [0]
    try:
        if src.is_file() and src.suffix.lower() == ".bag":
            from inertialab.io.formats import rosbag1_stream as r1

            conns, name = _choose(r1.connections(src), topic, p)
            ids = {c.id for c in conns}
            sink = _Sink(sum(c.msgcount for c in conns), p)
            store1 = typesys.get_typestore(typesys.Stores.ROS1_NOETIC)

            def deser(raw):
                return store1.deserialize_ros1(bytes(raw), "sensor_msgs/msg/Imu")

            _decode(r1.iter_messages(src, ids), True, deser, sink, counter)
        else:
            with hl.AnyReader([src], default_typestore=store) as reader:
                conns, name = _choose(reader.connections, topic, p)
                msgtype = conns[0].msgtype
                ros1 = _is_ros1(conns[0])
                sink = _Sink(sum(int(getattr(c, "msgcount", 0) or 0) for c in conns), p)

                def deser(raw):
                    return reader.deserialize(raw, msgtype)

                _decode(((t, raw) for _, t, raw in reader.messages(connections=conns)), ros1,
                        deser, sink, counter)
    except InputError:
        raise
    except Exception as exc:  # rosbags raises its own error types for damaged bags
        text = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise InputError(f"not a readable ROS bag: {type(exc).__name__} after {counter[0]} IMU "
                         f"messages ({text})", path=p) from None
    k = counter[0]
    if k == 0:
        raise InputError(f"IMU topic '{name}' holds no messages", path=p)
    t_ns, recv, v = sink.arrays()
    stamp_kind = "header.stamp"
    if not t_ns.any():
        t_ns = recv
        stamp_kind = "receive time (header stamps are all zero)"
    del recv
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


class _Sink:
    """Decoded stamps and values, preallocated from the bag's message count (grown by
    doubling if the count was short): 8 + 8 + 48 bytes per message, nothing else."""

    def __init__(self, expected: int, path=None):
        n = max(int(expected), 1024)
        check_budget(n * 72, f"the bag's declared {int(expected)} messages", path)
        self.t = np.empty(n, np.int64)
        self.recv = np.empty(n, np.int64)
        self.v = np.empty((n, 6), np.float64)
        self.k = 0
        self.r = 0

    def _room(self, m: int):
        need = self.k + m
        if need > self.t.size:
            n = max(need, 2 * self.t.size)
            self.t = np.resize(self.t, n)
            self.v = np.resize(self.v, (n, 6))
            self.recv = np.resize(self.recv, n)

    def add(self, t_ns, v):
        t_ns = np.atleast_1d(t_ns)
        m = t_ns.size
        self._room(m)
        self.t[self.k:self.k + m] = t_ns
        self.v[self.k:self.k + m] = v
        self.k += m

    def add_recv(self, t):
        if self.r >= self.recv.size:
            self._room(self.r + 1 - self.k)
        self.recv[self.r] = t
        self.r += 1

    def arrays(self):
        return self.t[:self.k], self.recv[:self.r], self.v[:self.k]


def _decode(messages, ros1: bool, deser, sink, counter) -> None:
    """Decode ``(receive time, raw)`` pairs into the typed arrays, in blocks."""
    block: list = []
    layout = None
    for t_recv, raw in messages:
        lay = _layout(raw, ros1)
        if lay is None:
            _flush(block, layout, deser, sink)
            block, layout = [], None
            _slow(raw, deser, sink)
        elif layout is not None and lay != layout:
            _flush(block, layout, deser, sink)
            block, layout = [raw], lay
        else:
            layout = lay
            block.append(raw)
            if len(block) >= BLOCK:
                _flush(block, layout, deser, sink)
                block = []
        sink.add_recv(int(t_recv))
        counter[0] += 1
    _flush(block, layout, deser, sink)


def _slow(raw, deser, sink):
    msg = deser(raw)
    st = msg.header.stamp
    w, a = msg.angular_velocity, msg.linear_acceleration
    sink.add(int(st.sec) * 1_000_000_000 + int(st.nanosec),
             np.array([[w.x, w.y, w.z, a.x, a.y, a.z]], dtype=np.float64))


def _flush(block, layout, deser, sink):
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
    ref = deser(block[0])
    rs = ref.header.stamp
    ok = (int(rs.sec) * 1_000_000_000 + int(rs.nanosec) == int(ns[0])
          and np.array_equal(v[0], [ref.angular_velocity.x, ref.angular_velocity.y,
                                    ref.angular_velocity.z, ref.linear_acceleration.x,
                                    ref.linear_acceleration.y, ref.linear_acceleration.z],
                             equal_nan=True))
    if not ok:
        for r in block:
            _slow(r, deser, sink)
        return
    sink.add(ns, v)


def _to_loaded(t_ns: np.ndarray, v: np.ndarray, p: Path, *, topic: str, stamp_kind: str,
               source: str, columns=COLUMNS, extra: dict | None = None) -> Loaded:
    """Audit the stamps as recorded, sort, drop duplicate stamps, build the frame."""
    dt = np.diff(t_ns)
    n_back = int(np.count_nonzero(dt < 0))
    if n_back:
        order = np.argsort(t_ns, kind="stable")
        ts = t_ns[order]
        keep = np.r_[True, np.diff(ts) != 0]
    else:
        order, ts = None, t_ns
        keep = np.r_[True, dt != 0]
    del dt
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
    if n_back == 0 and n_dup == 0:  # the usual case: no copies of the values
        t0 = int(t_ns[0])
        frame = pd.DataFrame(v, columns=list(columns), copy=False)
        frame.insert(0, "t_s", (t_ns - t0).astype(np.float64) * 1e-9)
    else:
        idx = order[keep] if order is not None else np.flatnonzero(keep)
        t0 = int(t_ns[idx[0]])
        frame = pd.DataFrame(v[idx], columns=list(columns), copy=False)
        frame.insert(0, "t_s", (t_ns[idx] - t0).astype(np.float64) * 1e-9)
    del order, ts, keep
    meta = {"bag" if source == "ros bag" else "ulog": info,
            "time_origin": {"column": stamp_kind.split(" ")[0], "unit": "ns", "value": t0}}
    return Loaded(frame, meta)
