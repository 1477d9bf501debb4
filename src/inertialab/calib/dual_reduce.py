"""Reduction of a dual-meter tumble to stop-level outputs (spec 003 §2.3), on arrays.

DMM samples (CCW/CW, position, sample; NaN padded) to one normalised output per meter,
position and direction: settling samples dropped, robust mean, voltage to local g,
CCW/CW mean, with the closure and hysteresis diagnostics and the position checks of
§3.2(a). The record -> arrays step is :func:`inertialab.workflows.dual.prepare`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from inertialab import units
from inertialab.errors import InputError
from inertialab.sensors.dual_meter import g2_observation, harmonic_matrix, reduce_to_g

__all__ = ["HARMONIC_LABELS", "MAX_HARMONIC_COND", "Reduced", "reduce_stops"]

HARMONIC_LABELS = ("1", "cos2t", "sin2t", "sint", "cost", "sin3t", "cos3t")


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
        raise InputError("no local gravity: give argument 'g_local' or 'g_local_mps2' in the sidecar",
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

