"""Workflow ``dual_tumble``: two accelerometers on a dividing head (spec 003).

From a record of the §2.2 format (or the virtual lab's arrays) this module

1. reduces the DMM samples to one normalised output per meter, position and direction
   (settling samples dropped, robust mean, voltage to local g, CCW/CW mean; §2.3),
   with the closure and hysteresis diagnostics;
2. fits M1 single-meter LS per meter (§3.1), M2 dual LS on the g^2 observation (harmonic
   LS with the estimable combinations, minimum-norm LS, naive normal equations; §3.2),
   M3 empirical Bayes ridge with the paper-faithful, certificate or historical prior
   (§3.3) and the ridge baselines HKB and GCV (§3.4);
3. reports per method the coefficients, SDs (§3.5), the residual R, the CCW->CW cross-fit
   residual R_val and the rank diagnostics (§4), and in simulation the errors vs truth;
4. fits the two-orientation stacked design (§7.2) and designs D-optimal positions.

The K2/Kx coupling of the g^2 design (rank 7 for 9 coefficients) is never hidden:
non-estimable coefficients of LS carry ``sd = None`` and the ``non_estimable`` flag, and
EBR warns that along the null directions it returns the prior centre.
"""

from __future__ import annotations

import json
import time
import warnings
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd

from inertialab import units
from inertialab.errors import InputError, NonIdentifiableWarning, ShrinkageWarning
from inertialab.regress.design import d_optimal_design, design_criteria
from inertialab.regress.ebr import EmpiricalBayesRidge
from inertialab.regress.lstsq import lstsq, naive_normal_equations, null_space_text
from inertialab.regress.ridge import ridge
from inertialab.seeding import as_generator
from inertialab.sensors.dual_meter import (
    COEF_NAMES,
    COEF_UNITS,
    SINGLE_NAMES,
    estimable_combinations,
    g2_design,
    g2_exact,
    g2_observation,
    harmonic_map,
    harmonic_matrix,
    reduce_to_g,
    single_design,
)
from inertialab.workflows.base import Headline, NullProgress, Study, StudyResult, settings_dict

__all__ = ["METHODS", "DualCalibration", "DualFit", "DualPrior", "MethodResult", "Reduced",
           "errors_vs_truth", "fit_single", "head_error_sensitivity",
           "STUDY", "calibrate", "certificate_prior", "design_dual", "fit_two_orientation",
           "load_prior", "monte_carlo", "reduce_record", "reduce_run", "reduce_stops",
           "run_demo"]

METHODS = ("single-ls", "ls", "ebr", "ridge-hkb", "ridge-gcv")
HARMONIC_LABELS = ("1", "cos2t", "sin2t", "sint", "cost", "sin3t", "cos3t")
CERT_LIMITS = {"KA2": 9.4e-5, "KB2": 2.5e-5}  # seed certificate limits, g/g^2 [P]


# ------------------------------------------------------------------------------ priors

@dataclass(frozen=True)
class DualPrior:
    """Prior centre and scale (beta0, w) on :data:`COEF_NAMES`; ``kind`` labels it."""

    kind: str
    mean: np.ndarray
    sd: np.ndarray

    def to_json(self) -> dict:
        return {"schema": "inertialab.prior/1",
                "coef": {n: {"mean": float(self.mean[j]), "sd": float(self.sd[j]),
                             "unit": COEF_UNITS[n]} for j, n in enumerate(COEF_NAMES)}}


def certificate_prior() -> DualPrior:
    """Certificate prior of spec §6.5: K2 centred at 0 with SD = limit/2, Kx 0 +- 1e-5,
    K0, k1, eta weakly informative (0 +- 1e-3)."""
    mean = np.zeros(9)
    sd = np.full(9, 1e-3)
    idx = {n: i for i, n in enumerate(COEF_NAMES)}
    sd[idx["KA2"]] = CERT_LIMITS["KA2"] / 2
    sd[idx["KB2"]] = CERT_LIMITS["KB2"] / 2
    sd[idx["KAx"]] = sd[idx["KBx"]] = 1e-5
    return DualPrior("certificate", mean, sd)


_UNIT_ALIASES = {"g/g": {"g/g", "1", "", "ratio"}, "rad": {"rad"}, "g": {"g"},
                 "g/g^2": {"g/g^2", "g/g2", "1/g"}}


def prior_from_dict(d: dict, *, path="<prior>") -> DualPrior:
    """Validate a prior JSON object ``{"schema": "inertialab.prior/1", "coef": {...}}``."""
    if not isinstance(d, dict) or d.get("schema") != "inertialab.prior/1":
        raise InputError("prior file needs \"schema\": \"inertialab.prior/1\"", path=path)
    coef = d.get("coef")
    if not isinstance(coef, dict):
        raise InputError("prior file needs a \"coef\" object", path=path)
    unknown = [k for k in coef if k not in COEF_NAMES]
    if unknown:
        raise InputError(f"unknown coefficient name(s) {', '.join(unknown)}; names are "
                         f"case-sensitive: {' '.join(COEF_NAMES)}", path=path)
    missing = [n for n in COEF_NAMES if n not in coef]
    if missing:
        raise InputError(f"prior lacks {', '.join(missing)}", path=path)
    mean, sd = np.zeros(9), np.zeros(9)
    for j, n in enumerate(COEF_NAMES):
        e = coef[n]
        try:
            mean[j], sd[j] = float(e["mean"]), float(e["sd"])
        except (KeyError, TypeError, ValueError):
            raise InputError(f"prior entry {n} needs numeric \"mean\" and \"sd\"",
                             path=path) from None
        unit = str(e.get("unit", COEF_UNITS[n]))
        if unit not in _UNIT_ALIASES[COEF_UNITS[n]]:
            raise InputError(f"prior entry {n} has unit '{unit}', expected "
                             f"'{COEF_UNITS[n]}'", path=path)
        if not (np.isfinite(mean[j]) and np.isfinite(sd[j]) and sd[j] > 0):
            raise InputError(f"prior entry {n}: mean must be finite and sd positive", path=path)
    return DualPrior(str(d.get("kind", "file")), mean, sd)


def load_prior(spec) -> DualPrior | None:
    """``None``/"none" (paper-faithful beta0 = 0, W = I), "certificate", a JSON prior file,
    a CSV of past calibrations (one row per calibration, columns :data:`COEF_NAMES`; mean
    and SD floored at tau/2 of spec §6.5), or a DualPrior."""
    if spec is None or isinstance(spec, DualPrior):
        return spec
    s = str(spec)
    if s.lower() == "none":
        return None
    if s.lower() == "certificate":
        return certificate_prior()
    p = Path(s)
    if not p.exists():
        raise InputError("no such prior file (use none, certificate, a JSON prior or a CSV "
                         "of past calibrations)", path=p)
    if p.suffix.lower() == ".csv":
        from inertialab.sim.dual_tumble import prior_from_history

        try:
            hist = pd.read_csv(p)
        except (OSError, ValueError) as exc:
            raise InputError(f"cannot read the calibration history: {exc}", path=p) from None
        try:
            pj = prior_from_history(hist)
        except InputError as exc:
            raise InputError(str(exc), path=p) from None
        return DualPrior("history", np.array([pj[n]["mean"] for n in COEF_NAMES]),
                         np.array([pj[n]["sd"] for n in COEF_NAMES]))
    try:
        d = json.loads(p.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise InputError(f"prior file is not JSON: {exc}", path=p) from None
    prior = prior_from_dict(d, path=p)
    return replace(prior, kind="file")


# ---------------------------------------------------------------------------- reduction

@dataclass(frozen=True)
class Reduced:
    """Stop-level data of one tumble (spec §2.3).

    ``theta`` (N,) rad in the software convention; ``u_a``, ``u_b`` CCW/CW means in
    local g; ``u_dir_a``/``u_dir_b`` (2, N) per direction; ``diff_a/b`` CCW - CW;
    ``se_a/b`` (2, N) standard errors of the stop means; ``closure`` per meter/pass.
    """

    theta: np.ndarray
    u_a: np.ndarray
    u_b: np.ndarray
    u_dir_a: np.ndarray
    u_dir_b: np.ndarray
    diff_a: np.ndarray
    diff_b: np.ndarray
    se_a: np.ndarray
    se_b: np.ndarray
    s_a: int
    s_b: int
    g_local_mps2: float
    closure: dict
    warnings: tuple
    run_id: str = ""

    @property
    def n(self) -> int:
        return int(self.theta.size)

    @property
    def y(self) -> np.ndarray:
        return g2_observation(self.u_a, self.u_b)


_METER_KEYS = ("k1_nom_ma_per_g", "r_load_ohm", "oa_sign")


def _meters(meta: dict, path) -> list[dict]:
    out = []
    for key in ("meter_a", "meter_b"):
        m = meta.get(key)
        if not isinstance(m, dict):
            raise InputError(f"sidecar lacks the required object '{key}' (with "
                             f"{', '.join(_METER_KEYS)})", path=path)
        for k in _METER_KEYS:
            if k not in m:
                raise InputError(f"sidecar '{key}' lacks the required key '{k}'", path=path)
        try:
            mm = {"k1_nom_ma_per_g": float(m["k1_nom_ma_per_g"]),
                  "r_load_ohm": float(m["r_load_ohm"]),
                  "r_alpha_per_c": float(m.get("r_alpha_per_c", 0.0) or 0.0),
                  "r_t0_c": None if m.get("r_t0_c") is None else float(m["r_t0_c"]),
                  "oa_sign": int(m["oa_sign"])}
        except (TypeError, ValueError):
            raise InputError(f"sidecar '{key}' has a non-numeric value", path=path) from None
        if mm["oa_sign"] not in (1, -1):
            raise InputError(f"sidecar '{key}.oa_sign' must be +1 or -1", path=path)
        if mm["r_alpha_per_c"] and mm["r_t0_c"] is None:
            raise InputError(f"sidecar '{key}' has r_alpha_per_c != 0 but no r_t0_c", path=path)
        out.append(mm)
    return out


def _robust_stop(v: np.ndarray):
    """Robust mean over the last axis with NaN padding: reject |v - med| > 4*1.4826*MAD."""
    med = np.nanmedian(v, axis=-1, keepdims=True)
    mad = np.nanmedian(np.abs(v - med), axis=-1, keepdims=True)
    keep = np.isfinite(v) & ((np.abs(v - med) <= 4 * 1.4826 * mad) | (mad == 0))
    cnt = keep.sum(axis=-1)
    vv = np.where(keep, v, 0.0)
    mean = vv.sum(axis=-1) / np.maximum(cnt, 1)
    var = np.where(keep, (v - mean[..., None]) ** 2, 0.0).sum(axis=-1) / np.maximum(cnt - 1, 1)
    return mean, np.sqrt(var), cnt


def reduce_stops(theta_cmd_deg, t_s, v_a, v_b, t_r, meta: dict, *, path="<record>",
                 run_id: str = "", g_local: float | None = None, dmm_range_v=None) -> Reduced:
    """Reduce (2, P, S) sample arrays (CCW/CW, position, sample; NaN padded) to a :class:`Reduced`.

    ``theta_cmd_deg`` (P,) commanded angles; a position at 360 deg is the closure stop.
    """
    warn: list[str] = []
    th = np.asarray(theta_cmd_deg, dtype=float)
    t_s, v_a, v_b, t_r = (np.asarray(a, dtype=float) for a in (t_s, v_a, v_b, t_r))
    g_loc = g_local if g_local is not None else meta.get("g_local_mps2")
    if g_loc is None:
        raise InputError("no local gravity: give --g-local or 'g_local_mps2' in the sidecar",
                         path=path)
    g_loc = float(g_loc)
    ma, mb = _meters(meta, path)
    rng_v = dmm_range_v if dmm_range_v is not None else (meta.get("dmm") or {}).get("range_v")
    if rng_v is not None:
        bad = np.argwhere(np.isfinite(v_a) & (np.abs(v_a) > float(rng_v)) |
                          np.isfinite(v_b) & (np.abs(v_b) > float(rng_v)))
        if bad.size:
            d, p, _ = bad[0]
            raise InputError(f"{len(bad)} voltage(s) beyond the DMM range +-{rng_v} V, first "
                             f"at {'CCW CW'.split()[d]} {th[p]:g} deg", path=path)
    t_settle = float(meta.get("t_settle_s", 10.0))
    arrival = np.nanmin(t_s, axis=-1, keepdims=True)
    ok = np.isfinite(v_a) & np.isfinite(v_b) & (t_s - arrival >= t_settle)
    va = np.where(ok, v_a, np.nan)
    vb = np.where(ok, v_b, np.nan)
    empty = ~ok.any(axis=-1)
    if np.any(empty):
        d, p = np.argwhere(empty)[0]
        raise InputError(f"no samples after the {t_settle:g} s settling time at "
                         f"{'CCW CW'.split()[d]} {th[p]:g} deg", path=path)
    mva, sva, ca = _robust_stop(va)
    mvb, svb, cb = _robust_stop(vb)
    tr_mean = np.nanmean(np.where(ok, t_r, np.nan), axis=-1) if np.isfinite(t_r).any() else None
    ua = reduce_to_g(mva, k1_nom_ma_per_g=ma["k1_nom_ma_per_g"], r_load_ohm=ma["r_load_ohm"],
                     g_local_mps2=g_loc, t_r_c=tr_mean, r_alpha_per_c=ma["r_alpha_per_c"],
                     r_t0_c=ma["r_t0_c"])
    ub = reduce_to_g(mvb, k1_nom_ma_per_g=mb["k1_nom_ma_per_g"], r_load_ohm=mb["r_load_ohm"],
                     g_local_mps2=g_loc, t_r_c=tr_mean, r_alpha_per_c=mb["r_alpha_per_c"],
                     r_t0_c=mb["r_t0_c"])
    sa = reduce_to_g(sva / np.sqrt(np.maximum(ca, 1)), k1_nom_ma_per_g=ma["k1_nom_ma_per_g"],
                     r_load_ohm=ma["r_load_ohm"], g_local_mps2=g_loc)
    sb = reduce_to_g(svb / np.sqrt(np.maximum(cb, 1)), k1_nom_ma_per_g=mb["k1_nom_ma_per_g"],
                     r_load_ohm=mb["r_load_ohm"], g_local_mps2=g_loc)
    closure_mask = th >= 360.0 - 1e-9
    fit_mask = ~closure_mask
    closure = {}
    zero = np.flatnonzero(np.isclose(np.mod(th, 360.0), 0.0) & fit_mask)
    if closure_mask.any() and zero.size:
        c, z = int(np.flatnonzero(closure_mask)[0]), int(zero[0])
        # [X] besides the stops' noise (spec §2.3 step 5), the two stops have independent
        # head setting errors (sidecar head_sd_arcsec, default 1" class [P]); at 0 deg
        # meter A's output moves by cos(0) = 1 g/rad with them, meter B's by sin(0) = 0
        head_sd = float(meta.get("head_sd_arcsec", 1.0)) * units.ARCSEC
        t0 = np.deg2rad(th[z])
        slope = {"A": abs(np.cos(t0)), "B": abs(np.sin(t0))}
        for meter, u, se in (("A", ua, sa), ("B", ub, sb)):
            for d, name in enumerate(("CCW", "CW")):
                diff = float(abs(u[d, c] - u[d, z]))
                sd_diff = np.sqrt(se[d, c] ** 2 + se[d, z] ** 2
                                  + 2 * (head_sd * slope[meter]) ** 2)
                lim = max(3e-6, 4 * float(sd_diff))
                closure[f"{meter}_{name}"] = {"abs_diff_g": diff, "limit_g": lim,
                                              "ok": diff <= lim}
                if diff > lim:
                    warn.append(f"closure of meter {meter} ({name}): |u(360)-u(0)| = "
                                f"{diff * 1e6:.2f} ug exceeds {lim * 1e6:.2f} ug (drift?)")
    theta_deg = th[fit_mask]
    pos = np.mod(theta_deg, 360.0)
    if np.unique(np.round(pos, 9)).size < pos.size:
        raise InputError("two positions share the same angle (mod 360 deg)", path=path)
    positive = str(meta.get("theta_positive", "cw")).lower()
    if positive not in ("cw", "ccw"):
        raise InputError("sidecar 'theta_positive' must be 'cw' or 'ccw'", path=path)
    theta = np.deg2rad(theta_deg) * (1.0 if positive == "cw" else -1.0)
    warn += _check_positions(theta, path)
    uda, udb = ua[:, fit_mask], ub[:, fit_mask]
    mean_a, diff_a = 0.5 * (uda[0] + uda[1]), uda[0] - uda[1]
    mean_b, diff_b = 0.5 * (udb[0] + udb[1]), udb[0] - udb[1]
    return Reduced(theta=theta, u_a=mean_a, u_b=mean_b, u_dir_a=uda, u_dir_b=udb,
                   diff_a=diff_a, diff_b=diff_b, se_a=sa[:, fit_mask], se_b=sb[:, fit_mask],
                   s_a=ma["oa_sign"], s_b=mb["oa_sign"], g_local_mps2=g_loc, closure=closure,
                   warnings=tuple(warn), run_id=run_id)


#: Condition number of the 7-column harmonic design above which the positions are
#: rejected (noise amplified 1e4-fold: an 1 ug stop noise becomes 1e-2 in K) [X].
MAX_HARMONIC_COND = 1e4


def _check_positions(theta: np.ndarray, path) -> list[str]:
    """Reject position sets that cannot resolve the harmonics 0–3 (spec §3.2(a)).

    Fewer than 7 distinct positions leave some harmonic unidentifiable (exactly: a
    degree-3 trigonometric polynomial has at most 6 zeros, so 7 distinct angles always
    give rank 7); positions crowded into part of the circle make the harmonics
    practically unidentifiable (cond > :data:`MAX_HARMONIC_COND`). Returns warnings
    for a merely poor coverage (cond > 10; equal spacing gives sqrt 2).
    """
    n = theta.size
    H = harmonic_matrix(theta)
    _, s, vt = np.linalg.svd(H, full_matrices=True)
    srt = np.sort(np.mod(theta, 2 * np.pi))
    gaps = np.diff(np.r_[srt, srt[0] + 2 * np.pi]) if n else np.array([2 * np.pi])
    cover = 360.0 - np.rad2deg(gaps.max())
    if n < 7:
        r = int(np.sum(s > 1e-10 * s[0])) if s.size else 0
        null = vt[r:]
        bad = [HARMONIC_LABELS[j] for j in range(7) if np.linalg.norm(null[:, j]) > 1e-6]
        raise InputError(f"{n} distinct positions; the g^2 harmonic model needs at least 7 "
                         f"(unidentifiable here: {', '.join(bad)})", path=path)
    cond = float(s[0] / s[-1])
    weak = [HARMONIC_LABELS[j] for j in range(7) if abs(vt[-1, j]) > 0.3]
    if cond > MAX_HARMONIC_COND:
        raise InputError(f"the positions cover only {cover:.0f} deg of the circle: the "
                         f"harmonics {', '.join(weak)} are practically unidentifiable "
                         f"(harmonic cond {cond:.3g}); spread the positions over 360 deg",
                         path=path)
    if cond > 10:
        return [f"positions cover {cover:.0f} deg of the circle: harmonics {', '.join(weak)} "
                f"are poorly resolved (harmonic cond {cond:.3g}, equal spacing gives 1.41)"]
    return []


def reduce_record(record, *, g_local: float | None = None) -> Reduced:
    """Reduce a validated ``dual_tumble`` :class:`~inertialab.io.Record` (spec §2.3)."""
    df = record.data
    path = record.path
    dirs = df["direction"].astype(str).str.strip().str.upper()
    bad = ~dirs.isin(["CCW", "CW"])
    if bad.any():
        rows = (np.flatnonzero(bad.to_numpy())[:5] + 1).tolist()
        raise InputError("direction must be CCW or CW", path=path, column="direction", row=rows)
    runs = (df["run_id"].map(lambda v: "" if pd.isna(v) else str(v)).unique()
            if "run_id" in df.columns else np.array([""]))
    if runs.size > 1:
        raise InputError(f"the file holds {runs.size} runs ({', '.join(repr(str(r)) for r in runs[:4])}); give one "
                         "run per file", path=path, column="run_id")
    d = (dirs == "CW").to_numpy().astype(int)
    pos = df["pos_index"].to_numpy().astype(int)
    sets = [set(pos[d == k].tolist()) for k in (0, 1)]
    if sets[0] != sets[1]:
        only_ccw = sorted(sets[0] - sets[1])
        only_cw = sorted(sets[1] - sets[0])
        raise InputError(f"CCW and CW runs have different position sets (only CCW: "
                         f"{only_ccw or 'none'}; only CW: {only_cw or 'none'})", path=path,
                         column="pos_index")
    upos = np.array(sorted(sets[0]))
    pidx = np.searchsorted(upos, pos)
    th_all = df["theta_cmd_deg"].to_numpy(dtype=float)
    th = np.full(upos.size, np.nan)
    th[pidx] = th_all
    if not np.allclose(th[pidx], th_all, atol=1e-6):
        raise InputError("one pos_index has different theta_cmd_deg values", path=path,
                         column="theta_cmd_deg")
    t = df["t_s"].to_numpy(dtype=float)
    key = d * upos.size + pidx
    order = np.lexsort((t, key))
    ks = key[order]
    starts = np.r_[0, np.flatnonzero(np.diff(ks)) + 1]
    counts = np.diff(np.r_[starts, ks.size])
    smp = np.arange(ks.size) - np.repeat(starts, counts)
    S = int(counts.max())
    shape = (2, upos.size, S)

    def grid(col):
        a = np.full(shape, np.nan)
        if col in df.columns:
            vals = df[col].to_numpy(dtype=float)[order]
            a[ks // upos.size, ks % upos.size, smp] = vals
        return a

    rng_v = None
    if "dmm_range_v" in df.columns:
        rng_v = float(np.nanmin(df["dmm_range_v"].to_numpy(dtype=float)))
    run_id = str(runs[0]) if runs.size else ""
    red = reduce_stops(th, grid("t_s"), grid("v_a_v"), grid("v_b_v"), grid("t_r_c"),
                       record.meta, path=path, run_id=run_id, g_local=g_local,
                       dmm_range_v=rng_v)
    unsorted = [name for k, name in ((0, "CCW"), (1, "CW")) if np.any(np.diff(t[d == k]) < 0)]
    if unsorted:  # CONTRACTS.md: per-test tables are sorted, with a warning
        red = replace(red, warnings=red.warnings + (
            f"{path}: the {' and '.join(unsorted)} rows were not in time order; sorted by t_s",))
    return red


def reduce_run(run, *, g_local: float | None = None) -> Reduced:
    """Reduce a simulated :class:`~inertialab.sim.dual_tumble.DualRun` without a DataFrame."""
    a = run.arrays
    # arrays are indexed by position in both directions already
    return reduce_stops(a["theta_cmd_deg"], a["t_s"], a["v_a_v"], a["v_b_v"], a["t_r_c"],
                        run.meta, run_id=run.run_id, g_local=g_local)


# ------------------------------------------------------------------------------ fitting

@dataclass
class MethodResult:
    """One method's answer (the ``--json`` shape of the issue, plus diagnostics)."""

    method: str
    coef: dict
    sd: dict
    residual: float
    rank: int
    estimable: list
    warnings: list
    non_estimable: list = field(default_factory=list)
    residual_raw: float = float("nan")
    r_val: float = float("nan")
    extra: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        d = {"coef": self.coef, "sd": {k: (None if v is None or not np.isfinite(v) else v)
                                       for k, v in self.sd.items()},
             "residual": self.residual, "rank": self.rank, "estimable": self.estimable,
             "warnings": self.warnings}
        if self.non_estimable:
            d["non_estimable"] = self.non_estimable
        d["residual_raw"] = self.residual_raw
        if np.isfinite(self.r_val):
            d["residual_val"] = self.r_val
        d.update({k: v for k, v in self.extra.items() if not k.startswith("_")})
        return d


def _single(red: Reduced, meter: str, u=None):
    s = red.s_a if meter == "A" else red.s_b
    u = (red.u_a if meter == "A" else red.u_b) if u is None else u
    X, off = single_design(red.theta, meter, s=s)
    return lstsq(X, u - off, names=SINGLE_NAMES[meter])


def fit_single(red: Reduced) -> MethodResult:
    """M1: single-meter LS for each meter (spec §3.1); eta = delta_B - delta_A."""
    ra, rb = _single(red, "A"), _single(red, "B")
    coef, sd = {}, {}
    for r in (ra, rb):
        for j, n in enumerate(r.names):
            coef[n] = float(r.coef[j])
            sd[n] = float(r.sd[j])
    ia, ib = 2, 2  # delta index
    coef["eta"] = coef["delta_B"] - coef["delta_A"]
    cab = ra.cov_minnorm[ia, ia] + rb.cov_minnorm[ib, ib]
    sd["eta"] = float(np.sqrt(cab))
    res = float(np.sqrt(0.5 * (ra.sigma2 + rb.sigma2)))
    raw = float(np.sqrt(0.5 * (ra.residual_ss + rb.residual_ss) / red.n))
    return MethodResult("single-ls", coef, sd, res, ra.rank + rb.rank, [], [],
                        residual_raw=raw,
                        extra={"residual_per_meter": {"A": ra.residual, "B": rb.residual}})


def _harmonic(theta, y, s_a, s_b):
    H = harmonic_matrix(theta)
    r = lstsq(H, y, names=HARMONIC_LABELS)
    M = harmonic_map(s_a=s_a, s_b=s_b)
    Mp = np.linalg.pinv(M)
    combos = []
    for name, c in estimable_combinations(s_a=s_a, s_b=s_b).items():
        wh = Mp.T @ c  # c^T beta = c^T M^+ h for c in the row space of M
        combos.append({"name": name, "value": float(wh @ r.coef),
                       "sd": float(np.sqrt(max(wh @ r.cov_minnorm @ wh, 0.0)))})
    return r, combos


def _second_order_y(red: Reduced, y: np.ndarray, n_iter: int = 3) -> np.ndarray:
    """[X] spec §1.5: ``y <- y - [y_exact(theta + delta_A; K) - a^T K]`` with M1's
    delta_A, K0, K2, Kx and the current dual k1, eta; ``n_iter`` passes."""
    ra, rb = _single(red, "A"), _single(red, "B")
    A = g2_design(red.theta, s_a=red.s_a, s_b=red.s_b)
    K = {"KA0": ra.coef[0], "KA2": ra.coef[3], "KAx": ra.coef[4],
         "KB0": rb.coef[0], "KB2": rb.coef[3], "KBx": rb.coef[4]}
    delta_a = float(ra.coef[2])
    yc = y
    for _ in range(n_iter):
        r, combos = _harmonic(red.theta, yc, red.s_a, red.s_b)
        cd = {c["name"]: c["value"] for c in combos}
        K.update(kA1=cd["kA1"], kB1=cd["kB1"], eta=cd["eta"])
        beta = np.array([K[n] for n in COEF_NAMES])
        yc = y - (g2_exact(red.theta, K, delta_a=delta_a, s_a=red.s_a, s_b=red.s_b) - A @ beta)
    return yc


def _dual_system(red: Reduced, *, second_order: bool, u_a=None, u_b=None):
    A = g2_design(red.theta, s_a=red.s_a, s_b=red.s_b)
    ua = red.u_a if u_a is None else u_a
    ub = red.u_b if u_b is None else u_b
    y = g2_observation(ua, ub)
    if second_order:
        y = _second_order_y(replace(red, u_a=ua, u_b=ub), y)
    return A, y


def _ls(A, y, red: Reduced) -> MethodResult:
    r = lstsq(A, y, names=COEF_NAMES)
    h, combos = _harmonic(red.theta, y, red.s_a, red.s_b)
    nulls = null_space_text(r.null_space, COEF_NAMES)
    coef = {n: float(r.coef[j]) for j, n in enumerate(COEF_NAMES)}
    sd = {n: (float(h_sd) if est else None) for n, est, h_sd in
          zip(COEF_NAMES, r.estimable, r.min_norm_sd)}
    # individually estimable ones (kA1, kB1, eta) take the harmonic-LS SDs
    hs = {c["name"]: c for c in combos}
    for n in ("kA1", "kB1", "eta"):
        sd[n] = hs[n]["sd"]
        coef[n] = hs[n]["value"]
    non_est = [n for n, e in zip(COEF_NAMES, r.estimable) if not e]
    warn = []
    if non_est:
        warn.append(f"rank {r.rank} < 9: {', '.join(non_est)} are not estimable on their own "
                    f"(null directions {'; '.join(nulls)}); their min-norm values are "
                    "arbitrary along those directions, use the estimable combinations, a "
                    "prior (--method ebr --prior ...) or a second orientation")
    res = h.residual
    return MethodResult("ls", coef, sd, res, r.rank, combos, warn, non_estimable=non_est,
                        residual_raw=float(np.sqrt(h.residual_ss / y.size)),
                        extra={"min_norm_sd": {n: float(v) for n, v in
                                               zip(COEF_NAMES, r.min_norm_sd)},
                               "singular_values": r.singular_values.tolist(),
                               "cond": r.cond, "null_directions": nulls,
                               "naive_normal_equations": dict(zip(
                                   COEF_NAMES, naive_normal_equations(A, y).tolist()))})


def _combos_from(coef: np.ndarray, cov: np.ndarray, red: Reduced) -> list:
    out = []
    for name, c in estimable_combinations(s_a=red.s_a, s_b=red.s_b).items():
        out.append({"name": name, "value": float(c @ coef),
                    "sd": float(np.sqrt(max(c @ cov @ c, 0.0)))})
    return out


def _prior_args(prior: DualPrior | None):
    return (None, None) if prior is None else (prior.mean, prior.sd)


def _ebr(A, y, red: Reduced, prior: DualPrior | None, *, ebr_method="E1",
         lambda_combination="star") -> MethodResult:
    pm, ps = _prior_args(prior)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        e = EmpiricalBayesRidge(prior_mean=pm, prior_scale=ps, method=ebr_method,
                                lambda_combination=lambda_combination).fit(
            pd.DataFrame(A, columns=COEF_NAMES), y)
    msgs = [str(w.message) for w in caught
            if issubclass(w.category, (NonIdentifiableWarning, ShrinkageWarning))]
    coef = {n: float(v) for n, v in zip(COEF_NAMES, e.coef_)}
    sd = {n: float(v) for n, v in zip(COEF_NAMES, e.coef_sd_)}
    return MethodResult(
        "ebr", coef, sd, e.fit_.residual(), e.rank_,
        _combos_from(e.coef_, e.coef_cov_sandwich_, red), msgs,
        residual_raw=float(np.sqrt(np.sum((y - A @ e.coef_) ** 2) / y.size)),
        extra={"sd_sandwich": {n: float(v) for n, v in zip(COEF_NAMES, e.coef_sd_sandwich_)},
               "lambda": e.lambda_, "lambda_star": e.lambda_star_, "lambda0": e.lambda0_,
               "minimax_sufficient": e.minimax_sufficient_, "k": e.k_,
               "r_eff": e.r_eff_, "shrinkage": e.shrinkage_.tolist(),
               "prior": "none (beta0 = 0, W = I)" if prior is None else prior.kind,
               "ebr_method": ebr_method, "_fit": e})


def _ridge(A, y, red: Reduced, prior: DualPrior | None, rule: str) -> MethodResult:
    pm, ps = _prior_args(prior)
    r = ridge(A, y, k=rule, prior_mean=pm, prior_scale=ps)
    f = r.fit
    coef = {n: float(v) for n, v in zip(COEF_NAMES, f.coef)}
    sd = {n: float(v) for n, v in zip(COEF_NAMES, f.sd_sandwich)}
    warn = []
    if f.canon.rank < 9:
        warn.append(f"rank {f.canon.rank} < 9: along the null directions the ridge estimate "
                    "is the prior centre; the sandwich SD is 0 there and says nothing")
    return MethodResult(
        f"ridge-{rule}", coef, sd, f.residual(), f.canon.rank,
        _combos_from(f.coef, f.cov_sandwich, red), warn,
        residual_raw=float(np.sqrt(np.sum((y - A @ f.coef) ** 2) / y.size)),
        extra={"k": r.k, "prior": "none (beta0 = 0, W = I)" if prior is None else prior.kind,
               "_fit": f})


def _fit_method(method: str, red: Reduced, prior, *, second_order: bool, u_a=None, u_b=None,
                ebr_method="E1", lambda_combination="star") -> MethodResult:
    if method == "single-ls":
        if u_a is not None:
            red = replace(red, u_a=u_a, u_b=u_b)
        return fit_single(red)
    A, y = _dual_system(red, second_order=second_order, u_a=u_a, u_b=u_b)
    if method == "ls":
        return _ls(A, y, red)
    if method == "ebr":
        return _ebr(A, y, red, prior, ebr_method=ebr_method,
                    lambda_combination=lambda_combination)
    if method in ("ridge-hkb", "ridge-gcv"):
        return _ridge(A, y, red, prior, method.split("-")[1])
    raise InputError(f"unknown method '{method}' (use {', '.join(METHODS)} or all)")


def _predict_err(method: str, fit: MethodResult, red: Reduced, ua, ub) -> np.ndarray:
    if method == "single-ls":
        ea = []
        for meter, u in (("A", ua), ("B", ub)):
            X, off = single_design(red.theta, meter, s=red.s_a if meter == "A" else red.s_b)
            b = np.array([fit.coef[n] for n in SINGLE_NAMES[meter]])
            ea.append(u - off - X @ b)
        return np.concatenate(ea)
    A = g2_design(red.theta, s_a=red.s_a, s_b=red.s_b)
    beta = np.array([fit.coef[n] for n in COEF_NAMES])
    return g2_observation(ua, ub) - A @ beta


def _r_val(method: str, red: Reduced, prior, **kw) -> float:
    """Cross-fit residual: fit CCW, evaluate CW, and vice versa; RMS (spec §4)."""
    errs = []
    for a, b in ((0, 1), (1, 0)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            f = _fit_method(method, red, prior, u_a=red.u_dir_a[a], u_b=red.u_dir_b[a], **kw)
        errs.append(_predict_err(method, f, red, red.u_dir_a[b], red.u_dir_b[b]))
    e = np.concatenate(errs)
    return float(np.sqrt(np.mean(e**2)))


@dataclass
class DualFit:
    """Result of :func:`calibrate`: per-method results, the model and diagnostics."""

    reduced: Reduced
    methods: dict
    model: DualCalibration
    diagnostics: dict
    warnings: list

    def to_json(self) -> dict:
        return {"methods": {k: v.to_json() for k, v in self.methods.items()},
                "diagnostics": self.diagnostics}


def calibrate(red: Reduced, *, methods=("single-ls", "ls", "ebr"), prior=None,
              second_order: bool = False, ebr_method: str = "E1",
              lambda_combination: str = "star", cross_fit: bool = True) -> DualFit:
    """Fit the chosen methods to one reduced tumble.

    Parameters
    ----------
    red : Reduced
    methods : sequence of str or "all", default=("single-ls", "ls", "ebr")
    prior : None, "none", "certificate", path or DualPrior
        Prior of EBR and the ridge baselines (None: paper-faithful beta0 = 0, W = I).
    second_order : bool, default=False
        Apply the [X] second-order correction of spec §1.5 to y.
    """
    if methods == "all" or methods == ("all",):
        methods = METHODS
    prior = load_prior(prior)
    out = {}
    kw = {"second_order": second_order, "ebr_method": ebr_method,
          "lambda_combination": lambda_combination}
    for m in methods:
        res = _fit_method(m, red, prior, **kw)
        if cross_fit:
            res.r_val = _r_val(m, red, prior, **kw)
        out[m] = res
    A = g2_design(red.theta, s_a=red.s_a, s_b=red.s_b)
    sv = np.linalg.svd(A, compute_uv=False)
    H = harmonic_matrix(red.theta)
    diag = {"n_positions": red.n, "singular_values": sv.tolist(),
            "cond": float(sv[0] / sv[-1]) if sv[-1] > 0 else None,
            "rank": int(np.sum(sv > 1e-10 * sv[0])),
            "harmonic_cond": float(np.linalg.cond(H)),
            "closure": red.closure,
            "hysteresis_rms_g": {"A": float(np.sqrt(np.mean(red.diff_a**2))),
                                 "B": float(np.sqrt(np.mean(red.diff_b**2)))},
            "oa_sign": {"A": red.s_a, "B": red.s_b}, "g_local_mps2": red.g_local_mps2,
            "prior": None if prior is None else prior.to_json()}
    primary = "ebr" if "ebr" in out else ("ls" if "ls" in out else next(iter(out)))
    pm = out[primary]
    model = DualCalibration(method=primary, coef=dict(pm.coef), sd=dict(pm.sd),
                            s_a=red.s_a, s_b=red.s_b, g_local_mps2=red.g_local_mps2,
                            estimable=list(pm.estimable), residual=pm.residual)
    warn = list(red.warnings)
    for r in out.values():
        warn += [w for w in r.warnings if w not in warn]
    return DualFit(red, out, model, diag, warn)


def head_error_sensitivity(red: Reduced, *, methods=("single-ls", "ls"), a1_arcsec: float = 1.0,
                           n_psi: int = 36, prior=None) -> dict:
    """Change of KA2, KB2 (and the estimable KA2+s_B KBx) per method when the data carry a
    first-harmonic head error ``a1 sin(theta + psi)``, for ``n_psi`` phases (spec §1.4).

    The perturbation is applied to the measured outputs to first order
    (``du_A = cos(theta) dtheta``, ``du_B = -sin(theta) dtheta``) and each method is
    refitted; returns ``{"psi_deg": [...], method: {"KA2": [...], ...}}`` in g/g^2.
    """
    prior = load_prior(prior)
    psi = np.linspace(0.0, 2 * np.pi, n_psi, endpoint=False)
    a1 = a1_arcsec * units.ARCSEC
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        base = {m: _fit_method(m, red, prior, second_order=False) for m in methods}
        out = {"psi_deg": np.rad2deg(psi).tolist(), "a1_arcsec": a1_arcsec}
        for m in methods:
            rows = {"KA2": [], "KB2": [], "KA0": []}
            for p in psi:
                dth = a1 * np.sin(red.theta + p)
                ua = red.u_a + np.cos(red.theta) * dth
                ub = red.u_b - np.sin(red.theta) * dth
                f = _fit_method(m, red, prior, second_order=False, u_a=ua, u_b=ub)
                for k in rows:
                    rows[k].append(f.coef[k] - base[m].coef[k])
            out[m] = rows
    return out


def errors_vs_truth(fit: DualFit, truth: dict) -> dict:
    """Per method, estimate minus truth for every coefficient and estimable combination
    present in ``truth`` (simulation; spec §4 "estimate error")."""
    out = {}
    tv = np.array([truth.get(n, np.nan) for n in COEF_NAMES], dtype=float)
    combos = estimable_combinations(s_a=fit.reduced.s_a, s_b=fit.reduced.s_b)
    for m, r in fit.methods.items():
        e = {n: float(v - truth[n]) for n, v in r.coef.items()
             if n in truth and v is not None and np.isfinite(truth[n])}
        ce = {c["name"]: float(c["value"] - combos[c["name"]] @ tv) for c in r.estimable
              if np.all(np.isfinite(tv[combos[c["name"]] != 0]))}
        out[m] = {"coef": e, "estimable": ce}
    return out


# ------------------------------------------------------------------- two orientations

def fit_two_orientation(red1: Reduced, red2: Reduced) -> MethodResult:
    """Stacked LS of two tumbles with opposite OA signs (spec §7.2): per-run K0, k1, eta,
    shared K2 and Kx; 14 columns, full rank when both meters are flipped."""
    if red1.s_a == red2.s_a and red1.s_b == red2.s_b:
        warnings.warn("both runs have the same OA signs: the stacked design stays rank "
                      "deficient (turn the meters 180 deg about their IA for run 2)",
                      NonIdentifiableWarning, stacklevel=2)
    blocks, ys = [], []
    run_cols = ["KA0", "KB0", "kA1", "kB1", "eta"]
    names = [f"{n}_1" for n in run_cols] + [f"{n}_2" for n in run_cols] + ["KA2", "KB2",
                                                                          "KAx", "KBx"]
    for i, red in enumerate((red1, red2)):
        A = g2_design(red.theta, s_a=red.s_a, s_b=red.s_b)
        X = np.zeros((red.n, 14))
        X[:, 5 * i:5 * i + 5] = A[:, :5]
        X[:, 10:] = A[:, 5:]
        blocks.append(X)
        ys.append(red.y)
    X = np.vstack(blocks)
    y = np.concatenate(ys)
    r = lstsq(X, y, names=names)
    coef = {n: float(v) for n, v in zip(names, r.coef)}
    sd = {n: (float(v) if np.isfinite(v) else None) for n, v in zip(names, r.sd)}
    non_est = [n for n, e in zip(names, r.estimable) if not e]
    warn = ([f"rank {r.rank} < 14: {', '.join(non_est)} not estimable"] if non_est else [])
    return MethodResult("two-orientation-ls", coef, sd, r.residual, r.rank, [], warn,
                        non_estimable=non_est, residual_raw=float(np.sqrt(r.residual_ss / y.size)),
                        extra={"cond": r.cond, "singular_values": r.singular_values.tolist()})


# ------------------------------------------------------------------------------ design

def design_dual(n_positions: int = 20, *, range_deg=(0.0, 360.0), step_deg: float = 1.0,
                noise_sd=None) -> dict:
    """D-optimal positions for the identifiable 7-harmonic g^2 model (spec §7.2).

    ``range_deg`` restricts the candidate angles ([lo, hi), step ``step_deg``);
    ``noise_sd`` (callable of angle in deg, or None) gives unequal noise. Returns a
    JSON-ready dict with the angles and D/A/E criteria, beside those of equal spacing.
    """
    lo, hi = float(range_deg[0]), float(range_deg[1])
    if not hi > lo or step_deg <= 0:
        raise InputError("the angle range must be increasing and the step positive")
    cand_deg = np.arange(lo, hi - 1e-9 if hi - lo >= 360 else hi + 1e-9, step_deg)
    w = None
    if noise_sd is not None:
        w = 1.0 / np.asarray([noise_sd(a) for a in cand_deg], dtype=float) ** 2
    d = d_optimal_design(n_positions, candidates=np.deg2rad(cand_deg), basis=harmonic_matrix,
                         weights=w)
    eq = np.deg2rad(lo + np.arange(n_positions) * (min(hi - lo, 360.0) / n_positions))
    ce = design_criteria(eq, basis=harmonic_matrix)
    A = g2_design(d.theta)
    sv = np.linalg.svd(A, compute_uv=False)
    return {"positions_deg": np.rad2deg(d.theta).round(6).tolist(),
            "criteria": asdict(d.criteria),
            "equally_spaced": {"positions_deg": np.rad2deg(eq).round(6).tolist(),
                               "criteria": asdict(ce)},
            "g2_design_rank": int(np.sum(sv > 1e-10 * sv[0])),
            "note": "criteria of the 7-column harmonic model; det(A^T A) of the 9-column "
                    "g^2 design is 0 for every design (rank 7)"}


# ------------------------------------------------------------------------------- model

class DualCalibration:
    """Calibrated dual-meter coefficients (model file type ``dual-calibration``)."""

    MODEL_TYPE = "dual-calibration"

    def __init__(self, *, method: str, coef: dict, sd: dict, s_a: int, s_b: int,
                 g_local_mps2: float, estimable=(), residual: float = float("nan")):
        self.method = method
        self.coef = dict(coef)
        self.sd = dict(sd)
        self.s_a = int(s_a)
        self.s_b = int(s_b)
        self.g_local_mps2 = float(g_local_mps2)
        self.estimable = list(estimable)
        self.residual = float(residual)

    def to_dict(self) -> dict:
        return {"method": self.method, "coef": self.coef,
                "sd": {k: (None if v is None or not np.isfinite(v) else v)
                       for k, v in self.sd.items()},
                "s_a": self.s_a, "s_b": self.s_b, "g_local_mps2": self.g_local_mps2,
                "estimable": self.estimable, "residual": self.residual,
                "units": {k: COEF_UNITS.get(k, "") for k in self.coef}}

    @classmethod
    def from_dict(cls, d: dict) -> DualCalibration:
        try:
            missing = [n for n in COEF_NAMES if n not in d["coef"]]
            if missing:
                raise InputError(f"dual-calibration model lacks {', '.join(missing)}")
            sd = {k: (float("inf") if v is None else float(v)) for k, v in d["sd"].items()}
            return cls(method=str(d["method"]), coef={k: float(v) for k, v in d["coef"].items()},
                       sd=sd, s_a=int(d["s_a"]), s_b=int(d["s_b"]),
                       g_local_mps2=float(d["g_local_mps2"]),
                       estimable=d.get("estimable", []),
                       residual=float(d["residual"]) if d.get("residual") is not None
                       else float("nan"))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"malformed dual-calibration model: {exc}") from None

    def predict_outputs(self, phi):
        """Normalised outputs (u_A, u_B) in local g at head angle ``phi`` (rad)."""
        from inertialab.sensors.dual_meter import meter_outputs

        return meter_outputs(phi, self.coef, s_a=self.s_a, s_b=self.s_b)


# ------------------------------------------------------------------------- Monte Carlo

def _truth_vec(truth: dict) -> np.ndarray:
    return np.array([truth[n] for n in COEF_NAMES])


def monte_carlo(n_runs: int, *, seed: int = 20240603, h: float = 1.0, scenario: str = "S1",
                prior: str = "history", methods=("single-ls", "ls", "ebr"),
                two_orientation: bool = False, n_positions: int = 20,
                second_order: bool = False, cross_fit: bool = False, overrides=None,
                progress=None) -> dict:
    """Monte Carlo over ``n_runs`` virtual tumbles; run m uses seed ``seed + m`` (spec §6).

    ``overrides`` are extra :class:`~inertialab.sim.dual_tumble.DualLabConfig` fields.

    ``prior``: "history" (the unit is drawn around table 6.1 with its H = 6 historical
    calibrations, spec §6.5), "certificate" or "none". Returns arrays (n_runs, ...) of
    errors per method, SDs, residuals and lambda; JSON-ready summaries come from the
    benchmark.
    """
    from inertialab.sim.dual_tumble import (
        prior_from_history,
        scenario_config,
        simulate_run,
        simulate_two_orientation,
    )

    progress = progress or NullProgress()
    cfg = scenario_config(scenario, h=h, draw_unit=True, n_positions=n_positions,
                          **(overrides or {}))
    out = {m: {"err": [], "sd": [], "R": [], "R_val": [], "combo_err": [], "combo_sd": []}
           for m in methods}
    out["prior_err"] = []
    out["truth"] = []
    out["lambda"] = []
    out["post_sd"] = []
    out["two_orientation_err"] = []
    for m_ in range(n_runs):
        g = as_generator(seed + m_)
        from inertialab.sim.dual_tumble import draw_unit

        truth0, hist = draw_unit(g)
        if two_orientation:
            r1, r2 = simulate_two_orientation(cfg, g, coef=truth0)
            red1, red2 = reduce_run(r1), reduce_run(r2)
            tw = fit_two_orientation(red1, red2)
            tv = r1.truth
            e = [tw.coef[n] - tv[n] for n in ("KA2", "KB2", "KAx", "KBx")]
            out["two_orientation_err"].append(e)
            run, red = r1, red1
        else:
            run = simulate_run(cfg, g, coef=truth0)
            red = reduce_run(run)
        truth = _truth_vec(run.truth)
        if prior == "history":
            pj = prior_from_history(hist)
            pr = DualPrior("history", np.array([pj[n]["mean"] for n in COEF_NAMES]),
                           np.array([pj[n]["sd"] for n in COEF_NAMES]))
        else:
            pr = load_prior(prior)
        out["prior_err"].append((np.zeros(9) if pr is None else pr.mean) - truth)
        out["truth"].append(truth)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fit = calibrate(red, methods=methods, prior=pr, second_order=second_order,
                            cross_fit=cross_fit)
        combos = estimable_combinations(s_a=red.s_a, s_b=red.s_b)
        for m in methods:
            res = fit.methods[m]
            if m == "single-ls":
                est = np.array([res.coef[n] for n in COEF_NAMES])
                sd = np.array([res.sd[n] for n in COEF_NAMES])
            else:
                est = np.array([res.coef[n] for n in COEF_NAMES])
                sd = np.array([np.inf if res.sd[n] is None else res.sd[n] for n in COEF_NAMES])
            out[m]["err"].append(est - truth)
            out[m]["sd"].append(sd)
            out[m]["R"].append(res.residual)
            out[m]["R_val"].append(res.r_val)
            if res.estimable:
                out[m]["combo_err"].append([c["value"] - combos[c["name"]] @ truth
                                            for c in res.estimable])
                out[m]["combo_sd"].append([c["sd"] for c in res.estimable])
            if m == "ebr":
                out["lambda"].append(res.extra["lambda"])
        progress.update(m_ + 1, n_runs, "Monte Carlo")
    for m in methods:
        for k in list(out[m]):
            out[m][k] = np.asarray(out[m][k], dtype=float)
    for k in ("prior_err", "truth", "lambda", "two_orientation_err"):
        out[k] = np.asarray(out[k], dtype=float)
    out["combo_names"] = list(estimable_combinations().keys())
    return out


# ---------------------------------------------------------------------------- the demo

@dataclass(frozen=True)
class QuickSettings:
    """Demo settings (quick): one default run, a small Monte Carlo and head-error sweep."""

    seed: int = 20240603
    n_mc: int = 30
    h_values: tuple = (0.0, 1.0, 2.5)


@dataclass(frozen=True)
class FullSettings:
    """Demo settings (full)."""

    seed: int = 20240603
    n_mc: int = 150
    h_values: tuple = (0.0, 0.5, 1.0, 2.5, 5.0)


def run_demo(settings, progress=None) -> StudyResult:
    """The ``dual`` study of ``inertialab demo``."""
    from inertialab.sim.dual_tumble import prior_from_history, scenario_config, simulate_run

    progress = progress or NullProgress()
    t0 = time.perf_counter()
    cfg = scenario_config("S1", draw_unit=True)
    run = simulate_run(cfg, settings.seed)
    red = reduce_run(run)
    pj = prior_from_history(run.head["history"])
    pr = DualPrior("history", np.array([pj[n]["mean"] for n in COEF_NAMES]),
                   np.array([pj[n]["sd"] for n in COEF_NAMES]))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = calibrate(red, methods=METHODS, prior=pr)
    truth = run.truth
    table = []
    for m, r in fit.methods.items():
        row = {"method": m, "residual_ug": r.residual * 1e6, "r_val_ug": r.r_val * 1e6}
        for n in ("KA2", "KB2", "kA1", "eta"):
            row[f"{n}_err"] = r.coef[n] - truth[n]
        table.append(row)
    progress.update(1, 3, "sweep")
    sweep = {}
    for h in settings.h_values:
        mc = monte_carlo(settings.n_mc, seed=settings.seed, h=h, methods=("single-ls", "ebr"))
        ia2 = COEF_NAMES.index("KA2")
        sweep[str(h)] = {
            "single_ls_KA2_rms": float(np.sqrt(np.mean(mc["single-ls"]["err"][:, ia2] ** 2))),
            "ebr_KA2_rms": float(np.sqrt(np.mean(mc["ebr"]["err"][:, ia2] ** 2))),
            "prior_KA2_rms": float(np.sqrt(np.mean(mc["prior_err"][:, ia2] ** 2))),
            "single_ls_R_median_ug": float(np.median(mc["single-ls"]["R"]) * 1e6),
            "ebr_R_median_ug": float(np.median(mc["ebr"]["R"]) * 1e6)}
    progress.update(2, 3, "design")
    design = design_dual(20)
    progress.update(3, 3, "done")
    e1 = sweep.get("1.0") or next(iter(sweep.values()))
    head = [
        Headline("g^2 design rank (9 coefficients)", fit.methods["ls"].rank, "collinear"),
        Headline("EBR K2 RMS error, historical prior (h = 1)", e1["ebr_KA2_rms"] * 1e6,
                 "higher accuracy", "ug/g^2"),
        Headline("single-meter LS KA2 RMS error (h = 1)", e1["single_ls_KA2_rms"] * 1e6,
                 "lowest accuracy", "ug/g^2"),
    ]
    text = [
        "Two orthogonal accelerometers on a virtual dividing head (spec 003): the g^2 "
        "observation cancels the head angle errors to first order but has rank 7 for 9 "
        "coefficients, so K0, K2 and Kx of each meter are coupled (null directions "
        + "; ".join(fit.methods["ls"].extra["null_directions"]) + ").",
        "Empirical Bayes ridge separates K2 only through its prior: with the paper's "
        "zero prior it equals minimum-norm LS along the null directions; with a prior "
        "from six historical calibrations it improves on that prior.",
    ]
    data = {"reduced": red, "fit": fit, "truth": truth, "sweep": sweep, "run": run}
    return StudyResult(
        name="dual", title="Dual accelerometers on a dividing head (g^2 model, EBR)",
        settings=settings_dict(settings), headline=head,
        tables={"single_run": table, "head_error_sweep": sweep, "design": design,
                "null_directions": fit.methods["ls"].extra["null_directions"]},
        data=data, text=text, wall_s=time.perf_counter() - t0)


STUDY = Study("dual", "Dual accelerometers on a dividing head (g^2 model, EBR)",
              quick=QuickSettings(), full=FullSettings(), run=run_demo)
