"""Virtual lab rig ``thermal-tumble``: quartz flexure accelerometers of one production lot
tumbled through 24 positions at 23 chamber set points (spec 000 §7).

A :class:`Lot` is drawn from one integer ``lot_seed``; :meth:`Lot.unit` gives the
constants of unit ``i``; :func:`run_tumble` simulates one test run of a unit (chamber
wander, first-order element and sensor lag integrated with 1-s Euler steps, bias
random walk, white noise, dividing-head angle errors, voltmeter resolution) and
returns the spec 000 §2.3 record with its ``true_*`` columns.

Random streams (fixed order, so the same seed gives the same numbers):
``SeedSequence(lot_seed)`` child 0 = the rig (dividing-head angle errors shared by
every run of the lot's rig), child ``1 + i`` = unit ``i``; the run noise comes from
``seed`` (default ``lot_seed``), drawn in the order chamber offsets/amplitudes/phases,
temperature-reading noise, per-visit angle errors, white noise, random walk.

Hysteresis (realistic preset) uses the direction of the schedule's temperature steps
(+1 on the up pass, -1 on the down pass) for ``sign(dT/dt)``; the literal derivative
during a soak is dominated by the chamber wander and flips every few minutes.

References
----------
Spec 000 §7 (presets, drift model, schedule, noise), §2.3 (record).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd
from scipy.signal import lfilter

from inertialab.errors import InputError
from inertialab.seeding import as_generator
from inertialab.sensors.pendulous import SingleAxisCoefficients, tumble_positions
from inertialab.units import ARCSEC

GENERATOR = "inertialab.sim.thermal_tumble"
GENERATOR_VERSION = "1"

#: Reference temperature of spec 000 (°C).
T_REF = 55.0

#: Lot-nominal drift coefficients of spec 000 §7.2 (µg/°C^k, µg, °C, ppm/°C^k, µg/g^2/°C).
LOT_NOMINAL = {
    "b1": 12.0, "b2": -0.035, "b3": 2e-4, "bk": 60.0,
    "s1": 27.0, "s2": -0.05, "u1": 5.0, "k2T": 0.2,
}
TK_NOMINAL = 0.0
WK = 8.0


@dataclass(frozen=True)
class Preset:
    """Error-source magnitudes of a preset (spec 000 §7).

    Attributes
    ----------
    name : "paper" or "realistic"
    temp_offset_sd_c : temperature-sensor offset SD per unit, °C (0.05 / 0.5)
    kd_urad_per_c : misalignment drift, µrad/°C (0.01 / 1.0)
    sr : relative unit-to-unit spread of the drift coefficients (0.001 / 0.15)
    st_c : spread of the bias-step temperature Tk, °C (0.05 / 3)
    tau_sensor_s : internal temperature-sensor lag, s (None = equal to the element)
    hysteresis_ug : bias hysteresis h_dir, µg (0 / 3)
    """

    name: str
    temp_offset_sd_c: float
    kd_urad_per_c: float
    sr: float
    st_c: float
    tau_sensor_s: float | None
    hysteresis_ug: float


PRESETS = {
    "paper": Preset("paper", 0.05, 0.01, 0.001, 0.05, None, 0.0),
    "realistic": Preset("realistic", 0.5, 1.0, 0.15, 3.0, 120.0, 3.0),
}


@dataclass(frozen=True)
class Schedule:
    """Test schedule (spec 000 §7.4).

    Set points ascending from ``t_min`` to ``t_max`` every ``t_step`` °C; ``soak_s``
    before the tumble; each position ``settle_s`` then ``record_s`` of recording;
    ``ramp`` "up" or "up_down" (a descending pass follows, ``ramp_dir = "down"``).
    """

    t_min: float = -40.0
    t_max: float = 70.0
    t_step: float = 5.0
    soak_s: int = 1800
    settle_s: int = 10
    record_s: int = 10
    n_positions: int = 24
    ramp: str = "up"
    rate_hz: float = 100.0

    def set_points(self) -> np.ndarray:
        n = int(round((self.t_max - self.t_min) / self.t_step)) + 1
        return self.t_min + self.t_step * np.arange(n)


@dataclass(frozen=True)
class Rig:
    """Rig constants: dividing-head angle error per position (arcsec, fixed), per-visit
    angle error SD (arcsec), element lag (s), white noise (µg, 10-s mean), bias random
    walk (µg/sqrt(h)), voltmeter resolution (mV)."""

    angle_error_arcsec: np.ndarray
    visit_angle_sd_arcsec: float = 0.5
    tau_element_s: float = 360.0
    white_ug: float = 0.5
    random_walk_ug_per_rth: float = 1.0
    resolution_mv: float = 0.001
    sample_noise_ug: float = 7.0


@dataclass(frozen=True)
class UnitParams:
    """Constants of one unit (spec 000 §7.1, §7.3).

    ``ref`` holds the 55 °C coefficients K0c, K1c, K2c, Kipc, Kpc (mV/g^k); ``coef`` the
    unit's drift coefficients (keys of :data:`LOT_NOMINAL`); ``tk_c``/``wk_c`` the bias
    step; ``delta_c_urad`` the 55 °C misalignment; ``kd_urad_per_c`` its drift;
    ``temp_offset_c`` the internal sensor's offset; ``hysteresis_ug`` h_dir.
    """

    unit_id: str
    lot_id: str
    index: int
    ref: SingleAxisCoefficients
    coef: dict
    tk_c: float
    wk_c: float
    delta_c_urad: float
    kd_urad_per_c: float
    temp_offset_c: float
    hysteresis_ug: float

    def bias_drift_ug(self, t_el) -> np.ndarray:
        """dK0(T) in µg (spec 000 §7.2)."""
        c = self.coef
        dT = np.asarray(t_el, dtype=float) - T_REF
        step = np.tanh((dT + T_REF - self.tk_c) / self.wk_c) - np.tanh((T_REF - self.tk_c) / self.wk_c)
        return c["b1"] * dT + c["b2"] * dT**2 + c["b3"] * dT**3 + c["bk"] * step

    def scale_drift_ppm(self, t_el, a_i) -> np.ndarray:
        """dS(T, a_i) in ppm (spec 000 §7.2)."""
        c = self.coef
        dT = np.asarray(t_el, dtype=float) - T_REF
        return c["s1"] * dT + c["s2"] * dT**2 + np.sign(a_i) * c["u1"] * dT

    def output_mv(self, t_el, a_i, a_p, hyst_sign=0.0) -> np.ndarray:
        """Noise-free output in mV at element temperature ``t_el`` (°C) and true inputs
        ``a_i``, ``a_p`` (g) (spec 000 §7.2)."""
        a_i = np.asarray(a_i, dtype=float)
        a_p = np.asarray(a_p, dtype=float)
        dT = np.asarray(t_el, dtype=float) - T_REF
        r = self.ref
        dk0 = self.bias_drift_ug(t_el) + self.hysteresis_ug * np.asarray(hyst_sign, dtype=float)
        ds = self.scale_drift_ppm(t_el, a_i)
        k2 = r.k2 + 1e-6 * self.coef["k2T"] * dT * r.k1
        delta = self.delta_c_urad + self.kd_urad_per_c * dT
        return (r.k0 + r.k1 * (dk0 * 1e-6 + (1.0 + ds * 1e-6) * a_i + 1e-6 * delta * a_p)
                + k2 * a_i**2 + r.kip * a_i * a_p)


def drift_truth(unit: UnitParams, t_el, a_i, a_p=None) -> np.ndarray:
    """Output drift relative to 55 °C, in g: ``(U(T) - U(55))/K1c`` at the given inputs
    (Fu et al., spec 000, Figs. 2-4; ``a_p`` defaults to ``+sqrt(1 - a_i^2)``)."""
    a_i = np.asarray(a_i, dtype=float)
    if a_p is None:
        a_p = np.sqrt(np.clip(1.0 - a_i**2, 0.0, None))
    return (unit.output_mv(t_el, a_i, a_p) - unit.output_mv(T_REF, a_i, a_p)) / unit.ref.k1


@dataclass(frozen=True)
class Lot:
    """A production lot drawn from ``lot_seed`` with a preset."""

    lot_seed: int
    preset: Preset
    rig: Rig
    lot_id: str

    def unit(self, i: int) -> UnitParams:
        """Constants of unit ``i`` (stream ``1 + i`` of the lot seed)."""
        if i < 0:
            raise InputError(f"unit index must be >= 0, got {i}")
        g = np.random.Generator(np.random.PCG64(
            np.random.SeedSequence(self.lot_seed, spawn_key=(1 + int(i),))))
        p = self.preset
        k1c = 1000.0 * g.uniform(0.90, 1.10)
        b0 = g.normal(0.0, 1e-3)
        k2c = k1c * 1e-6 * g.normal(0.0, 8.0)
        kipc = k1c * 1e-6 * g.normal(0.0, 8.0)
        delta_c = g.normal(0.0, 300.0)
        t_off = g.normal(0.0, p.temp_offset_sd_c)
        z = g.standard_normal(len(LOT_NOMINAL))
        coef = {k: v * (1.0 + p.sr * zk) for (k, v), zk in zip(LOT_NOMINAL.items(), z)}
        tk = TK_NOMINAL + g.normal(0.0, p.st_c)
        ref = SingleAxisCoefficients(k0=k1c * b0, k1=k1c, k2=k2c, kip=kipc,
                                     kp=1e-6 * k1c * delta_c)
        return UnitParams(unit_id=f"QFA-{self.lot_seed}-{i:03d}", lot_id=self.lot_id, index=int(i),
                          ref=ref, coef=coef, tk_c=tk, wk_c=WK, delta_c_urad=delta_c,
                          kd_urad_per_c=p.kd_urad_per_c, temp_offset_c=t_off,
                          hysteresis_ug=p.hysteresis_ug)


def make_lot(lot_seed: int = 0, preset: str = "paper", *, n_positions: int = 24) -> Lot:
    """Draw a lot (spec 000 §7.5). ``preset`` is "paper" or "realistic"."""
    if preset not in PRESETS:
        raise InputError(f"unknown preset {preset!r}; choose one of {sorted(PRESETS)}")
    if int(lot_seed) != lot_seed or lot_seed < 0:
        raise InputError(f"lot seed must be a non-negative integer, got {lot_seed}")
    g = np.random.Generator(np.random.PCG64(np.random.SeedSequence(int(lot_seed), spawn_key=(0,))))
    rig = Rig(angle_error_arcsec=g.normal(0.0, 1.0, n_positions))
    return Lot(int(lot_seed), PRESETS[preset], rig, f"LOT-{int(lot_seed)}")


@dataclass(frozen=True)
class TumbleRun:
    """One simulated run: the §2.3 ``frame`` (canonical column names), its sidecar
    ``meta``, the ``noise_floor_ug`` (rms of (output - true_output)/K1c, angle errors
    included, spec 000 §7.4) and ``noise_only_ug`` (white + random walk + resolution)."""

    frame: pd.DataFrame
    meta: dict
    noise_floor_ug: float
    noise_only_ug: float
    unit: UnitParams = field(repr=False)


def _window_means(x: np.ndarray, starts: np.ndarray, length: int):
    cs = np.concatenate([[0.0], np.cumsum(x)])
    cs2 = np.concatenate([[0.0], np.cumsum(x * x)])
    s = cs[starts + length] - cs[starts]
    s2 = cs2[starts + length] - cs2[starts]
    m = s / length
    var = np.maximum(s2 / length - m * m, 0.0)
    return m, np.sqrt(var * length / max(length - 1, 1))


def _plateaus(sch: Schedule):
    """The plateaus' set points (deg C) and ramp directions (``up``, ``down``)."""
    sp = sch.set_points()
    plateaus = list(sp)
    dirs = ["up"] * len(sp)
    if sch.ramp == "up_down":
        plateaus += list(sp[-2::-1])
        dirs += ["down"] * (len(sp) - 1)
    return np.asarray(plateaus), dirs


def _temperatures(g, lot: Lot, sch: Schedule, tset: np.ndarray):
    """Chamber, element and sensor temperatures (deg C) on a 1-s grid.

    The chamber follows ``T_set + o_k + A_k sin(2 pi t/600 + phi_k)`` per plateau (the
    draws, in this order: o, A, phi), the element and the sensor lag it (first order,
    1-s Euler steps). Returns ``(t_el, t_s)``."""
    n_pl = tset.size
    pl_len = sch.soak_s + sch.n_positions * (sch.settle_s + sch.record_s)
    t = np.arange(n_pl * pl_len + 1, dtype=float)
    pl_idx = np.minimum((t // pl_len).astype(int), n_pl - 1)
    o = g.uniform(-0.1, 0.1, n_pl)
    A = g.uniform(0.05, 0.25, n_pl)
    phi = g.uniform(0.0, 2 * np.pi, n_pl)
    t_ch = tset[pl_idx] + o[pl_idx] + A[pl_idx] * np.sin(2 * np.pi * t / 600.0 + phi[pl_idx])

    def lag(tau: float) -> np.ndarray:
        a = 1.0 / tau  # 1-s Euler step: T[n+1] = T[n] + (T_ch[n] - T[n])/tau
        y0 = tset[0] + o[0]
        out = lfilter([a], [1.0, -(1.0 - a)], t_ch[:-1], zi=[(1.0 - a) * y0])[0]
        return np.concatenate([[y0], out])

    t_el = lag(lot.rig.tau_element_s)
    return t_el, t_el if lot.preset.tau_sensor_s is None else lag(lot.preset.tau_sensor_s)


def _windows(sch: Schedule, n_pl: int):
    """The recording windows: plateau and position of each visit and its first sample
    (s) on the 1-s grid."""
    per_pos = sch.settle_s + sch.record_s
    pl_len = sch.soak_s + sch.n_positions * per_pos
    k_pl = np.repeat(np.arange(n_pl), sch.n_positions)
    pos = np.tile(np.arange(sch.n_positions), n_pl)
    starts = (k_pl * pl_len + sch.soak_s + pos * per_pos + sch.settle_s).astype(int)
    return k_pl, pos, starts


def _outputs(g, unit: UnitParams, rig: Rig, sch: Schedule, pos, hs, tel_mean, t_mid):
    """The unit's recorded outputs (mV) at each visit. Draws, in order: the dividing
    head's angle errors, white noise, random walk, the sample spread. Returns the nominal
    and true inputs (g), the clean, recorded and true outputs and the outputs' sample
    standard deviation (mV), with the samples per window."""
    n_vis = pos.size
    P = tumble_positions(sch.n_positions)
    ang_nom = P.angle_deg[pos]
    a_nom, p_nom = P.a_in_g[pos], P.a_pend_g[pos]
    err = (rig.angle_error_arcsec[pos] + g.normal(0.0, rig.visit_angle_sd_arcsec, n_vis)) * ARCSEC
    th = np.deg2rad(ang_nom) + err
    a_true, p_true = np.sin(th), np.cos(th)
    white = g.normal(0.0, rig.white_ug, n_vis)
    dt_h = np.diff(np.concatenate([[0.0], t_mid])) / 3600.0
    rw = np.cumsum(g.normal(0.0, 1.0, n_vis) * rig.random_walk_ug_per_rth * np.sqrt(dt_h))
    k1 = unit.ref.k1
    clean = unit.output_mv(tel_mean, a_true, p_true, hs)
    noisy = clean + k1 * 1e-6 * (white + rw)
    res = rig.resolution_mv
    out = np.round(noisy / res) * res
    true_out = unit.output_mv(tel_mean, a_nom, p_nom, hs)
    n_samp = int(round(sch.rate_hz * sch.record_s))
    out_std = k1 * 1e-6 * rig.sample_noise_ug * np.sqrt(g.chisquare(n_samp - 1, n_vis) / (n_samp - 1))
    return ang_nom, a_nom, p_nom, a_true, clean, out, true_out, out_std, n_samp


def run_tumble(lot: Lot, unit: UnitParams | int, *, seed=None, schedule: Schedule | None = None,
               run_id: str | None = None) -> TumbleRun:
    """Simulate one thermal tumble run of ``unit`` (spec 000 §7.4).

    Parameters
    ----------
    lot : Lot
    unit : UnitParams or int
        The unit or its index in the lot.
    seed : int or None
        Run-noise seed (default: the lot seed).
    schedule : Schedule, optional
        Defaults: -40..70 °C every 5 °C, 30-min soak, 24 positions of 10 s settle +
        10 s record, ascending.
    """
    if isinstance(unit, (int, np.integer)):
        unit = lot.unit(int(unit))
    sch = schedule or Schedule()
    if sch.ramp not in ("up", "up_down"):
        raise InputError(f"ramp must be 'up' or 'up_down', got {sch.ramp!r}")
    if sch.n_positions != lot.rig.angle_error_arcsec.size:
        raise InputError("the schedule's number of positions differs from the rig's")
    seed = lot.lot_seed if seed is None else seed
    g = as_generator(seed)
    tset, dirs = _plateaus(sch)
    t_el, t_s = _temperatures(g, lot, sch, tset)
    k_pl, pos, starts = _windows(sch, tset.size)
    L = int(sch.record_s)
    tel_mean, _ = _window_means(t_el, starts, L)
    ts_mean, ts_std = _window_means(t_s, starts, L)
    n_vis = starts.size
    t_mid = starts + L / 2.0
    temp_meas = ts_mean + unit.temp_offset_c + g.normal(0.0, 0.01, n_vis)
    hs = np.where(np.asarray(dirs)[k_pl] == "up", 1.0, -1.0)
    ang_nom, a_nom, p_nom, a_true, clean, out, true_out, out_std, n_samp = _outputs(
        g, unit, lot.rig, sch, pos, hs, tel_mean, t_mid)
    k1 = unit.ref.k1
    rid = run_id or f"{unit.unit_id}-run{seed}"
    frame = pd.DataFrame({
        "unit_id": unit.unit_id, "lot_id": unit.lot_id, "run_id": rid,
        "seq": np.arange(n_vis, dtype=int), "t_s": t_mid,
        "temp_set_c": tset[k_pl], "temp_meas_c": temp_meas, "temp_std_c": ts_std,
        "pos_index": pos.astype(int), "angle_deg": ang_nom, "a_in_g": a_nom, "a_pend_g": p_nom,
        "output_mv": out, "output_std_mv": out_std, "n_samples": n_samp,
        "ramp_dir": np.asarray(dirs)[k_pl],
        "true_a_in_g": a_true, "true_temp_c": tel_mean, "true_output_mv": true_out,
    })
    floor = float(np.sqrt(np.mean(((out - true_out) / k1) ** 2)) * 1e6)
    only = float(np.sqrt(np.mean(((out - clean) / k1) ** 2)) * 1e6)
    meta = {
        "source": "virtual_lab", "generator": GENERATOR, "generator_version": GENERATOR_VERSION,
        "seed": int(seed), "lot_seed": lot.lot_seed, "preset": lot.preset.name,
        "unit_id": unit.unit_id, "lot_id": unit.lot_id, "unit_index": unit.index,
        "g_local_mps2": 9.80665, "reference_temp_c": T_REF, "readout_resistor_ohm": 750.0,
        "noise_floor_ug": floor, "noise_only_ug": only, "ramp": sch.ramp,
    }
    return TumbleRun(frame, meta, floor, only, unit)


def simulate(preset: str = "paper", lot_seed: int = 0, unit: int = 0, *, seed=None,
             ramp: str = "up") -> TumbleRun:
    """One record of unit ``unit`` of lot ``lot_seed`` (the ``simulate thermal-tumble`` rig)."""
    lot = make_lot(lot_seed, preset)
    return run_tumble(lot, unit, seed=seed, schedule=replace(Schedule(), ramp=ramp))
