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

Memory: messages are decoded one at a time into typed arrays (8 bytes per number), so
a long bag needs about twice the decoded IMU arrays (7 numbers per message), never the
messages themselves.
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
            for conn, t_recv, raw in reader.messages(connections=conns):
                msg = reader.deserialize(raw, conn.msgtype)
                st = msg.header.stamp
                stamps.append(int(st.sec) * 1_000_000_000 + int(st.nanosec))
                recv.append(int(t_recv))
                w, a = msg.angular_velocity, msg.linear_acceleration
                vals.extend((w.x, w.y, w.z, a.x, a.y, a.z))
                k += 1
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
