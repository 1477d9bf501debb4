"""Cut a few seconds of a real PX4 ULog into tests/data/px4 (run from the repository root).

    python tests/data/px4/make_cut.py SRC.ulg OUT.ulg SECONDS [TOPIC ...]

Byte-level, at message boundaries (ULog file format, docs.px4.io "ULog File Format"):
the 16-byte header and every definition message are kept; of the data section, the
data ('D') messages of the named topics (default: every topic) whose timestamp lies in
the first SECONDS of the log, and every other non-data message in that span. The
appended-data offsets of a flag-bits ('B') message are zeroed (the cut holds no
appended section). Nothing is re-encoded: each kept message is the original bytes.
"""

from __future__ import annotations

import struct
import sys


def _messages(buf: bytes, pos: int):
    while pos + 3 <= len(buf):
        size, mtype = struct.unpack_from("<HB", buf, pos)
        end = pos + 3 + size
        if end > len(buf):
            return
        yield pos, mtype, buf[pos:end]
        pos = end


def cut(src: str, out: str, seconds: float, topics=()) -> None:
    buf = open(src, "rb").read()
    header = bytearray(buf[:16])
    kept = [bytes(header)]
    subs = {}  # msg_id -> topic name
    t0 = None
    data_started = False
    for _pos, mtype, msg in _messages(buf, 16):
        payload = msg[3:]
        if mtype == ord("B"):
            msg = bytearray(msg)
            msg[3 + 8 + 8:3 + 8 + 8 + 24] = b"\0" * 24  # appended_offsets[3]
            msg[3 + 8] &= 0xFE  # incompat flag 0: DATA_APPENDED
            kept.append(bytes(msg))
            continue
        if mtype == ord("A"):
            msg_id = struct.unpack_from("<H", payload, 1)[0]
            subs[msg_id] = payload[3:].decode("ascii", "replace")
            data_started = True
            kept.append(msg)
            continue
        if mtype == ord("D"):
            data_started = True
            msg_id = struct.unpack_from("<H", payload, 0)[0]
            ts = struct.unpack_from("<Q", payload, 2)[0] / 1e6
            t0 = ts if t0 is None else t0
            if ts - t0 > seconds:
                continue
            if topics and subs.get(msg_id) not in topics:
                continue
            kept.append(msg)
            continue
        if not data_started or mtype in (ord("F"), ord("I"), ord("M"), ord("P"), ord("Q")):
            kept.append(msg)  # definitions and parameters
            continue
        if mtype == ord("L") or mtype == ord("C"):
            ts = struct.unpack_from("<Q", payload, 1 if mtype == ord("L") else 3)[0] / 1e6
            if t0 is not None and ts - t0 > seconds:
                continue
        kept.append(msg)
    with open(out, "wb") as fh:
        fh.write(b"".join(kept))


if __name__ == "__main__":
    cut(sys.argv[1], sys.argv[2], float(sys.argv[3]), tuple(sys.argv[4:]))
