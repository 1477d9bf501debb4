"""Dual-accelerometer dividing-head calibration (spec 003): the fits and the model.

On a reduced tumble (:class:`~inertialab.calib.dual_reduce.Reduced`, spec §2.3) this module

1. fits M1 single-meter LS per meter (§3.1), M2 dual LS on the g^2 observation (harmonic
   LS with the estimable combinations, minimum-norm LS, naive normal equations; §3.2),
   M3 empirical Bayes ridge with the paper-faithful, certificate or historical prior
   (§3.3) and the ridge baselines HKB and GCV (§3.4);
2. reports per method the coefficients, SDs (§3.5), the residual R, the CCW->CW cross-fit
   residual R_val and the rank diagnostics (§4), and in simulation the errors vs truth;
3. fits the two-orientation stacked design (§7.2), designs D-optimal positions, and
   measures the head-error sensitivity of each method (§1.4);
4. holds the fitted artefact :class:`DualCalibration` (model-file type ``dual-calibration``).

The K2/Kx coupling of the g^2 design (rank 7 for 9 coefficients) is never hidden:
non-estimable coefficients of LS carry ``sd = None`` and the ``non_estimable`` flag, and
EBR warns that along the null directions it returns the prior centre.

Coefficient names (spec §1.3, docs/dual.md): ``KA0 KB0 kA1 kB1 eta KA2 KB2
KAx KBx``. The paper calls the cross-coupling term "Kip"; for a tumble about the
pendulous axis it is K_io (spec §1.3), named ``Kx`` here; tables that mirror the paper
label ``KAx``/``KBx`` with the aliases ``KAip_paper``/``KBip_paper``
(:data:`~inertialab.sensors.dual_meter.PAPER_ALIASES`), which prior and model files may
also use.
"""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass, field, replace

import numpy as np
import pandas as pd

from inertialab import units
from inertialab.calib.dual_prior import CERT_LIMITS, DualPrior, resolve_prior
from inertialab.calib.dual_reduce import HARMONIC_LABELS, Reduced, reduce_stops
from inertialab.errors import InputError, NonIdentifiableWarning, ShrinkageWarning
from inertialab.io.model_schemas import check_own_payload
from inertialab.regress.design import d_optimal_design, design_criteria
from inertialab.regress.ebr import EmpiricalBayesRidge
from inertialab.regress.lstsq import lstsq, naive_normal_equations, null_space_text
from inertialab.regress.ridge import ridge
from inertialab.sensors.dual_meter import (
    COEF_NAMES,
    COEF_UNITS,
    PAPER_ALIASES,
    SINGLE_NAMES,
    canonical_coef_name,
    estimable_combinations,
    g2_design,
    g2_exact,
    g2_observation,
    harmonic_map,
    harmonic_matrix,
    single_design,
)

__all__ = ["CERT_LIMITS", "METHODS", "PAPER_ALIASES", "DualCalibration", "DualFit", "DualPrior", "MethodResult",
           "Reduced", "calibrate", "design_dual", "errors_vs_truth", "fit_single",
           "fit_two_orientation", "head_error_sensitivity", "reduce_stops"]

METHODS = ("single-ls", "ls", "ebr", "ridge-hkb", "ridge-gcv")


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
                    "prior (argument 'method' = 'ebr' with argument 'prior') or a second "
                    "orientation")
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
    prior = resolve_prior(prior)
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
    prior = resolve_prior(prior)
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

#: Bounds of :func:`design_dual` (1e8 positions ran out of memory). The
#: exchange algorithm costs positions x candidates 7x7 determinants per sweep; 360
#: positions on a 0.1-deg grid take seconds. Spec S4 uses 8 to 36 positions.
MAX_DESIGN_POSITIONS = 360
MAX_DESIGN_CANDIDATES = 3601


def design_dual(n_positions: int = 20, *, range_deg=(0.0, 360.0), step_deg: float = 1.0,
                noise_sd=None) -> dict:
    """D-optimal positions for the identifiable 7-harmonic g^2 model (spec §7.2).

    ``range_deg`` restricts the candidate angles ([lo, hi), step ``step_deg``);
    ``noise_sd`` (callable of angle in deg, or None) gives unequal noise. Returns a
    JSON-ready dict with the angles and D/A/E criteria, beside those of equal spacing.
    """
    lo, hi = float(range_deg[0]), float(range_deg[1])
    step_deg = float(step_deg)
    if not (np.isfinite(lo) and np.isfinite(hi) and np.isfinite(step_deg)):
        raise InputError("argument 'range_deg' and 'step_deg' must be finite")
    if not hi > lo or step_deg <= 0:
        raise InputError("the angle range must be increasing and the step positive")
    if not isinstance(n_positions, (int, np.integer)) or isinstance(n_positions, bool) \
            or not 1 <= n_positions <= MAX_DESIGN_POSITIONS:
        raise InputError(f"argument 'n_positions' must be an integer from 7 to "
                         f"{MAX_DESIGN_POSITIONS}, got {n_positions}")
    n_cand = int(min(hi - lo, 360.0) // step_deg) + 1
    if n_cand > MAX_DESIGN_CANDIDATES:
        raise InputError(f"argument 'step_deg' = {step_deg:g} gives {n_cand} candidate angles; "
                         f"at most {MAX_DESIGN_CANDIDATES} (a step of at least "
                         f"{min(hi - lo, 360.0) / (MAX_DESIGN_CANDIDATES - 1):.3g} deg here)")
    cand_deg = np.arange(lo, hi - 1e-9 if hi - lo >= 360 else hi + 1e-9, step_deg)
    if n_positions > cand_deg.size:
        raise InputError(f"argument 'n_positions' = {n_positions} exceeds the {cand_deg.size} "
                         "candidate angles of the range and step")
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
    """Calibrated dual-meter coefficients (model file type ``dual-calibration``).

    Examples
    --------
    The outputs the coefficients predict: at a head angle of 0 meter A senses no input
    (its bias KA0), at 90 deg one g with its scale-factor error kA1 and second-order term
    KA2:

    >>> import numpy as np
    >>> coef = dict(KA0=1e-4, KB0=-2e-4, kA1=2e-4, kB1=-3e-4, eta=0.0, KA2=5e-6, KB2=0.0,
    ...             KAx=0.0, KBx=0.0)
    >>> cal = DualCalibration(method="ls", coef=coef, sd=dict.fromkeys(coef, 1e-6), s_a=1,
    ...                       s_b=1, g_local_mps2=9.80)
    >>> u_a, u_b = cal.predict_outputs(np.array([0.0, np.pi / 2]))
    >>> bool(np.allclose(u_a, [1e-4, 1e-4 + (1 + 2e-4) + 5e-6]))
    True
    >>> bool(np.isclose(u_b[0], -2e-4 + (1 - 3e-4)))  # meter B sees cos(0) = 1 g
    True
    >>> DualCalibration.from_dict(cal.to_dict()).coef == cal.coef
    True
    """

    MODEL_TYPE = "dual-calibration"
    #: Payload format of this type (bump when ``to_dict`` changes; old versions keep loading).
    FORMAT_VERSION = 1

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
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        try:
            coef = {canonical_coef_name(k): float(v) for k, v in d["coef"].items()}
            missing = [n for n in COEF_NAMES if n not in coef]
            if missing:
                raise InputError(f"dual-calibration model lacks {', '.join(missing)}")
            bad = [k for k, v in coef.items() if not np.isfinite(v)]
            if bad:
                raise InputError(f"dual-calibration model has non-finite {', '.join(bad)}")
            sd = {canonical_coef_name(k): (float("inf") if v is None else float(v))
                  for k, v in d["sd"].items()}
            if any(np.isnan(v) or v < 0 for v in sd.values()):
                raise InputError("dual-calibration model: sd must be >= 0 or null")
            if int(d["s_a"]) not in (1, -1) or int(d["s_b"]) not in (1, -1):
                raise InputError("dual-calibration model: s_a and s_b must be +1 or -1")
            g = float(d["g_local_mps2"])
            if not (np.isfinite(g) and 9.7 < g < 9.9):
                raise InputError(f"dual-calibration model: g_local_mps2 {g} is not a local "
                                 "gravity on Earth")
            return cls(method=str(d["method"]), coef=coef,
                       sd=sd, s_a=int(d["s_a"]), s_b=int(d["s_b"]),
                       g_local_mps2=float(d["g_local_mps2"]),
                       estimable=d.get("estimable", []),
                       residual=float(d["residual"]) if d.get("residual") is not None
                       else float("nan"))
        except (KeyError, TypeError, ValueError, AttributeError, OverflowError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"malformed dual-calibration model: {exc}") from None

    def predict_outputs(self, phi):
        """Normalised outputs (u_A, u_B) in local g at head angle ``phi`` (rad)."""
        from inertialab.sensors.dual_meter import meter_outputs

        return meter_outputs(phi, self.coef, s_a=self.s_a, s_b=self.s_b)

