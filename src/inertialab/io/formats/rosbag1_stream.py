"""Streaming reader of ROS 1 bags (format 2.0) for one ``sensor_msgs/Imu`` topic.

rosbags' ROS 1 reader builds an index entry (a Python object) for every message when it
opens a bag: about 170 bytes per message, three times the 56 bytes inertialab keeps.
For a long bag this module reads the records in file order instead (ROS bag format 2.0,
http://wiki.ros.org/Bags/Format/2.0): the bag header gives ``index_pos``; the connection
records after it name the topics and types; the chunks before it (``none``, ``bz2`` or
``lz4`` compressed) are decompressed one at a time and their message-data records of the
chosen connection handed on raw, so memory is one chunk plus the decoded arrays. Any
inconsistency is an :class:`~inertialab.errors.InputError` naming the byte position.

Written by hand because no maintained library streams a ROS 1 bag without an index;
the message bytes are still decoded (and checked) against rosbags' deserialiser.
"""

from __future__ import annotations

import bz2
import os
import struct
from pathlib import Path

from inertialab.errors import InputError
from inertialab.limits import check_budget

__all__ = ["Connection", "connections", "iter_messages"]

_MAGIC = b"#ROSBAG V2.0\n"
_OP_MSG, _OP_HEADER, _OP_CHUNK, _OP_CONN, _OP_CHUNK_INFO = 0x02, 0x03, 0x05, 0x07, 0x06


class Connection:
    def __init__(self, conn: int, topic: str, msgtype: str):
        self.id = conn
        self.topic = topic
        self.msgtype = msgtype
        self.msgcount = 0


def _fields(h: bytes, p: Path, at: int) -> dict:
    out, i = {}, 0
    while i < len(h):
        if i + 4 > len(h):
            raise InputError(f"damaged ROS bag record header at byte {at}", path=p)
        n = struct.unpack_from("<i", h, i)[0]
        i += 4
        if n < 0 or i + n > len(h):
            raise InputError(f"damaged ROS bag record header at byte {at}", path=p)
        k, sep, v = h[i:i + n].partition(b"=")
        if not sep:
            raise InputError(f"damaged ROS bag record header at byte {at}", path=p)
        out[k.decode("ascii", "replace")] = v
        i += n
    return out


def _records(buf, base: int, p: Path, stop: int | None = None):
    """Yield (fields, data, position) of the records in ``buf`` (a bytes object or an open
    file); ``base`` is the file position of buf[0] (for messages)."""
    if isinstance(buf, (bytes, bytearray, memoryview)):
        i, end = 0, len(buf)
        while i < end:
            at = base + i
            if i + 4 > end:
                raise InputError(f"truncated or damaged ROS bag record at byte {at}", path=p)
            hl = struct.unpack_from("<i", buf, i)[0]
            if hl < 0 or i + 4 + hl + 4 > end:
                raise InputError(f"truncated or damaged ROS bag record at byte {at}", path=p)
            h = bytes(buf[i + 4:i + 4 + hl])
            dl = struct.unpack_from("<i", buf, i + 4 + hl)[0]
            d0 = i + 8 + hl
            if dl < 0 or d0 + dl > end:
                raise InputError(f"truncated or damaged ROS bag record at byte {at}", path=p)
            yield _fields(h, p, at), buf[d0:d0 + dl], at
            i = d0 + dl
        return
    fh = buf
    size = os.fstat(fh.fileno()).st_size
    while True:
        at = fh.tell()
        if stop is not None and at >= stop:
            return
        head = fh.read(4)
        if not head:
            return
        if len(head) < 4:
            raise InputError(f"truncated or damaged ROS bag record at byte {at}", path=p)
        hl = struct.unpack("<i", head)[0]
        if hl > size - at:
            raise InputError(f"truncated or damaged ROS bag record at byte {at}", path=p)
        h = fh.read(hl) if hl >= 0 else b""
        dlb = fh.read(4)
        if hl < 0 or len(h) < hl or len(dlb) < 4:
            raise InputError(f"truncated or damaged ROS bag record at byte {at}", path=p)
        dl = struct.unpack("<i", dlb)[0]
        if dl > size - at:
            raise InputError(f"truncated or damaged ROS bag record at byte {at}", path=p)
        data = fh.read(dl) if dl >= 0 else b""
        if dl < 0 or len(data) < dl:
            raise InputError(f"truncated or damaged ROS bag record at byte {at}", path=p)
        yield _fields(h, p, at), data, at


def _op(f: dict) -> int:
    v = f.get("op", b"")
    return v[0] if len(v) == 1 else -1


def _conn_of(f: dict, data, p: Path, at: int) -> Connection:
    try:
        cid = struct.unpack("<I", f["conn"])[0]
        topic = f["topic"].decode("utf-8")
        inner = _fields(bytes(data), p, at)
        msgtype = inner.get("type", b"").decode("utf-8")
    except (KeyError, struct.error, UnicodeDecodeError):
        raise InputError(f"damaged ROS bag connection record at byte {at}", path=p) from None
    return Connection(cid, topic, msgtype)


def connections(path) -> list[Connection]:
    """The connections of a ROS 1 bag (read from the index section at its end)."""
    p = Path(path)
    with open(p, "rb") as fh:
        if fh.read(len(_MAGIC)) != _MAGIC:
            raise InputError("not a ROS 1 bag (no '#ROSBAG V2.0' magic at byte 0)", path=p)
        f, _, at = next(_records(fh, 0, p), (None, None, 13))
        if f is None or _op(f) != _OP_HEADER or "index_pos" not in f:
            raise InputError(f"no bag header record at byte {at}", path=p)
        index_pos = struct.unpack("<Q", f["index_pos"])[0]
        size = p.stat().st_size
        if not 0 < index_pos <= size:
            raise InputError(f"ROS bag header points its index outside the file (byte "
                             f"{index_pos}, file {size} bytes): truncated, or the recording "
                             "was not closed", path=p)
        fh.seek(index_pos)
        out, counts = {}, {}
        for f, data, at in _records(fh, index_pos, p):
            if _op(f) == _OP_CONN:
                c = _conn_of(f, data, p, at)
                out[c.id] = c
            elif _op(f) == _OP_CHUNK_INFO and len(data) % 8 == 0:
                for cid, n in struct.iter_unpack("<II", data):
                    counts[cid] = counts.get(cid, 0) + n
    for cid, c in out.items():
        c.msgcount = counts.get(cid, 0)
    return list(out.values())


def _decompress(f: dict, data, p: Path, at: int) -> bytes:
    kind = f.get("compression", b"none").decode("ascii", "replace")
    try:
        declared = struct.unpack("<I", f["size"])[0] if len(f.get("size", b"")) == 4 else None
    except struct.error:  # pragma: no cover - guarded by the length test
        declared = None
    if kind in ("bz2", "lz4"):
        # a chunk says how large it inflates to: check it, and never inflate past it
        check_budget(declared if declared is not None else float("inf"),
                     f"the {kind} chunk at byte {at}", p)
    try:
        if kind == "none":
            return bytes(data)
        if kind == "bz2":
            out = bz2.BZ2Decompressor().decompress(data, max_length=declared + 1)
        elif kind == "lz4":
            import lz4.frame

            out = lz4.frame.LZ4FrameDecompressor().decompress(data, max_length=declared + 1)
        else:
            out = None
        if out is not None:
            if len(out) > declared:
                raise InputError(f"{kind} chunk at byte {at} inflates beyond its declared "
                                 f"{declared} bytes", path=p)
            return out
    except ImportError:
        raise InputError("reading an lz4-compressed bag needs the 'lz4' package: pip install "
                         "'inertialab[formats]'", path=p) from None
    except InputError:
        raise
    except Exception as exc:
        raise InputError(f"damaged {kind} chunk at byte {at} ({type(exc).__name__})",
                         path=p) from None
    raise InputError(f"unknown chunk compression '{kind}' at byte {at}", path=p)


def iter_messages(path, conn_ids: set[int]):
    """Yield ``(receive_time_ns, raw message bytes)`` of the connections ``conn_ids`` in
    file order (one chunk in memory at a time)."""
    p = Path(path)
    with open(p, "rb") as fh:
        fh.read(len(_MAGIC))
        f, _, _ = next(_records(fh, 0, p))
        index_pos = struct.unpack("<Q", f["index_pos"])[0]
        for f, data, at in _records(fh, 0, p, stop=index_pos):
            op = _op(f)
            if op == _OP_CHUNK:
                inner = _decompress(f, data, p, at)
                del data
                for g, raw, _ in _records(memoryview(inner), at, p):
                    if _op(g) == _OP_MSG:
                        cid = struct.unpack("<I", g["conn"])[0]
                        if cid in conn_ids:
                            sec, nsec = struct.unpack("<II", g["time"])
                            yield sec * 1_000_000_000 + nsec, raw
            elif op == _OP_MSG:
                cid = struct.unpack("<I", f["conn"])[0]
                if cid in conn_ids:
                    sec, nsec = struct.unpack("<II", f["time"])
                    yield sec * 1_000_000_000 + nsec, data
