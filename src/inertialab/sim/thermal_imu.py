"""Virtual lab rig ``thermal-imu``: a drone flight controller's MEMS IMUs on a temperature
ramp (cold soak, heating, cooling), logged as PX4 and ArduPilot users log them.

One :class:`ImuUnit` (drawn from ``unit_seed``) holds, per IMU instance, the temperature
model of the six offsets: a polynomial of order 3 or 5 in the *element* temperature,
scaled so that its steepest slope over -15..56 °C is a drawn fraction of the published
sizes (ArduPilot Methodic Configurator's vehicle templates: gyro up to 1.5e-4 rad/s/°C,
accelerometer up to 1.1e-3 m/s^2/°C). Instance 0 is shaped like an ICM-42688 (order 5
on gx, gz and az: the axes an order-3 fit leaves badly), instance 1 like a BMI088
(order 3 on every axis).

:func:`simulate` runs one ramp (:data:`RAMPS`): a piecewise-linear chamber profile, the
board's element temperature as a first-order lag of the chamber (``TAU_BOARD_S``), the
die temperature sensor as a first-order lag of the element (``tau_sensor_s`` per
instance, 20-45 s), a 0.05 °C reading noise and 1 °C quantisation of the reported
temperature (Bosch drivers, PX4 #13551). Each logged sample carries full-bandwidth white
noise (ICM-42688 densities 2.8e-3 °/s/√Hz and 70 µg/√Hz over a 500 Hz bandwidth: 1.1e-3
rad/s and 0.015 m/s^2) and a bias random walk (in-run stability of a few °/h). Truth
columns ``true_temp_c`` (element) and ``true_off_*`` (the temperature offset without
noise or random walk) come with every row.

:func:`ulog_bytes` writes the log as a PX4 ULog (``sensor_accel`` / ``sensor_gyro``, one
multi-instance each, with ``device_id`` and ``temperature``), following the ULog file
format specification (header, flag bits, formats, subscriptions, data), and
:func:`dataflash_bytes` as an ArduPilot DataFlash log (``FMT`` + ``IMU`` messages with
``I`` and ``T``), the binary layout pymavlink's ``DFReader`` reads.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.seeding import as_generator

GENERATOR = "inertialab.sim.thermal_imu"
GENERATOR_VERSION = "1"

G = 9.80665
#: Calibrated temperature range of the published coefficient sets (°C).
T_LO, T_HI = -15.0, 56.0
#: Largest slopes of the published sets: gyro rad/s/°C, accelerometer m/s^2/°C.
MAX_SLOPE = {"gyro": 1.5e-4, "accel": 1.1e-3}
#: Board (element) time constant behind the chamber air (s) [ours: a 10 g FMU board].
TAU_BOARD_S = 60.0
#: Per-sample white noise at full bandwidth (see the module docstring).
NOISE = {"gyro": 1.1e-3, "accel": 0.015}
#: Random-walk SD after one hour: gyro rad/s (≈ 4 °/h), accelerometer m/s^2 (≈ 20 µg).
RANDOM_WALK_1H = {"gyro": 2e-5, "accel": 2e-4}
AXES = ("ax", "ay", "az", "gx", "gy", "gz")
COLUMNS = ("ax_mps2", "ay_mps2", "az_mps2", "gx_rps", "gy_rps", "gz_rps")
#: Order of each axis per instance (instance 0 ICM-42688-like, 1 BMI088-like).
ORDERS = ({"ax": 3, "ay": 3, "az": 5, "gx": 5, "gy": 3, "gz": 5},
          {"ax": 3, "ay": 3, "az": 3, "gx": 3, "gy": 3, "gz": 3})
#: PX4 device ids of the two instances (bus/address/devtype packed as PX4 does).
DEVICE_IDS = ((2490378, 2621450), (3014666, 3080202))

#: Chamber profiles: (time s, chamber °C) corners. ``calibration``: cold soak at -15 °C,
#: heat at 1.2 °C/min to 56 °C, hold, cool at 0.9 °C/min; ``holdout``: another ramp of
#: the same unit (heat at 0.7 °C/min to 50 °C, cool fast at 2 °C/min, reheat to 30 °C);
#: ``heat``: an onboard-calibration-like heating only.
RAMPS = {
    "calibration": ((0, -15), (600, -15), (600 + 3550, 56), (600 + 3550 + 600, 56),
                    (600 + 3550 + 600 + 4733, -15), (600 + 3550 + 600 + 4733 + 300, -15)),
    "holdout": ((0, -12), (300, -12), (300 + 5314, 50), (300 + 5314 + 300, 50),
                (300 + 5314 + 300 + 1800, -10), (300 + 5314 + 300 + 1800 + 1200, 30)),
    "heat": ((0, -10), (300, -10), (300 + 4500, 50), (300 + 4500 + 300, 50)),
}


@dataclass(frozen=True)
class ImuInstance:
    """One IMU: ``coef[axis]`` power coefficients of the offset in ``u = (T_el - 20.5) /
    35.5`` (lowest power first, constant 0), ``order[axis]``, sensor lag (s), device ids
    and ``scale[axis]``: the accelerometer's scale-factor error in u (a tempco of
    20-50 ppm/°C and a small curvature: ICM-42688 and BMI088 data sheets give ±0.005 %/°C
    and ±0.002 %/K)."""

    index: int
    coef: dict
    order: dict
    tau_sensor_s: float
    accel_device_id: int
    gyro_device_id: int
    scale: dict | None = None

    def scale_errors(self, t_el: np.ndarray) -> dict:
        """True accelerometer scale-factor error per axis (dimensionless) at element
        temperatures (0 at 20.5 °C)."""
        u = (np.asarray(t_el, float) - 20.5) / 35.5
        return {a: np.polynomial.polynomial.polyval(u, self.scale[a]) for a in AXES[:3]}

    def offsets(self, t_el: np.ndarray) -> dict:
        """True temperature offset per axis (m/s^2 or rad/s) at element temperatures."""
        u = (np.asarray(t_el, float) - 20.5) / 35.5
        return {a: np.polynomial.polynomial.polyval(u, self.coef[a]) for a in AXES}


@dataclass(frozen=True)
class ImuUnit:
    unit_seed: int
    instances: tuple


def _axis_coef(rng, order: int, kind: str) -> np.ndarray:
    """A polynomial of ``order`` in u whose steepest slope over [-1, 1] is a drawn
    40-100 % of :data:`MAX_SLOPE` (per °C): a dominant linear term, and for order 5
    strong u^4 and u^5 terms."""
    c = np.zeros(order + 1)
    c[1] = rng.choice([-1.0, 1.0]) * rng.uniform(1.0, 1.5)
    c[2:] = rng.normal(0.0, 0.5, order - 1)
    if order >= 5:
        c[4:] = rng.choice([-1.0, 1.0], order - 3) * rng.uniform(0.5, 0.8, order - 3)
    u = np.linspace(-1, 1, 721)
    slope = np.max(np.abs(np.polynomial.polynomial.polyval(
        u, np.polynomial.polynomial.polyder(c)))) / 35.5
    return c * (rng.uniform(0.4, 1.0) * MAX_SLOPE[kind] / slope)


def make_unit(unit_seed: int = 0, n_instances: int = 2) -> ImuUnit:
    """The IMUs of one board, drawn from ``unit_seed`` (orders of :data:`ORDERS`)."""
    if not 1 <= int(n_instances) <= len(ORDERS):
        raise InputError(f"argument 'instances' must be 1..{len(ORDERS)}, got {n_instances}")
    rng = as_generator(np.random.SeedSequence([int(unit_seed), 7]))
    rng_scale = as_generator(np.random.SeedSequence([int(unit_seed), 13]))  # own stream
    out = []
    for i in range(int(n_instances)):
        coef = {a: _axis_coef(rng, ORDERS[i][a], "accel" if a[0] == "a" else "gyro")
                for a in AXES}
        scale = {a: np.array([0.0, rng_scale.choice([-1.0, 1.0]) * rng_scale.uniform(20, 50),
                              rng_scale.normal(0.0, 5.0)]) * 35.5e-6 for a in AXES[:3]}
        out.append(ImuInstance(i, coef, dict(ORDERS[i]), float(rng.uniform(20.0, 45.0)),
                               *DEVICE_IDS[i], scale=scale))
    return ImuUnit(int(unit_seed), tuple(out))


def _lag(x: np.ndarray, dt: float, tau: float, x0: float) -> np.ndarray:
    """First-order lag ``dy/dt = (x - y)/tau`` (exact discretisation, zero-order hold)."""
    from scipy.signal import lfilter

    a = np.exp(-dt / tau)
    y, _ = lfilter([1 - a], [1, -a], x, zi=[a * x0])
    return y


def chamber(ramp: str, rate_hz: float):
    """Time (s) and chamber temperature (°C) of ramp ``ramp`` sampled at ``rate_hz``."""
    if ramp not in RAMPS:
        raise InputError(f"argument 'ramp' must be one of {', '.join(RAMPS)}, got '{ramp}'")
    corners = np.asarray(RAMPS[ramp], float)
    t = np.arange(0.0, corners[-1, 0], 1.0 / rate_hz)
    return t, np.interp(t, corners[:, 0], corners[:, 1])


#: The six rest faces of a several-orientation log (specific force / g per axis, FRD):
#: level first, then upside down, nose down/up, right/left wing down; ``FACE_S`` each.
FACES = ((0, 0, -1), (0, 0, 1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0))
FACE_S = 120.0


def _instance_frame(inst: ImuInstance, t, t_ch, rate_hz, rng, faces: int) -> pd.DataFrame:
    dt = 1.0 / rate_hz
    t_el = _lag(t_ch, dt, TAU_BOARD_S, t_ch[0])
    t_sens = _lag(t_el, dt, inst.tau_sensor_s, t_el[0])
    reported = np.round(t_sens + rng.normal(0.0, 0.05, t.size))
    off = inst.offsets(t_el)
    cols = {"instance": np.full(t.size, inst.index), "t_s": t, "temp_c": reported}
    face = np.asarray(FACES, float)[(np.floor(t / FACE_S).astype(int) % faces)]
    scale = inst.scale_errors(t_el) if faces > 1 else {a: 0.0 for a in AXES[:3]}
    for k, (a, name) in enumerate(zip(AXES, COLUMNS)):
        kind = "accel" if a[0] == "a" else "gyro"
        walk = np.cumsum(rng.normal(0.0, RANDOM_WALK_1H[kind] * np.sqrt(dt / 3600.0), t.size))
        grav = G * face[:, k] * (1.0 + scale[a]) if kind == "accel" else 0.0
        cols[name] = grav + off[a] + walk + rng.normal(0.0, NOISE[kind], t.size)
    cols["true_temp_c"] = t_el
    for a in AXES:
        cols[f"true_off_{a}"] = off[a]
    if faces > 1:
        for k, a in enumerate(AXES[:3]):
            cols[f"true_scale_{a}"] = scale[a]
            cols[f"true_g_{a}"] = G * face[:, k]
    return pd.DataFrame(cols)


@dataclass
class ImuRampLog:
    """A simulated ramp: ``frame`` (every instance stacked, column ``instance``),
    ``unit`` and ``meta`` (generator, seeds, ramp)."""

    frame: pd.DataFrame
    unit: ImuUnit
    meta: dict


def simulate(unit_seed: int = 0, *, ramp: str = "calibration", rate_hz: float = 10.0,
             seed: int | None = None, n_instances: int = 2, faces: int = 1) -> ImuRampLog:
    """One ramp log of unit ``unit_seed``; ``seed`` draws the run noise (default the unit
    seed). ``faces`` 1: the board rests level (a level log sees a scale-factor drift only
    as an offset, so none is simulated); 6: it is turned through :data:`FACES` every
    ``FACE_S`` seconds and the accelerometers' scale factors drift too (columns
    ``true_scale_*``, ``true_g_*``). The same seeds give the same frame."""
    if faces not in (1, 6):
        raise InputError(f"argument 'faces' must be 1 or 6, got {faces}")
    if not 0.01 <= float(rate_hz) <= 1000.0:
        raise InputError(f"argument 'rate' must be in [0.01, 1000] Hz, got {rate_hz}")
    unit = make_unit(unit_seed, n_instances)
    run_seed = int(unit_seed if seed is None else seed)
    t, t_ch = chamber(ramp, float(rate_hz))
    frames = []
    for inst in unit.instances:
        rng = as_generator(np.random.SeedSequence([run_seed, 11, inst.index]))
        frames.append(_instance_frame(inst, t, t_ch, float(rate_hz), rng, faces))
    meta = {"generator": GENERATOR, "generator_version": GENERATOR_VERSION,
            "unit_seed": int(unit_seed), "seed": run_seed, "ramp": ramp, "faces": faces,
            "rate_hz": float(rate_hz),
            "device_ids": {str(i.index): {"accel": i.accel_device_id, "gyro": i.gyro_device_id}
                           for i in unit.instances},
            "tau_sensor_s": {str(i.index): i.tau_sensor_s for i in unit.instances},
            "orders": {str(i.index): i.order for i in unit.instances}}
    return ImuRampLog(pd.concat(frames, ignore_index=True), unit, meta)


# ------------------------------------------------------------------------- ULog writer

def _ulog_msg(kind: bytes, payload: bytes) -> bytes:
    return struct.pack("<HB", len(payload), kind[0]) + payload


_SENSOR_FORMAT = ("uint64_t timestamp;uint64_t timestamp_sample;uint32_t device_id;"
                  "float x;float y;float z;float temperature;uint32_t error_count;")


def ulog_bytes(log: ImuRampLog) -> bytes:
    """The log as a PX4 ULog (file format version 1): ``sensor_accel`` and
    ``sensor_gyro`` with one multi-instance per IMU (``x y z`` in m/s^2 or rad/s,
    ``temperature`` °C, ``device_id``), timestamps in µs."""
    out = [b"ULog\x01\x12\x35", bytes([1]), struct.pack("<Q", 0)]
    out.append(_ulog_msg(b"B", bytes(8) + bytes(8) + bytes(24)))
    for name in ("sensor_accel", "sensor_gyro"):
        out.append(_ulog_msg(b"F", f"{name}:{_SENSOR_FORMAT}".encode()))
    key, value = b"char[14] sys_name", b"inertialab-sim"
    out.append(_ulog_msg(b"I", bytes([len(key)]) + key + value))
    f = log.frame
    ids = {}
    for inst in log.unit.instances:
        for name in ("sensor_accel", "sensor_gyro"):
            msg_id = len(ids)
            ids[(inst.index, name)] = msg_id
            out.append(_ulog_msg(b"A", struct.pack("<BH", inst.index, msg_id) + name.encode()))
    rec = np.dtype([("size", "<u2"), ("kind", "u1"), ("msg_id", "<u2"), ("ts", "<u8"),
                    ("ts_sample", "<u8"), ("dev", "<u4"), ("x", "<f4"), ("y", "<f4"),
                    ("z", "<f4"), ("temp", "<f4"), ("err", "<u4")])
    blocks = []
    for inst in log.unit.instances:
        g = f[f["instance"] == inst.index]
        us = np.round(g["t_s"].to_numpy() * 1e6).astype(np.uint64) + np.uint64(1_000_000)
        for name, cols, dev, shift in (
                ("sensor_accel", COLUMNS[:3], inst.accel_device_id, 0),
                ("sensor_gyro", COLUMNS[3:], inst.gyro_device_id, 200)):
            a = np.zeros(len(g), rec)
            a["size"] = rec.itemsize - 3
            a["kind"] = ord("D")
            a["msg_id"] = ids[(inst.index, name)]
            a["ts"] = us + np.uint64(shift)
            a["ts_sample"] = us + np.uint64(shift)
            a["dev"] = dev
            a["x"], a["y"], a["z"] = (g[c].to_numpy() for c in cols)
            a["temp"] = g["temp_c"].to_numpy()
            blocks.append(a)
    allrec = np.concatenate(blocks)
    allrec = allrec[np.argsort(allrec["ts"], kind="stable")]
    return b"".join(out) + allrec.tobytes()


# -------------------------------------------------------------------- DataFlash writer

_DF_HEAD = b"\xa3\x95"


def _df_fmt(type_id: int, length: int, name: str, fmt: str, cols: str) -> bytes:
    return _DF_HEAD + bytes([128]) + struct.pack("<BB4s16s64s", type_id, length, name.encode(),
                                                 fmt.encode(), cols.encode())


def dataflash_bytes(log: ImuRampLog) -> bytes:
    """The log as an ArduPilot DataFlash ``.bin``: ``FMT`` records and one ``IMU`` message
    per sample and instance (``TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,T``; ArduPilot's
    body frame is the same FRD frame as PX4's)."""
    head = _df_fmt(128, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")
    rec = np.dtype([("h", "S2"), ("kind", "u1"), ("us", "<u8"), ("i", "u1"), ("gx", "<f4"),
                    ("gy", "<f4"), ("gz", "<f4"), ("ax", "<f4"), ("ay", "<f4"), ("az", "<f4"),
                    ("t", "<f4")])
    head += _df_fmt(130, rec.itemsize, "IMU", "QBfffffff", "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,"
                                                          "AccZ,T")
    f = log.frame
    a = np.zeros(len(f), rec)
    a["h"] = _DF_HEAD
    a["kind"] = 130
    a["us"] = np.round(f["t_s"].to_numpy() * 1e6).astype(np.uint64) + np.uint64(1_000_000)
    a["i"] = f["instance"].to_numpy()
    for k, c in zip(("ax", "ay", "az", "gx", "gy", "gz"), COLUMNS):
        a[k] = f[c].to_numpy()
    a["t"] = f["temp_c"].to_numpy()
    a = a[np.lexsort((a["i"], a["us"]))]
    return head + a.tobytes()
