"""Thermal-compensation parameter files of the two autopilots, their readers, and the
firmware's own evaluation of them (used by the tests and the benchmark).

PX4 (QGroundControl ``.params``, tab-separated ``vehicle component name value type``,
type 6 = int32, 9 = float, as ``Tools/process_sensor_caldata.py`` writes it): per sensor
``TC_<A|G><i>_ID`` (the device id the firmware matches), ``TC_<A|G><i>_TREF``, ``_TMIN``,
``_TMAX`` and ``TC_<A|G><i>_X<k>_<axis>`` (k = 0..3, axis 0..2), and the switches
``TC_A_ENABLE``/``TC_G_ENABLE``. The firmware (``TemperatureCompensation::
calc_thermal_offsets_3D``) clips the temperature to [TMIN, TMAX], forms ``d = T - TREF``
and *subtracts* ``X0 + X1 d + X2 d^2 + X3 d^3`` from the reading (:func:`px4_offset`).

ArduPilot (Mission Planner ``.param``, ``NAME,VALUE``): per IMU ``INS_TCAL<n>_ENABLE``,
``_TMIN``, ``_TMAX``, ``_ACC<k>_<X|Y|Z>``, ``_GYR<k>_<X|Y|Z>`` (k = 1..3, stored times
1e6). ``AP_InertialSensor_TCal::correct_sensor`` constrains both the temperature and the
calibration temperature (``INS_ACC<n>_CALTEMP``, ``INS_GYR<n>_CALTEMP``) to [TMIN, TMAX]
and applies ``v - P(T - 35) + P(T_cal - 35)`` with ``P(e) = (c1 + (c2 + c3 e) e) e *
1e-6``: a cubic without constant about a fixed 35 °C, relative to the temperature of the
last ordinary calibration (:func:`ardupilot_correct`).
"""

from __future__ import annotations

import numpy as np

from inertialab.errors import InputError

__all__ = ["AP_SCALE", "AP_TREF_C", "ardupilot_correct", "ardupilot_text", "px4_offset",
           "px4_text", "read_ardupilot", "read_px4", "write_ardupilot", "write_px4"]

#: ArduPilot's fixed reference temperature (°C) and parameter scale.
AP_TREF_C = 35.0
AP_SCALE = 1.0e6
_LETTER = {"accel": "A", "gyro": "G"}
_AP = {"accel": "ACC", "gyro": "GYR"}


def _num(v: float) -> str:
    return f"{float(v):.9g}"


def px4_text(sensors, *, comments=()) -> str:
    """QGroundControl ``.params`` text. ``sensors``: dicts with ``kind``, ``slot`` (the
    TC instance 0..3), ``device_id``, ``t_ref``, ``t_min``, ``t_max`` and ``x`` (4, 3):
    rows X0..X3, columns axes."""
    lines = ["# Sensor thermal compensation parameters (inertialab, drone IMU thermal fit)"]
    lines += [f"# {c}" for c in comments]
    lines += ["#", "# Vehicle-Id Component-Id Name Value Type"]
    for kind in ("accel", "gyro"):
        if any(s["kind"] == kind for s in sensors):
            lines.append(f"1\t1\tTC_{_LETTER[kind]}_ENABLE\t1\t6")
    for s in sensors:
        p = f"TC_{_LETTER[s['kind']]}{int(s['slot'])}_"
        lines.append(f"1\t1\t{p}ID\t{int(s['device_id'])}\t6")
        for key in ("TMAX", "TMIN", "TREF"):
            lines.append(f"1\t1\t{p}{key}\t{_num(s['t_' + key[1:].lower()])}\t9")
        x = np.asarray(s["x"], float)
        for k in range(4):
            for a in range(3):
                lines.append(f"1\t1\t{p}X{k}_{a}\t{_num(x[k, a])}\t9")
    return "\n".join(lines) + "\n"


def read_px4(text: str) -> dict:
    """Parameters of a QGroundControl ``.params`` text: name -> int or float."""
    out = {}
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        parts = line.split("\t")
        if len(parts) != 5:
            raise InputError(f"line {n}: expected 5 tab-separated fields, got {len(parts)}")
        out[parts[2]] = int(parts[3]) if parts[4].strip() == "6" else float(parts[3])
    return out


def px4_offset(params: dict, kind: str, slot: int, temp_c) -> np.ndarray:
    """The offsets (n, 3) PX4 subtracts at reported temperatures ``temp_c`` (float32, as
    the firmware computes them; clipped to [TMIN, TMAX])."""
    p = f"TC_{_LETTER[kind]}{int(slot)}_"
    f32 = np.float32
    t = np.asarray(temp_c, f32)
    tmin, tmax, tref = (f32(params[p + k]) for k in ("TMIN", "TMAX", "TREF"))
    d = np.where(t > tmax, tmax - tref, np.where(t < tmin, tmin - tref, t - tref)).astype(f32)
    d2 = d * d
    d3 = d2 * d
    x = [[f32(params[f"{p}X{k}_{a}"]) for a in range(3)] for k in range(4)]
    return np.column_stack([x[0][a] + x[1][a] * d + x[2][a] * d2 + x[3][a] * d3
                            for a in range(3)]).astype(np.float64)


def ardupilot_text(sensors, *, comments=()) -> str:
    """Mission Planner ``.param`` text. ``sensors``: one dict per IMU with ``imu`` (1-based),
    ``t_min``, ``t_max``, ``accel`` and ``gyro`` ((3, 3): rows c1..c3 in SI units per
    °C^k about 35 °C, columns axes), optional ``accel_caltemp``/``gyro_caltemp`` (°C)."""
    lines = ["# ArduPilot IMU temperature calibration (inertialab, drone IMU thermal fit)"]
    lines += [f"# {c}" for c in comments]
    for s in sensors:
        p = f"INS_TCAL{int(s['imu'])}_"
        lines += [f"{p}ENABLE,1", f"{p}TMIN,{_num(s['t_min'])}", f"{p}TMAX,{_num(s['t_max'])}"]
        for kind in ("accel", "gyro"):
            c = np.asarray(s[kind], float) * AP_SCALE
            for k in range(3):
                for a, ax in enumerate("XYZ"):
                    lines.append(f"{p}{_AP[kind]}{k + 1}_{ax},{_num(c[k, a])}")
        for kind in ("accel", "gyro"):
            if s.get(f"{kind}_caltemp") is not None:
                lines.append(f"INS_{_AP[kind]}{int(s['imu'])}_CALTEMP,"
                             f"{_num(s[kind + '_caltemp'])}")
    return "\n".join(lines) + "\n"


def read_ardupilot(text: str) -> dict:
    """Parameters of a ``.param`` text (``NAME,VALUE`` or ``NAME VALUE``): name -> float."""
    out = {}
    for n, line in enumerate(text.splitlines(), 1):
        s = line.split("#", 1)[0].strip()
        if not s:
            continue
        parts = s.replace(",", " ").split()
        if len(parts) != 2:
            raise InputError(f"line {n}: expected NAME,VALUE")
        out[parts[0]] = float(parts[1])
    return out


def ardupilot_correct(params: dict, kind: str, imu: int, temp_c, values, cal_temp_c) -> np.ndarray:
    """``values`` (n, 3) corrected as ``AP_InertialSensor_TCal::correct_sensor`` does at
    temperatures ``temp_c`` for a calibration made at ``cal_temp_c`` (float32)."""
    p = f"INS_TCAL{int(imu)}_"
    f32 = np.float32
    v = np.asarray(values, f32).copy()
    if int(params.get(p + "ENABLE", 0)) != 1:
        return v.astype(np.float64)
    lo, hi = f32(params[p + "TMIN"]), f32(params[p + "TMAX"])
    t = np.clip(np.asarray(temp_c, f32), lo, hi)
    tc = np.clip(f32(cal_temp_c), lo, hi)
    c = np.array([[params[f"{p}{_AP[kind]}{k}_{ax}"] for ax in "XYZ"] for k in (1, 2, 3)], f32)

    def poly(e):
        e = np.asarray(e, f32)[..., None]
        return (c[0] + (c[1] + c[2] * e) * e) * e * f32(1.0 / AP_SCALE)

    return (v - poly(t - f32(AP_TREF_C)) + poly(tc - f32(AP_TREF_C))).astype(np.float64)


def write_px4(model, path, o=None) -> list:
    """Write a ``thermal-imu`` model's PX4 file (its ``px4_sensors`` and residual
    notes) atomically; returns ``[path]``."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, px4_text(model.px4_sensors(), comments=model.residual_notes()))
    return [str(path)]


def write_ardupilot(model, path, o=None) -> list:
    """Write a ``thermal-imu`` model's ArduPilot file; option ``caltemp_c`` writes
    ``INS_ACCn_CALTEMP``/``INS_GYRn_CALTEMP`` (else the board keeps its own)."""
    from inertialab.io.writers import atomic_write_text

    cal = (o or {}).get("caltemp_c")
    notes = model.residual_notes() + [
        "the correction is relative to INS_ACCn_CALTEMP / INS_GYRn_CALTEMP, the temperature "
        "of the last accelerometer calibration and gyro calibration" +
        (f" (set here to {cal:g} C)" if cal is not None else
         " (kept as the board has them: calibrate the accelerometers after loading)")]
    atomic_write_text(path, ardupilot_text(model.ardupilot_sensors(caltemp_c=cal),
                                           comments=notes))
    return [str(path)]
