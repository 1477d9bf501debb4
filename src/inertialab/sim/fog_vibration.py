"""Virtual lab ``fog-vibration``: a simulated FOG on a linear shaker (spec 001 §6).

:func:`simulate` produces one run of the seed's two experiments, each with three phases
(P1 static, P2 vibration, P3 static):

- ``"sweep"`` (E1): logarithmic sweep ``f(t) = f_start 2^((t - t_on)/60 s)`` (1 oct/min)
  from 1 Hz to 500 Hz, then a 5-s dwell at 500 Hz (P2 = 542.9 s);
- ``"fixed"`` (E2): 500 Hz for 1800 s.

P1 = P3 = 1800 s at fs = 200 Hz, a = 5 g peak, Nanjing latitude 32.06 deg, sensitive
axis east (heading 90 deg, Earth-rate projection 0). The result is the spec's §2.2
record (``t_s, rate_dph, vib_on, vib_freq_hz, vib_acc_g, phase``), its sidecar keys,
and a truth table (the lagged bias shift and every error component) for tests.

Static FOG: :func:`inertialab.sensors.gyro.simulate_gyro_components` (spec §6.2, preset
``"mid"`` by default), which spawns its streams from ``SeedSequence(seed)`` in the fixed
order white, GM1..GM5, RRW, jitter, spare. The vibration effects of spec §6.3 come from
:mod:`inertialab.sensors.gyro_vibration`: the deterministic ones (lagged bias shift,
fixture thermal drift, edge transients, drive lines) enter as the input rate before the
angle quantizer, the noise increases as per-sample multipliers of the static streams.

Same arguments give bit-identical output on one platform (spec §6.4).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.limits import bounded, check_budget
from inertialab.sensors.gyro import GyroNoiseParams, simulate_gyro_components
from inertialab.sensors.gyro import preset as gyro_preset
from inertialab.sensors.gyro_vibration import (
    VibrationEffects,
    bias_shift_dph,
    drive_phase_rad,
    edge_transient_dph,
    first_order_lag,
    noise_multipliers,
    thermal_drift_dph,
    vibration_lines_dph,
)

__all__ = [
    "EARTH_RATE_DPH",
    "GENERATOR_VERSION",
    "FogVibrationRun",
    "RigSettings",
    "simulate",
]

GENERATOR_VERSION = "fog-vibration/1"
#: Earth rate in deg/h (spec 001 §1).
EARTH_RATE_DPH = 15.041


@dataclass(frozen=True)
class RigSettings:
    """Timing and environment of a run (spec 001 §6.1 defaults, all [A]).

    Attributes
    ----------
    fs_hz : float, default=200.0
    p1_s, p3_s : float, default=1800.0
        Static phases before and after vibration.
    p2_fixed_s : float, default=1800.0
        Vibration time of the fixed run.
    f_fixed_hz : float, default=500.0
    f_start_hz, f_end_hz : float, default 1 and 500
        Sweep range.
    sweep_oct_per_min : float, default=1.0
    dwell_end_s : float, default=5.0
        Dwell at ``f_end`` after the sweep.
    acc_g : float, default=5.0
        Acceleration amplitude, g peak.
    latitude_deg : float, default=32.06
    heading_deg : float, default=90.0
        Angle between sensitive axis and north (90: east, Earth-rate projection 0).
    """

    fs_hz: float = 200.0
    p1_s: float = 1800.0
    p3_s: float = 1800.0
    p2_fixed_s: float = 1800.0
    f_fixed_hz: float = 500.0
    f_start_hz: float = 1.0
    f_end_hz: float = 500.0
    sweep_oct_per_min: float = 1.0
    dwell_end_s: float = 5.0
    acc_g: float = 5.0
    latitude_deg: float = 32.06
    heading_deg: float = 90.0


@dataclass(frozen=True)
class FogVibrationRun:
    """One simulated run.

    Attributes
    ----------
    record : DataFrame
        The §2.2 record (``t_s, rate_dph, vib_on, vib_freq_hz, vib_acc_g, phase``).
    meta : dict
        Sidecar keys of §2.2 plus ``preset``, ``t_on_s``, ``t_off_s`` and the settings.
    truth : DataFrame
        ``true_bias_vib_dph`` (b_v after the lag), ``true_white_dph``, ``true_gm_dph``,
        ``true_rrw_dph``, ``true_ramp_dph``, ``true_thermal_dph``, ``true_edge_dph``,
        ``true_lines_dph``, ``true_static_dph`` (b0 + Earth rate) and
        ``true_rate_dph`` (before quantization).
    """

    record: pd.DataFrame
    meta: dict
    truth: pd.DataFrame


def _profile(experiment: str, s: RigSettings):
    """Drive frequency per sample and the on/off indices."""
    fs = s.fs_hz
    if experiment == "sweep":
        if not 0 < s.f_start_hz < s.f_end_hz:
            raise InputError(f"sweep needs 0 < f_start < f_end, got {s.f_start_hz}, {s.f_end_hz}")
        sweep_s = 60.0 * math.log2(s.f_end_hz / s.f_start_hz) / s.sweep_oct_per_min
        p2_s = sweep_s + s.dwell_end_s
    elif experiment == "fixed":
        p2_s = s.p2_fixed_s
    else:
        raise InputError(f"experiment must be 'sweep' or 'fixed', got {experiment!r}")
    n1 = int(round(s.p1_s * fs))
    n2 = int(round(p2_s * fs))
    n3 = int(round(s.p3_s * fs))
    if min(n1, n2, n3) < 1:
        raise InputError("every phase must contain at least one sample")
    n = n1 + n2 + n3
    # the record, truth and noise streams: about 20 doubles per sample
    check_budget(n * 20 * 8, f"a simulated vibration run of {n} samples")
    f = np.zeros(n)
    dt = np.arange(n2) / fs
    if experiment == "sweep":
        f2 = s.f_start_hz * 2.0 ** (dt * s.sweep_oct_per_min / 60.0)
        f[n1:n1 + n2] = np.minimum(f2, s.f_end_hz)
    else:
        f[n1:n1 + n2] = s.f_fixed_hz
    return f, n1, n1 + n2 - 1, p2_s


def _check_overrides(overrides: dict, s) -> None:
    """Every numeric override finite and of a sane magnitude; the vibration within 1000 g;
    a positive sample rate."""
    if not s.fs_hz > 0:
        raise InputError(f"fs_hz must be positive, got {s.fs_hz}")
    for name in sorted(overrides):
        if isinstance(overrides[name], (int, float)) and not isinstance(overrides[name], bool):
            bounded(name, overrides[name], -1e9, 1e9)
    bounded("acc_g", s.acc_g, 0, 1000)


def _settings(preset: str, overrides: dict):
    """The rig settings and the static FOG parameters of ``preset`` with ``overrides``
    (fields of either), checked."""
    if preset not in ("mid", "nav", "tactical"):
        raise InputError(f"unknown preset {preset!r} (known: mid, nav, tactical)")
    rig_keys = set(RigSettings.__dataclass_fields__)
    fog_keys = set(GyroNoiseParams.__dataclass_fields__)
    bad = set(overrides) - rig_keys - fog_keys
    if bad:
        raise InputError(f"unknown simulate option(s): {', '.join(sorted(bad))}")
    s = replace(RigSettings(), **{k: v for k, v in overrides.items() if k in rig_keys})
    p = gyro_preset(preset).with_(**{k: v for k, v in overrides.items() if k in fog_keys})
    _check_overrides(overrides, s)
    return s, p


def _vibration_effects(t, f, on, s: RigSettings, e: VibrationEffects, fs: float,
                       t_on: float, t_off: float):
    """The vibration effects of spec 001 §6.3, deg/h: the lagged bias shift, the thermal
    drift, the edge transients and the spectral lines."""
    bv_in = np.where(on, bias_shift_dph(f, s.acc_g, e), 0.0)
    bias_vib = first_order_lag(bv_in, e.bias_lag_s, fs)
    thermal = thermal_drift_dph(t, t_on, t_off, e)
    edge = edge_transient_dph(t, (t_on, t_off), e)
    lines = vibration_lines_dph(drive_phase_rad(f, fs), f, fs, vib_on=on, effects=e)
    return bias_vib, thermal, edge, lines


def _meta(experiment: str, seed: int, preset: str, vibration: bool, s: RigSettings, p,
          e: VibrationEffects, fs: float, t_on: float, t_off: float, p2_s: float) -> dict:
    """The record's sidecar: the drive, the rig, the FOG grade and the effects."""
    sweep = experiment == "sweep"
    return {
        "fs_hz": fs,
        "experiment": experiment,
        "sweep_law": "log" if sweep else None,
        "sweep_rate_oct_per_min": s.sweep_oct_per_min if sweep else None,
        "f_start_hz": s.f_start_hz if sweep else s.f_fixed_hz,
        "f_end_hz": s.f_end_hz if sweep else s.f_fixed_hz,
        "dwell_end_s": s.dwell_end_s if sweep else None,
        "acc_g": s.acc_g,
        "axis": "x",
        "latitude_deg": s.latitude_deg,
        "heading_deg": s.heading_deg,
        "gyro_id": f"virtual-fog-{preset}",
        "units": {"rate": "dph"},
        "source": "virtual_lab",
        "seed": int(seed),
        "generator_version": GENERATOR_VERSION,
        "preset": preset,
        "vibration_effects": vibration,
        "t_on_s": float(t_on),
        "t_off_s": float(t_off),
        "p2_s": float(p2_s),
        "rig": asdict(s),
        "fog": p.to_dict(),
        "effects": e.to_dict(),
    }


def simulate(experiment: str = "fixed", seed: int = 0, preset: str = "mid", *,
             effects: VibrationEffects | None = None, vibration: bool = True,
             **overrides) -> FogVibrationRun:
    """Simulate one FOG vibration run (spec 001 §6).

    Parameters
    ----------
    experiment : {"fixed", "sweep"}, default="fixed"
        E2 (500 Hz constant) or E1 (1-500 Hz log sweep plus end dwell).
    seed : int, default=0
        Root of ``SeedSequence(seed)`` for the static model's streams.
    preset : {"mid", "nav", "tactical"}, default="mid"
        Static FOG grade (spec §6.2).
    effects : VibrationEffects, optional
        Vibration effects (default: spec §6.3).
    vibration : bool, default=True
        False keeps the drive columns but switches every vibration effect off
        (a control run).
    **overrides
        Fields of :class:`RigSettings` (``fs_hz``, ``p1_s``, ``acc_g`` ...) or of
        :class:`inertialab.sensors.gyro.GyroNoiseParams` (``b0_dph``, ``arw_deg_rth`` ...).

    Returns
    -------
    FogVibrationRun
    """
    s, p = _settings(preset, overrides)
    e = effects or VibrationEffects()
    fs = float(s.fs_hz)
    tau0 = 1.0 / fs

    f, k_on, k_off, p2_s = _profile(experiment, s)
    n = f.size
    t = np.arange(n) * tau0
    on = np.zeros(n, dtype=bool)
    on[k_on:k_off + 1] = True
    phase = np.ones(n, dtype=np.int8)
    phase[k_on:k_off + 1] = 2
    phase[k_off + 1:] = 3
    t_on, t_off = t[k_on], t[k_off]

    mult = noise_multipliers(on if vibration else np.zeros(n, bool), f, e)
    # static output: Earth rate projection (b0 is added by the static model)
    earth = EARTH_RATE_DPH * math.cos(math.radians(s.latitude_deg)) * math.cos(
        math.radians(s.heading_deg))
    if vibration:
        bias_vib, thermal, edge, lines = _vibration_effects(t, f, on, s, e, fs, t_on, t_off)
    else:
        bias_vib = thermal = edge = lines = np.zeros(n)

    effect = bias_vib + thermal + edge + lines
    comp = simulate_gyro_components(n, fs, p, int(seed), input_rate_dph=earth + effect,
                                    multipliers=mult)
    static = earth + p.b0_dph
    omega = static + comp.white + comp.bias_instability + comp.rrw + comp.ramp + effect
    record = pd.DataFrame({
        "t_s": t,
        "rate_dph": comp.rate_dph,
        "vib_on": on.astype(np.int8),
        "vib_freq_hz": f,
        "vib_acc_g": np.where(on, s.acc_g, 0.0),
        "phase": phase,
    })
    truth = pd.DataFrame({
        "true_bias_vib_dph": bias_vib,
        "true_white_dph": comp.white,
        "true_gm_dph": comp.bias_instability,
        "true_rrw_dph": comp.rrw,
        "true_ramp_dph": comp.ramp,
        "true_thermal_dph": thermal,
        "true_edge_dph": edge,
        "true_lines_dph": lines,
        "true_static_dph": np.full(n, static),
        "true_rate_dph": omega,
    })
    meta = _meta(experiment, seed, preset, vibration, s, p, e, fs, t_on, t_off, p2_s)
    return FogVibrationRun(record=record, meta=meta, truth=truth)
