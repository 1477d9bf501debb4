"""PX4 ULog (``.ulg``) via ``pyulog`` (the ``[formats]`` extra).

Messages (``topic``):

* ``sensor_combined`` (default): ``gyro_rad[0..2]`` (rad/s) and
  ``accelerometer_m_s2[0..2]`` (m/s^2) at the gyro's ``timestamp`` (us);
* ``sensor_gyro`` / ``sensor_accel``: one raw sensor (``instance`` = the ULog multi id,
  default 0), ``x y z`` in rad/s or m/s^2 and ``temperature`` (deg C) at
  ``timestamp_sample`` (us) when logged, else ``timestamp``.

Only the chosen message is decoded (pyulog's message filter), so memory is about the
decoded arrays of that message. What the log's headers *declare* is checked before pyulog
acts on it: every subscription flattens its message format (nested types times array
sizes) into one Python object per field, so the fields of all subscriptions together are
bounded (:data:`MAX_FIELDS`; a format containing itself or nested deeper than
:data:`MAX_NESTING` is refused), and the decoded columns of the chosen message go
through :func:`inertialab.limits.check_budget` before they are allocated. A damaged log (pyulog reports corruption, or the header
does not parse) is refused with one line; pyulog's own console output is captured so
that it never reaches stdout. Stamps are audited, sorted and de-duplicated as for bags
(:func:`inertialab.io.formats.rosbag._to_loaded`).
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np

from inertialab.errors import InputError
from inertialab.io.formats.base import Loaded, need
from inertialab.limits import check_budget

__all__ = ["MAX_FIELDS", "MAX_NESTING", "ULOG_TOPICS", "read_ulog"]

ULOG_TOPICS = {
    "sensor_combined": (("gyro_rad[0]", "gyro_rad[1]", "gyro_rad[2]", "accelerometer_m_s2[0]",
                         "accelerometer_m_s2[1]", "accelerometer_m_s2[2]"),
                        ("gx_rps", "gy_rps", "gz_rps", "ax_mps2", "ay_mps2", "az_mps2")),
    "sensor_gyro": (("x", "y", "z", "temperature"), ("gx_rps", "gy_rps", "gz_rps", "temp_c")),
    "sensor_accel": (("x", "y", "z", "temperature"), ("ax_mps2", "ay_mps2", "az_mps2", "temp_c")),
}


#: Most fields the message formats of one log may flatten to, over all its subscriptions
#: (real PX4 logs: 350 to 2 300; pyulog builds about 600 bytes and 10 us per field, so
#: this bound is about 120 MB and 2 s).
MAX_FIELDS = 200_000
#: Deepest nesting of message formats (PX4's deepest is 3).
MAX_NESTING = 32


class _Declared(Exception):
    """A declaration of the log beyond a bound (raised inside pyulog's parser, which
    would take a ``ValueError`` for corruption and carry on)."""


def _flat_fields(name: str, formats: dict, memo: dict, scalar, depth: int = 0) -> int:
    """Scalar fields the message format ``name`` flattens to (nested types times their
    array sizes), without building them; 0 for an undefined format (pyulog reports it)."""
    if name in memo:
        if memo[name] is None:
            raise _Declared(f"message format '{name}' contains itself")
        return memo[name]
    if depth > MAX_NESTING:
        raise _Declared(f"message formats nested more than {MAX_NESTING} deep")
    fmt = formats.get(name)
    if fmt is None:
        return 0
    memo[name] = None  # on the stack
    n = 0
    for type_name, size, _field in fmt.fields:
        each = 1 if type_name in scalar else _flat_fields(type_name, formats, memo, scalar,
                                                           depth + 1)
        n = min(n + each * max(int(size), 1), 2 ** 62)
    memo[name] = n
    return n


def _bounded_parser(pyulog):
    """pyulog's ``ULog`` whose subscription messages are checked against
    :data:`MAX_FIELDS` before pyulog flattens their formats."""
    base = pyulog.ULog
    seen = {"fields": 0}
    memo: dict = {}

    class _AddLogged(base._MessageAddLogged):
        def __init__(self, data, header, message_formats):
            name = base.parse_string(data[3:])
            seen["fields"] += _flat_fields(name, message_formats, memo, base._UNPACK_TYPES)
            if seen["fields"] > MAX_FIELDS:
                raise _Declared(f"message formats declare more than {MAX_FIELDS} fields "
                                f"(a PX4 log has a few thousand)")
            super().__init__(data, header, message_formats)

    class _Bounded(base):
        _MessageAddLogged = _AddLogged

    return _Bounded


def read_ulog(path, *, topic: str | None = None, instance: int | None = None) -> Loaded:
    """Read one IMU message of a PX4 ULog into canonical columns."""
    pyulog = need("pyulog", "PX4 ULog files", path=path)
    p = Path(path)
    name = topic or "sensor_combined"
    if name not in ULOG_TOPICS:
        raise InputError(f"ULog message '{name}' is not an IMU message inertialab reads "
                         f"(known: {', '.join(ULOG_TOPICS)})", path=p)
    inst = 0 if instance is None else int(instance)
    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said):
            log = _bounded_parser(pyulog)(str(p), [name])
    except _Declared as exc:
        raise InputError(f"PX4 ULog refused before decoding: {exc}", path=p) from None
    except RecursionError:
        raise InputError("PX4 ULog refused before decoding: message formats nested too "
                         "deeply", path=p) from None
    except Exception as exc:  # pyulog raises ULogException and struct/index errors
        text = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise InputError(f"not a readable PX4 ULog ({text})", path=p) from None
    if getattr(log, "file_corruption", False):
        note = " ".join(said.getvalue().split())[:200] or "pyulog reports corruption"
        raise InputError(f"corrupt PX4 ULog ({note})", path=p)
    found = [d for d in log.data_list if d.name == name]
    if not found:
        raise InputError(f"no '{name}' messages in the log (truncated, or not logged)", path=p)
    chosen = [d for d in found if d.multi_id == inst]
    if not chosen:
        ids = sorted(d.multi_id for d in found)
        raise InputError(f"'{name}' has no instance {inst} (instances: "
                         f"{', '.join(map(str, ids))}; argument 'instance')", path=p)
    d = chosen[0].data
    fields, columns = ULOG_TOPICS[name]
    missing = [f for f in fields if f not in d]
    if missing:
        raise InputError(f"'{name}' lacks the fields {', '.join(missing)}", path=p)
    stamp = "timestamp_sample" if "timestamp_sample" in d and np.any(d["timestamp_sample"]) \
        else "timestamp"
    check_budget(len(d[stamp]) * 8.0 * (len(fields) + 1), f"decoding '{name}' "
                 f"({len(d[stamp])} samples)", path=p)
    t_ns = np.asarray(d[stamp], dtype=np.int64) * 1000
    v = np.column_stack([np.asarray(d[f], dtype=np.float64) for f in fields])
    from inertialab.io.formats.rosbag import _to_loaded

    out = _to_loaded(t_ns, v, p, topic=name, stamp_kind=f"{stamp} (us)", source="px4 ulog",
                     columns=columns, extra={"instance": inst,
                                             "instances": sorted(x.multi_id for x in found)})
    out.meta["time_origin"]["unit"] = "ns"
    return out
