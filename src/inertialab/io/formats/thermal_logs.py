"""Temperature-ramp logs of drone IMUs, read as one stream per sensor instance.

:func:`read_imu_thermal_log` reads, by suffix:

* ``.ulg`` (PX4 ULog, pyulog of the ``[formats]`` extra): every multi-instance of
  ``sensor_accel`` and ``sensor_gyro`` with ``x y z`` (m/s^2, rad/s), ``temperature``
  (°C) and ``device_id``, at ``timestamp_sample`` (µs) when logged, else ``timestamp``;
* ``.bin`` (ArduPilot DataFlash, pymavlink of the ``[formats]`` extra): every ``IMU``
  message (``I`` = instance; older logs: ``IMU``, ``IMU2``, ``IMU3``; ``GyrX..Z`` rad/s,
  ``AccX..Z`` m/s^2, ``T`` °C) at ``TimeUS``; device ids from the ``INS_ACC*_ID``/``INS_GYR*_ID`` parameters when the log
  has them, else 0;
* anything else as a table (CSV/whitespace text or Parquet) with the columns
  ``t_s, temp_c, ax_mps2, ay_mps2, az_mps2, gx_rps, gy_rps, gz_rps`` and optionally
  ``instance``, ``accel_device_id``, ``gyro_device_id``.

A non-finite temperature or value is refused with one line naming the sensor instance
(drivers do report NaN temperatures: PX4 #15582, #11854).
"""

from __future__ import annotations

import contextlib
import hashlib
import io
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.io.formats.base import need

__all__ = ["IMU_TABLE_COLUMNS", "ImuThermalLog", "SensorStream", "read_imu_thermal_log",
           "streams_from_frame"]

IMU_TABLE_COLUMNS = ("t_s", "temp_c", "ax_mps2", "ay_mps2", "az_mps2", "gx_rps", "gy_rps",
                     "gz_rps")


@dataclass
class SensorStream:
    """One sensor instance: ``kind`` ``accel`` (m/s^2) or ``gyro`` (rad/s), its
    ``instance`` and ``device_id``, time ``t_s`` (s), reported ``temp_c`` (°C) and
    ``values`` (n, 3) in the x, y, z order of the log."""

    kind: str
    instance: int
    device_id: int
    t_s: np.ndarray
    temp_c: np.ndarray
    values: np.ndarray

    @property
    def name(self) -> str:
        """``accel 0 (device 2490378)``: how messages name the stream."""
        return f"{self.kind} {self.instance} (device {self.device_id})"


@dataclass
class ImuThermalLog:
    """Every sensor stream of one log; ``source`` names the format."""

    path: str
    source: str
    streams: list
    sha256: str | None = None
    meta: dict = field(default_factory=dict)


def _check(stream: SensorStream, path) -> SensorStream:
    order = np.argsort(stream.t_s, kind="stable")
    stream.t_s, stream.temp_c = stream.t_s[order], stream.temp_c[order]
    stream.values = stream.values[order]
    bad_t = ~np.isfinite(stream.temp_c)
    if bad_t.any():
        raise InputError(f"{stream.name}: temperature is NaN or infinite at {int(bad_t.sum())} "
                         f"of {bad_t.size} samples (first at sample {int(np.argmax(bad_t)) + 1}); "
                         "a driver without a temperature cannot be calibrated", path=path)
    bad_v = ~np.all(np.isfinite(stream.values), axis=1) | ~np.isfinite(stream.t_s)
    if bad_v.any():
        raise InputError(f"{stream.name}: non-finite time or value at {int(bad_v.sum())} samples "
                         f"(first at sample {int(np.argmax(bad_v)) + 1})", path=path)
    if stream.t_s.size < 10:
        raise InputError(f"{stream.name}: only {stream.t_s.size} samples", path=path)
    return stream


def _ulog(path: Path) -> list:
    pyulog = need("pyulog", "PX4 ULog files", path=path)
    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said):
            log = pyulog.ULog(str(path), ["sensor_accel", "sensor_gyro"])
    except Exception as exc:  # pyulog raises ULogException and struct/index errors
        text = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise InputError(f"not a readable PX4 ULog ({text})", path=path) from None
    out = []
    for d in sorted(log.data_list, key=lambda d: (d.name, d.multi_id)):
        kind = "accel" if d.name == "sensor_accel" else "gyro"
        v = d.data
        missing = [k for k in ("x", "y", "z", "temperature") if k not in v]
        if missing:
            raise InputError(f"'{d.name}' instance {d.multi_id} lacks {', '.join(missing)}",
                             path=path)
        stamp = ("timestamp_sample" if "timestamp_sample" in v and np.any(v["timestamp_sample"])
                 else "timestamp")
        dev = int(np.median(v["device_id"])) if "device_id" in v else 0
        out.append(SensorStream(kind, int(d.multi_id), dev,
                                np.asarray(v[stamp], np.float64) * 1e-6,
                                np.asarray(v["temperature"], np.float64),
                                np.column_stack([np.asarray(v[k], np.float64)
                                                 for k in ("x", "y", "z")])))
    if not out:
        raise InputError("no 'sensor_accel' or 'sensor_gyro' messages (log the thermal "
                         "calibration profile: SDLOG_PROFILE bit 2)", path=path)
    return out


def _dataflash(path: Path) -> list:
    dfr = need("pymavlink.DFReader", "ArduPilot DataFlash logs", path=path)
    try:
        reader = dfr.DFReader_binary(str(path))
    except Exception as exc:
        text = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise InputError(f"not a readable DataFlash log ({text})", path=path) from None
    rows, params = [], {}
    while True:
        m = reader.recv_match(type=["IMU", "IMU2", "IMU3", "PARM"])
        if m is None:
            break
        kind = m.get_type()
        if kind == "PARM":
            params[m.Name] = m.Value
            continue
        # newer ArduPilot logs IMU with an instance field I; older ones IMU, IMU2, IMU3
        inst = getattr(m, "I", None) if kind == "IMU" else int(kind[-1]) - 1
        rows.append((m.TimeUS, inst or 0, m.T, m.AccX, m.AccY, m.AccZ, m.GyrX, m.GyrY, m.GyrZ))
    if not rows:
        raise InputError("no IMU messages in the DataFlash log", path=path)
    a = np.asarray(rows, np.float64)
    out = []
    for i in np.unique(a[:, 1]).astype(int):
        r = a[a[:, 1] == i]
        n = "" if i == 0 else str(i + 1)
        for kind, cols, key in (("accel", slice(3, 6), f"INS_ACC{n}_ID"),
                                ("gyro", slice(6, 9), f"INS_GYR{n}_ID")):
            out.append(SensorStream(kind, int(i), int(params.get(key, 0)), r[:, 0] * 1e-6,
                                    r[:, 2], r[:, cols].copy()))
    return out


def _table(path: Path) -> list:
    try:
        if path.suffix.lower() in (".parquet", ".pq"):
            f = pd.read_parquet(path)
        else:
            f = pd.read_csv(path, sep=None, engine="python", comment="#")
    except (OSError, ValueError, ImportError) as exc:
        raise InputError(f"cannot read the table ({' '.join(str(exc).split())[:120]})",
                         path=path) from None
    return _frame_streams(f, path=path)


def _frame_streams(f: pd.DataFrame, *, path="<frame>") -> list:
    f = f.copy()
    f.columns = [str(c).strip().lower() for c in f.columns]
    for c in IMU_TABLE_COLUMNS:
        if c not in f.columns:
            raise InputError(f"missing required column (need {', '.join(IMU_TABLE_COLUMNS)})",
                             path=path, column=c)
        vals = pd.to_numeric(f[c], errors="coerce")
        if c != "temp_c" and vals.isna().any():
            raise InputError("not a number", path=path, column=c,
                             row=int(np.flatnonzero(vals.isna().to_numpy())[0]) + 2)
        f[c] = vals
    inst = f["instance"].astype(int) if "instance" in f.columns else pd.Series(0, index=f.index)
    out = []
    for i in sorted(inst.unique()):
        g = f[inst == i]
        for kind, cols in (("accel", ["ax_mps2", "ay_mps2", "az_mps2"]),
                           ("gyro", ["gx_rps", "gy_rps", "gz_rps"])):
            dev_col = f"{kind}_device_id"
            dev = int(g[dev_col].iloc[0]) if dev_col in g.columns else 0
            out.append(SensorStream(kind, int(i), dev, g["t_s"].to_numpy(float),
                                    g["temp_c"].to_numpy(float), g[cols].to_numpy(float)))
    return out


def streams_from_frame(frame: pd.DataFrame, *, path="<frame>") -> ImuThermalLog:
    """A table already in memory (the columns of :data:`IMU_TABLE_COLUMNS`) as a log."""
    return ImuThermalLog(str(path), "table", [_check(s, path) for s in _frame_streams(frame)])


def read_imu_thermal_log(path) -> ImuThermalLog:
    """Read a temperature-ramp log (module docstring) into checked sensor streams."""
    p = Path(path)
    if not p.is_file():
        raise InputError("no such file", path=p)
    suffix = p.suffix.lower()
    if suffix == ".ulg":
        streams, source = _ulog(p), "px4 ulog"
    elif suffix == ".bin":
        streams, source = _dataflash(p), "ardupilot dataflash"
    else:
        streams, source = _table(p), "table"
    sha = hashlib.sha256(p.read_bytes()).hexdigest()
    return ImuThermalLog(str(p), source, [_check(s, p) for s in streams], sha256=sha)
