"""Rig ``gyro-static``: a FOG at rest logging its rate (spec 001 §6.2).

Writes a ``gyro_log`` record (``t_s``, ``rate_dph``) with the §6.2 static noise model of
:mod:`inertialab.sensors.gyro` (no vibration), plus a truth table of the components and
the preset's Q N B K R in the sidecar (``truth_terms``), so the Allan analysis can be
checked against known values. Presets: ``mid`` (default §6.2 grade), ``nav``,
``tactical``, and the identification presets ``allan-rrw`` (N, K), ``allan-bi`` (N, B)
and ``allan-test`` (known Q, N, B, K in one record).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.limits import bounded, check_budget
from inertialab.sensors.gyro import (
    PRESETS,
    GyroNoiseParams,
    native_terms,
    simulate_gyro_components,
)
from inertialab.sensors.gyro import (
    preset as gyro_preset,
)

GENERATOR_VERSION = "gyro-static/1"

#: Earth rate in deg/h (WGS-84 7.292115e-5 rad/s).
EARTH_RATE_DPH = 15.041067

TERM_UNITS = {"Q": "arcsec", "N": "deg/sqrt(h)", "B": "deg/h", "K": "deg/h/sqrt(h)",
              "R": "deg/h^2"}


@dataclass(frozen=True)
class GyroStaticRun:
    """A simulated static gyro record: ``record`` (t_s, rate_dph), ``meta`` (sidecar) and
    ``truth`` (components in deg/h)."""

    record: pd.DataFrame
    meta: dict
    truth: pd.DataFrame


def simulate(preset: str = "allan-test", *, hours: float = 1.0, rate_hz: float = 10.0,
             seed: int = 0, latitude_deg: float = 32.06, heading_deg: float = 90.0,
             **overrides) -> GyroStaticRun:
    """Simulate a static FOG log.

    Parameters
    ----------
    preset : str, default "allan-test"
        One of :data:`inertialab.sensors.gyro.PRESETS`.
    hours : float, default 1.0
        Record length in hours.
    rate_hz : float, default 10.0
        Output rate in Hz.
    seed : int, default 0
        Root seed of the noise streams (:data:`inertialab.sensors.gyro.STREAMS`).
    latitude_deg, heading_deg : float, default 32.06, 90
        Site latitude and axis heading (spec 001 §6.1); the Earth-rate projection
        ``15.041 cos(lat) cos(heading)`` deg/h is the true input (0 for an east axis).
    **overrides
        Fields of :class:`~inertialab.sensors.gyro.GyroNoiseParams`.
    """
    if preset not in PRESETS:
        raise InputError(f"unknown gyro-static preset '{preset}' (use {', '.join(PRESETS)})")
    bad = set(overrides) - set(GyroNoiseParams.__dataclass_fields__)
    if bad:
        raise InputError(f"unknown simulate option(s): {', '.join(sorted(bad))}")
    for name, v in (("hours", hours), ("rate_hz", rate_hz)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise InputError(f"--{name.replace('_hz', '')} must be positive, got {v}")
    bounded("latitude_deg", latitude_deg, -90, 90)
    bounded("heading_deg", heading_deg, -1e4, 1e4)
    bounded("seed", seed, 0, 2**63 - 1)
    p = gyro_preset(preset).with_(**overrides)
    fs = float(rate_hz)
    # the record, its truth columns, the generator's work arrays and the CSV writer:
    # about 20 doubles per sample (measured: 10 h at 100 Hz peaks at 0.7 GB resident),
    # checked before any of them is allocated
    check_budget(hours * 3600.0 * fs * 20 * 8, f"a simulated record of {hours:g} h at "
                 f"{fs:g} Hz")
    n = int(round(hours * 3600.0 * fs))
    if n < 16:
        raise InputError(f"record too short: {n} samples (hours x 3600 x rate)")
    earth = EARTH_RATE_DPH * math.cos(math.radians(latitude_deg)) * math.cos(
        math.radians(heading_deg))
    if abs(earth) < 1e-12:
        earth = 0.0
    c = simulate_gyro_components(n, fs, p, int(seed), input_rate_dph=earth)
    t = np.arange(n) / fs
    record = pd.DataFrame({"t_s": t, "rate_dph": c.rate_dph})
    truth = pd.DataFrame({"true_white_dph": c.white, "true_gm_dph": c.bias_instability,
                          "true_rrw_dph": c.rrw, "true_ramp_dph": c.ramp,
                          "true_quantization_dph": c.quantization,
                          "true_static_dph": np.full(n, earth + p.b0_dph)})
    terms = native_terms(p)
    meta = {
        "fs_hz": fs,
        "units": {"rate": "dph"},
        "source": "virtual_lab",
        "seed": int(seed),
        "generator_version": GENERATOR_VERSION,
        "preset": preset,
        "hours": float(hours),
        "latitude_deg": float(latitude_deg),
        "heading_deg": float(heading_deg),
        "earth_rate_dph": float(earth),
        "gyro_id": f"virtual-fog-{preset}",
        "fog": p.to_dict(),
        "truth_terms": {k: {"value": float(v), "unit": TERM_UNITS[k]} for k, v in terms.items()},
    }
    return GyroStaticRun(record=record, meta=meta, truth=truth)


__all__ = ["EARTH_RATE_DPH", "GENERATOR_VERSION", "GyroStaticRun", "TERM_UNITS", "simulate"]
