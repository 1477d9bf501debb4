"""Virtual lab rig ``dual-tumble`` (``sim.dual``): two accelerometers on a dividing head
(spec 003 §6).

One run is a CCW pass over positions 0..N (N = closure at 360 deg) followed by a CW
pass back, with the dividing-head errors (zero offset, first and second harmonic
systematic error, random setting error, direction-dependent reversal, all but the
zero offset scaled by ``h``), the meter temperature ramp with bias and scale-factor
temperature coefficients, the sampling-resistor temperature coefficient, white
accelerometer noise, a settling transient in the first readings of each stop, and the
DMM (noise, 10 uV quantisation, optional INL). Nothing is linearised: the outputs are
the exact IEEE-1293 PA-tumble outputs of :func:`inertialab.sensors.dual_meter.meter_outputs`.

Randomness: one generator from ``rng`` (default seed 20240603, spec §6); its draws are
taken in a fixed order (unit draw if asked, head phases and zero, per-stop head errors,
temperatures, meter noise, DMM noise), so the same seed gives the same run. Scenario
S0 versus S0 with ``h = 5`` and the same seed share the zero offset delta0 (AC-3).

Truth returned: the nine coefficients at the run-mean meter temperatures, plus
``delta_A`` (mounting + head zero) and ``delta_B = delta_A + eta``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from inertialab import units
from inertialab.errors import InputError
from inertialab.limits import bounded, bounded_int, check_budget
from inertialab.seeding import as_generator
from inertialab.sensors.dual_meter import COEF_NAMES, TURN_ON_TAU, meter_outputs

__all__ = ["DEFAULT_SEED", "SCENARIOS", "TAU", "NU", "DualLabConfig", "DualRun", "TRUTH_REF",
           "draw_unit", "scenario_config", "simulate_run",
           "simulate_two_orientation"]

DEFAULT_SEED = 20240603
GENERATOR_VERSION = "dual-tumble/1"

#: Table 6.1 reference coefficients (local-g units; K0 g, k1 g/g, eta rad, K2/Kx g/g^2).
TRUTH_REF = {"KA0": 5.0e-4, "KB0": -3.0e-4, "kA1": 1.5e-4, "kB1": -8.0e-5, "eta": 1.2e-4,
             "KA2": 4.0e-5, "KB2": 1.5e-5, "KAx": 1.0e-5, "KBx": -8.0e-6}
#: Turn-on repeatability tau (spec §6.5): K0 20 ug, k1 30 ppm, eta 5 urad, K2/Kx 5 ug/g^2.
TAU = TURN_ON_TAU
#: Estimation noise of one historical run nu (spec §6.5).
NU = {"KA0": 2e-6, "KB0": 2e-6, "kA1": 2e-6, "kB1": 2e-6, "eta": 1e-6,
      "KA2": 3e-6, "KB2": 3e-6, "KAx": 3e-6, "KBx": 3e-6}

SCENARIOS = ("S0", "S1", "S2", "S3", "S4", "S5")


@dataclass(frozen=True)
class DualLabConfig:
    """Settings of the virtual dual-tumble lab (spec §6.1–6.2 defaults).

    Angles of the head error in arc-seconds, noise in ug / uV, temperatures in deg C.
    """

    coef: dict = field(default_factory=lambda: dict(TRUTH_REF))
    delta_mount_rad: float = 9.70e-5  # IA misalignment + levelling (20")
    draw_unit: bool = False  # draw the unit's coefficients around coef with TAU (spec §6.5)
    n_history: int = 6
    s_a: int = 1
    s_b: int = 1
    k1_nom_ma_per_g: tuple = (1.300, 1.250)
    r_load_ohm: tuple = (5000.0, 5000.0)
    r_alpha_per_c: float = 1e-6
    r_t0_c: float = 25.0
    n_positions: int = 20
    n_samples: int = 20
    n_settle_samples: int = 2
    t_settle_s: float = 10.0
    sample_dt_s: float = 5.0
    move_s: float = 30.0
    settle_transient_ug: float = 30.0
    head_zero_sd_arcsec: float = 20.0
    head_a1_arcsec: float = 2.0
    head_a2_arcsec: float = 1.0
    head_random_sd_arcsec: float = 1.0
    head_reversal_arcsec: float = 0.5
    h: float = 1.0
    systematic_only: bool = False  # AC-3: only the first harmonic a1 (no a2, random, reversal)
    psi1: float | None = None  # fixed phase of the first harmonic (else U(0, 2 pi))
    t0_c: float = 20.0
    temp_ramp_c: float = 0.1
    temp_noise_c: float = 0.01
    bias_tc_ug_per_c: float = 20.0
    sf_tc_ppm_per_c: float = 50.0
    accel_noise_ug: float = 5.0
    dmm_noise_uv: float = 1.5
    dmm_resolution_uv: float = 10.0
    dmm_range_v: float = 10.0
    nplc: float = 10.0
    inl_kappa: float = 0.0
    K3: tuple = (0.0, 0.0)
    noise_free: bool = False
    g_local_mps2: float = 9.80625
    scenario: str = "S1"


@dataclass
class DualRun:
    """One simulated tumble (CCW + CW).

    ``arrays`` holds (2, P, S) arrays (direction CCW/CW, position 0..N, sample) of
    ``t_s``, ``v_a_v``, ``v_b_v``, ``t_a_c``, ``t_b_c``, ``t_r_c``, plus
    ``theta_cmd_deg`` (P,), ``theta_read_deg`` (2, P) and ``settle`` (S,) bool.
    """

    arrays: dict
    meta: dict
    truth: dict
    head: dict
    run_id: str = "run1"

    def to_frame(self) -> pd.DataFrame:
        """The spec §2.2 record (one row per DMM sample, CCW pass first, in time order)."""
        a = self.arrays
        P = a["theta_cmd_deg"].size
        S = a["t_s"].shape[2]
        frames = []
        for d, name in enumerate(("CCW", "CW")):
            order = np.arange(P) if d == 0 else np.arange(P)[::-1]
            pos = np.repeat(order, S)
            smp = np.tile(np.arange(S), P)
            frames.append(pd.DataFrame({
                "run_id": self.run_id,
                "direction": name,
                "pos_index": pos,
                "theta_cmd_deg": a["theta_cmd_deg"][pos],
                "theta_read_deg": a["theta_read_deg"][d][pos],
                "sample_index": smp,
                "t_s": a["t_s"][d][order].ravel(),
                "v_a_v": a["v_a_v"][d][order].ravel(),
                "v_b_v": a["v_b_v"][d][order].ravel(),
                "t_a_c": a["t_a_c"][d][order].ravel(),
                "t_b_c": a["t_b_c"][d][order].ravel(),
                "t_r_c": a["t_r_c"][d][order].ravel(),
                "dmm_range_v": self.meta["dmm"]["range_v"],
                "nplc": self.meta["dmm"]["nplc"],
            }))
        return pd.concat(frames, ignore_index=True)


def scenario_config(name: str = "S1", **overrides) -> DualLabConfig:
    """Config of scenario S0–S5 (spec §6.4), with field overrides.

    S0 noise-free (no head error except the zero offset, constant temperature, no DMM
    noise or quantisation, no meter noise); S1 default; S2 head-error sweep (give
    ``h``); S3 model error (K3 = 5e-6 g/g^3 both meters, DMM INL kappa = 2e-6); S4
    position count (give ``n_positions``); S5 the two-orientation run (see
    :func:`simulate_two_orientation`; the config is that of run 1).
    """
    key = str(name).upper()
    if key not in SCENARIOS:
        raise InputError(f"unknown scenario '{name}' (known: {', '.join(SCENARIOS)})")
    base = DualLabConfig(scenario=key)
    if key == "S0":
        base = replace(base, noise_free=True, h=0.0)
    elif key == "S3":
        base = replace(base, K3=(5e-6, 5e-6), inl_kappa=2e-6)
    try:
        return replace(base, **overrides)
    except TypeError as exc:
        raise InputError(f"bad dual-tumble setting: {exc}") from None


def draw_unit(rng, *, n_history: int = 6, ref: dict | None = None):
    """Draw the current unit's truth and ``n_history`` historical estimates (spec §6.5).

    Returns ``(beta_true, history)``: a dict and an (H, 9) array in :data:`COEF_NAMES` order.
    """
    g = as_generator(rng)
    ref = dict(TRUTH_REF if ref is None else ref)
    b = np.array([ref[n] for n in COEF_NAMES])
    tau = np.array([TAU[n] for n in COEF_NAMES])
    nu = np.array([NU[n] for n in COEF_NAMES])
    hist = b + g.standard_normal((n_history, 9)) * tau + g.standard_normal((n_history, 9)) * nu
    true = b + g.standard_normal(9) * tau
    return dict(zip(COEF_NAMES, true.tolist())), hist


def _meta(cfg: DualLabConfig, seed) -> dict:
    meters = {}
    for j, key in enumerate(("meter_a", "meter_b")):
        meters[key] = {"serial": f"VL-{'AB'[j]}-001", "k1_nom_ma_per_g": cfg.k1_nom_ma_per_g[j],
                       "r_load_ohm": cfg.r_load_ohm[j], "r_alpha_per_c": cfg.r_alpha_per_c,
                       "r_t0_c": cfg.r_t0_c, "oa_sign": (cfg.s_a, cfg.s_b)[j]}
    return {"schema_version": 1, "g_local_mps2": cfg.g_local_mps2, "t_settle_s": cfg.t_settle_s,
            "step_deg": 360.0 / cfg.n_positions, "n_positions": cfg.n_positions,
            "theta_positive": "cw", "dividing_head": "virtual 1-arcsec grating head",
            "dmm": {"model": "virtual Keithley 2000", "range_v": cfg.dmm_range_v,
                    "nplc": cfg.nplc},
            "head_sd_arcsec": max(cfg.h * cfg.head_random_sd_arcsec, 0.0),
            "operator": "virtual_lab", "date": "2024-06-03T20:00:00Z", "source": "virtual_lab",
            "seed": seed, "generator_version": GENERATOR_VERSION, "scenario": cfg.scenario,
            **meters}


def _checked_size(cfg: DualLabConfig) -> tuple[int, int]:
    """``(positions, samples per position)`` of a rig within bounds and the memory budget
    (every number of the rig finite and of sane size)."""
    N = bounded_int("n_positions", cfg.n_positions, 1, 100_000)
    S = bounded_int("n_samples", cfg.n_samples, 1, 1_000_000)
    bounded("g_local", cfg.g_local_mps2, 1.0, 100.0)
    for name, v in vars(cfg).items():
        if isinstance(v, float):
            bounded(name, v, -1e9, 1e9)
    # (2, P, S) arrays of about a dozen quantities
    check_budget(2.0 * (N + 1) * S * 12 * 8, f"a simulated tumble of {N} positions x "
                 f"{S} samples")
    return N, S


def _head_angles(cfg: DualLabConfig, g, theta: np.ndarray):
    """The table angles of both passes with the head errors drawn (fixed draw order):
    ``(psi1, psi2, delta0, delta_a, dtheta, phi)``, radians, ``phi`` of shape (2, P)."""
    asec = units.ARCSEC
    P = theta.size
    psi1 = g.uniform(0, 2 * np.pi) if cfg.psi1 is None else float(cfg.psi1)
    psi2 = g.uniform(0, 2 * np.pi)
    delta0 = g.normal(0.0, cfg.head_zero_sd_arcsec) * asec
    rand = g.standard_normal((2, P)) * cfg.head_random_sd_arcsec * asec
    h = cfg.h
    syst = cfg.head_a1_arcsec * asec * np.sin(theta + psi1)
    if not cfg.systematic_only:
        syst = syst + cfg.head_a2_arcsec * asec * np.sin(2 * theta + psi2)
        rev = np.array([1.0, -1.0])[:, None] * cfg.head_reversal_arcsec * asec
        dtheta = h * (syst[None, :] + rand + rev)
    else:
        dtheta = h * np.broadcast_to(syst, (2, P))
    delta_a = cfg.delta_mount_rad + delta0
    phi = theta[None, :] + delta_a + dtheta  # (2, P)
    return psi1, psi2, delta0, delta_a, dtheta, phi


def _sample_times(cfg: DualLabConfig, P: int):
    """Sample times (s) of both passes, shape (2, P, samples per stop): stop j of a pass
    arrives at j*(stop + move), the CW pass after the CCW pass. Also returns the offsets
    within a stop, the run's length (s) and the settling mask of a stop."""
    offs = np.concatenate([np.arange(cfg.n_settle_samples) * cfg.sample_dt_s,
                           cfg.t_settle_s + np.arange(cfg.n_samples) * cfg.sample_dt_s])
    stop_len = offs[-1] + cfg.move_s
    arrive = np.empty((2, P))
    arrive[0] = np.arange(P) * stop_len
    arrive[1] = (P + np.arange(P)[::-1]) * stop_len  # CW visits P-1 .. 0
    t = arrive[:, :, None] + offs[None, None, :]
    return t, offs, 2 * P * stop_len, offs < cfg.t_settle_s


def _temperatures(cfg: DualLabConfig, g, t: np.ndarray, t_run: float):
    """Meter A, meter B and load-resistor temperatures (deg C) at the sample times, and
    the reference temperature of the temperature coefficients."""
    if cfg.noise_free:
        ta = np.full(t.shape, cfg.t0_c)
        tb = ta.copy()
        tr = np.full(t.shape, cfg.r_t0_c)
    else:
        ramp = cfg.t0_c + cfg.temp_ramp_c * t / t_run
        ta = ramp + g.normal(0, cfg.temp_noise_c, t.shape)
        tb = ramp + g.normal(0, cfg.temp_noise_c, t.shape)
        tr = cfg.r_t0_c + 0.02 + g.normal(0, cfg.temp_noise_c / 5, t.shape)
    t_ref = cfg.t0_c + (0.0 if cfg.noise_free else cfg.temp_ramp_c / 2)
    return ta, tb, tr, t_ref


def _coef_at(coef: dict, cfg: DualLabConfig, t_ref: float, Ta, Tb) -> dict:
    """The unit's coefficients with bias and scale factor moved by the meters'
    temperatures ``Ta``, ``Tb`` (deg C) from ``t_ref``."""
    bt, st = cfg.bias_tc_ug_per_c * 1e-6, cfg.sf_tc_ppm_per_c * 1e-6
    c = dict(coef)
    c["KA0"] = coef["KA0"] + bt * (Ta - t_ref)
    c["kA1"] = coef["kA1"] + st * (Ta - t_ref)
    c["KB0"] = coef["KB0"] + bt * (Tb - t_ref)
    c["kB1"] = coef["kB1"] + st * (Tb - t_ref)
    return c


def _voltages(cfg: DualLabConfig, g, ua, ub, tr, shape) -> list:
    """The DMM voltages (V) of both meters from their outputs (g): current through the
    load resistor at temperature ``tr``, INL, noise and resolution; over range is an
    :class:`InputError`."""
    gfac = cfg.g_local_mps2 / units.G_STANDARD
    volts = []
    for j, u in enumerate((ua, ub)):
        k1 = units.to_si(cfg.k1_nom_ma_per_g[j], "ma_per_g")
        r = cfg.r_load_ohm[j] * (1.0 + cfg.r_alpha_per_c * (tr - cfg.r_t0_c))
        v = u * k1 * r * gfac
        if cfg.inl_kappa:
            v = v + cfg.inl_kappa * v * np.abs(v) / cfg.dmm_range_v
        if not cfg.noise_free:
            v = v + g.standard_normal(shape) * cfg.dmm_noise_uv * 1e-6
            q = cfg.dmm_resolution_uv * 1e-6
            v = np.round(v / q) * q
        if np.any(np.abs(v) > cfg.dmm_range_v):
            raise InputError(f"simulated voltage exceeds the DMM range {cfg.dmm_range_v} V; "
                             "lower r_load_ohm")
        volts.append(v)
    return volts


def simulate_run(config: DualLabConfig | None = None, rng=None, *, coef: dict | None = None,
                 run_id: str = "run1") -> DualRun:
    """Simulate one CCW + CW tumble.

    Parameters
    ----------
    config : DualLabConfig, optional
        Default :func:`scenario_config` ("S1").
    rng : int, Generator or None
        Seed (default :data:`DEFAULT_SEED`).
    coef : dict, optional
        The unit's coefficients (overrides ``config.coef`` and ``draw_unit``).
    """
    cfg = config or scenario_config("S1")
    seed = DEFAULT_SEED if rng is None else rng
    g = as_generator(seed)
    history = None
    if coef is None:
        if cfg.draw_unit:
            coef, history = draw_unit(g, n_history=cfg.n_history, ref=cfg.coef)
        else:
            coef = dict(cfg.coef)
    N, S = _checked_size(cfg)
    P = N + 1
    theta_deg = np.arange(P) * 360.0 / N
    psi1, psi2, delta0, delta_a, dtheta, phi = _head_angles(cfg, g, np.deg2rad(theta_deg))
    t, offs, t_run, settle = _sample_times(cfg, P)
    ta, tb, tr, t_ref = _temperatures(cfg, g, t, t_run)
    used = ~settle[None, None, :] & np.ones(t.shape, bool)
    ua, ub = meter_outputs(phi[:, :, None], _coef_at(coef, cfg, t_ref, ta, tb), s_a=cfg.s_a,
                           s_b=cfg.s_b, K3=cfg.K3)
    if not cfg.noise_free:
        ua = ua + g.standard_normal(t.shape) * cfg.accel_noise_ug * 1e-6
        ub = ub + g.standard_normal(t.shape) * cfg.accel_noise_ug * 1e-6
    tr_amp = cfg.settle_transient_ug * 1e-6 * np.exp(-offs / 2.0) * settle
    volts = _voltages(cfg, g, ua + tr_amp, ub - tr_amp, tr, t.shape)
    truth = _coef_at(coef, cfg, t_ref, float(ta[used].mean()), float(tb[used].mean()))
    truth = {k: float(v) for k, v in truth.items()}
    truth["delta_A"] = float(delta_a)
    truth["delta_B"] = float(delta_a + coef["eta"])
    read = np.broadcast_to(theta_deg, (2, P)).copy()  # head read-out = commanded angle
    arrays = {"theta_cmd_deg": theta_deg, "theta_read_deg": read, "t_s": t,
              "v_a_v": volts[0], "v_b_v": volts[1], "t_a_c": ta, "t_b_c": tb, "t_r_c": tr,
              "settle": settle}
    meta = _meta(cfg, seed if isinstance(seed, (int, np.integer)) else None)
    head = {"psi1": float(psi1), "psi2": float(psi2), "delta0_rad": float(delta0),
            "a1_rad": float(cfg.h * cfg.head_a1_arcsec * units.ARCSEC), "h": float(cfg.h),
            "dtheta_rad": dtheta}
    run = DualRun(arrays=arrays, meta=meta, truth=truth, head=head, run_id=run_id)
    if history is not None:
        run.head["history"] = history
    return run


def simulate_two_orientation(config: DualLabConfig | None = None, rng=None, *,
                             coef: dict | None = None) -> tuple[DualRun, DualRun]:
    """The two-orientation experiment (spec §7.2, scenario S5).

    Run 1 as configured; run 2 with both meters turned 180 deg about their IA (OA signs
    flipped) and its own K0, k1 and eta (redrawn with the turn-on repeatability TAU);
    K2 and Kx are shared. Run 2 uses a child generator of ``rng``.

    Examples
    --------
    The second run has both meters' output axes turned over and its own turn-on terms;
    the second-order terms are the unit's and shared:

    >>> run1, run2 = simulate_two_orientation(rng=0)
    >>> run1.run_id, run2.run_id
    ('orient1', 'orient2')
    >>> run1.meta["meter_a"]["oa_sign"], run2.meta["meter_a"]["oa_sign"]
    (1, -1)
    >>> run1.truth["KA2"] == run2.truth["KA2"], run1.truth["KA0"] == run2.truth["KA0"]
    (True, False)
    """
    cfg = config or scenario_config("S5")
    g = as_generator(DEFAULT_SEED if rng is None else rng)
    g1, g2 = g.spawn(2)
    if coef is None:
        if cfg.draw_unit:
            coef, _ = draw_unit(g, n_history=cfg.n_history, ref=cfg.coef)
        else:
            coef = dict(cfg.coef)
    run1 = simulate_run(cfg, g1, coef=coef, run_id="orient1")
    c2 = dict(coef)
    for n in ("KA0", "KB0", "kA1", "kB1", "eta"):
        c2[n] = coef[n] + g2.normal(0.0, TAU[n])
    cfg2 = replace(cfg, s_a=-cfg.s_a, s_b=-cfg.s_b)
    run2 = simulate_run(cfg2, g2, coef=c2, run_id="orient2")
    return run1, run2
