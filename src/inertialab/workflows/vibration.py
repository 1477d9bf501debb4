"""Workflow ``vibration``: FOG errors under linear vibration (spec 001).

Verbs: :func:`prepare` (a ``gyro_log`` record -> validated, segmented
:class:`~inertialab.calib.vibration.VibrationRun`), :func:`fit` (sweep and optional fixed
run -> :class:`VibrationResult` with the fitted
:class:`~inertialab.calib.vibration.VibrationModel`), :func:`apply` (model + record ->
compensated record). The pipeline of spec 001 §3.11 on a sweep record (E1) and,
optionally, a fixed-frequency record (E2), both in the ``gyro_log`` schema with
``vib_on``, ``vib_freq_hz`` and (optionally) ``phase``:

1. segment P1 / P2 / P3 (``k_on``, ``k_off`` = first/last sample with ``vib_on = 1``);
2. overlapping Allan deviation and the five noise terms Q N B K R per phase
   (seed Table 1);
3. spectral views (Welch per phase, CWT scalogram, EMD of a window at the onset);
4. db4 decomposition to J = 10 and the level L (6 = seed, or the §3.6 rule);
5. noise terms of raw, ``A_L`` and ``x - A_L`` (seed Table 2, "ols" as in the paper);
6. bias-error targets versus frequency from E1 (§3.7), an RBF network (§3.8) and the
   4th-order polynomial baseline (§3.9);
7. compensation of E2 (§3.10) and the noise terms of raw, ``A_L``, RBF- and
   polynomial-compensated E2 (seed Table 3, "wls", ``tau >= 2^(L+1) tau0`` for
   ``A_L``-derived rows), the residual bias and the edge metrics of §4.

The commands ``vibration fit|apply``, one call each: :class:`FitConfig` (the one
settings class of the command and the pipeline: each setting named as its flag and its
JSON key; ``VibrationConfig`` its deprecated former name) and
``run_fit(sweep, fixed, config) -> FitResult``, :class:`ApplyConfig` and
``run_apply(model, record, config) -> ApplyResult`` (:class:`inertialab.result.Result`).
The estimator (:mod:`inertialab.calib.vibration`), the wavelets (PyWavelets) and the
record reader (:mod:`inertialab.workflows.vibration_record`) are imported inside the
functions that use them, so that ``vibration fit --help`` starts light; their names
re-exported here load on first use.

The model itself (estimator on arrays, model file) is :mod:`inertialab.calib.vibration`;
the virtual-lab demo is :mod:`inertialab.studies.vibration`. This module neither reads
arguments nor draws (figures are in :mod:`inertialab.report.figures.vibration`).
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from inertialab import metrics as _metrics
from inertialab.config import Config as _Settings
from inertialab.config import seed_setting, setting
from inertialab.errors import DataQualityWarning, ExtrapolationWarning, InputError
from inertialab.progress import NullProgress
from inertialab.result import ResultBase

if TYPE_CHECKING:
    from inertialab.calib.vibration import (
        BiasTargets,
        VibrationModel,
        VibrationRun,
        bias_targets,
        residual_metrics,
    )
    from inertialab.noise.spectral import wavelet as wv
    from inertialab.workflows.vibration_record import load_run, prepare, run_from_frame

__all__ = [
    "BiasTargets",
    "CompensatedRecord",
    "VibrationConfig",
    "VibrationModel",
    "VibrationResult",
    "VibrationRun",
    "analyse",
    "apply",
    "bias_targets",
    "fit",
    "load_run",
    "prepare",
    "residual_metrics",
    "run_from_frame",
    "ApplyConfig",
    "ApplyResult",
    "FitConfig",
    "FitResult",
    "run_apply",
    "run_fit",
]

#: Names of the floors below re-exported for callers of the workflow, loaded on first
#: use: the estimator's (:mod:`inertialab.calib.vibration`) and the record reader's.
_CALIB = ("SPREAD_GRID", "BiasTargets", "VibrationModel", "VibrationRun", "bias_targets", "phase_stats", "residual_metrics", "select_spread")
_RECORD = ("load_run", "prepare", "run_from_frame")


def __getattr__(name: str):
    """The floors' names (:data:`_CALIB`, :data:`_RECORD`) on first use."""
    if name in _CALIB:
        from inertialab.calib import vibration

        return getattr(vibration, name)
    if name in _RECORD:
        from inertialab.workflows import vibration_record

        return getattr(vibration_record, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


TERMS = ("Q", "N", "B", "K", "R")
#: Report units of the five terms (docs/vibration.md).
TERM_UNITS = {"Q": "arcsec", "N": "deg/sqrt(h)", "B": "deg/h", "K": "deg/h/sqrt(h)",
              "R": "deg/h^2"}


# ----------------------------------------------------------------------------- noise terms

def _oadev(x: np.ndarray, fs: float):
    from inertialab.noise.statistics.allan import oadev

    # alpha=0 before any model exists (spec §3.2); the WLS fit re-derives the edf
    return oadev(x, rate_hz=fs, taus="octave", alpha=0)


def noise_terms_row(x, fs_hz: float, *, method: str = "wls", tau_min_s: float | None = None
                    ) -> dict:
    """Q N B K R of a rate signal (deg/h) as a JSON-ready table row.

    OADEV on octave taus, identification on ``[max(tau0, tau_min), T/8]``
    (spec 001 §3.4) with ``method`` "wls" (default), "ols" (paper-compatible) or "slope".
    Each term is ``{"value", "unit", "ci", "method", "tau_range_s"}`` in the report unit.
    """
    from inertialab.noise.terms.fit import fit_noise_terms

    x = np.asarray(x, dtype=float)
    dev = _oadev(x, fs_hz)
    T = x.size / fs_hz
    lo = 1.0 / fs_hz if tau_min_s is None else max(1.0 / fs_hz, float(tau_min_s))
    keep = (dev.taus_s >= lo * (1 - 1e-9)) & (dev.taus_s <= T / 8 * (1 + 1e-9))
    if keep.sum() < 3:
        raise InputError(f"signal of {T:g} s has fewer than 3 octave taus in "
                         f"[{lo:g}, {T / 8:g}] s for the noise-term fit")
    nt = fit_noise_terms(dev, unit="dph", kind="gyro", method=method,
                         tau_range_s=(lo * (1 - 1e-9), T / 8 * (1 + 1e-9)))
    return _terms_to_row(nt)


def _terms_to_row(nt) -> dict:
    return {k: getattr(nt, k).to_dict() for k in TERMS}


def _values(row: dict) -> dict:
    return {k: row[k]["value"] for k in TERMS}


def _ratios(row: dict, ref: dict) -> dict:
    out = {}
    for k in TERMS:
        a, b = row[k]["value"], ref[k]["value"]
        out[k] = a / b if (b and np.isfinite(a) and np.isfinite(b) and b != 0) else float("nan")
    return out


@dataclass(frozen=True)
class VibrationResult:
    """Everything the pipeline produced.

    Attributes
    ----------
    level : int
        The level used.
    level_selection : LevelSelection
        The §3.6 rule's table (always computed).
    tables : dict
        ``{"phases", "decomposition", "compensation"}``: row name -> {Q N B K R term}.
    residual_bias_dph : dict or None
        ``{"rbf", "poly"}`` Delta_b of the compensated fixed run (None without one).
    fit : dict
        ``{"rbf": {"neurons", "train_rmse", "heldout_rmse", ...}, "poly": {...}}``.
    metrics : dict
        Residual metrics, ratios, tau ranges, level-rule details (JSON-ready).
    model : VibrationModel
    views : dict
        Arrays for the figures (not JSON).
    settings : dict
    """

    level: int
    level_selection: wv.LevelSelection
    tables: dict
    residual_bias_dph: dict | None
    fit: dict
    metrics: dict
    model: VibrationModel
    views: dict
    settings: dict

    def to_json(self) -> dict:
        """The ``--json`` keys of ``vibration fit`` (docs/vibration.md)."""
        return {
            "level": int(self.level),
            "delta_j": {str(j): float(d) for j, d in self.level_selection.delta.items()},
            "tables": self.tables,
            "residual_bias_dph": self.residual_bias_dph,
            "fit": self.fit,
        }

    def to_report(self) -> dict:
        """All JSON-ready results (``result.json``)."""
        d = self.to_json()
        d["metrics"] = self.metrics
        d["settings"] = self.settings
        return d


def _level_selection(run: VibrationRun, dec, cfg: FitConfig):
    from inertialab.noise.spectral import wavelet as wv

    w = run.guarded(run.p2, cfg.level_guard_s)
    return wv.select_level(dec, window=w, reference=run.p1, threshold=cfg.delta_threshold)


def _true_curve(run: VibrationRun, f_hz: np.ndarray):
    """The simulated bias curve ``b_v(f)`` when the record comes from the virtual lab."""
    if run.meta.get("source") != "virtual_lab" or not run.meta.get("vibration_effects", True):
        return None
    from inertialab.sensors.gyro_vibration import VibrationEffects, bias_shift_dph

    eff = run.meta.get("effects")
    try:
        e = VibrationEffects(**{k: (tuple(v) if isinstance(v, list) else v)
                                for k, v in eff.items()}) if isinstance(eff, dict) else \
            VibrationEffects()
    except TypeError:
        e = VibrationEffects()
    return bias_shift_dph(f_hz, float(run.meta.get("acc_g", 5.0)), e)


def _fit_block(targets: BiasTargets, cfg: FitConfig, level: int, run: VibrationRun):
    from inertialab.calib.vibration import SPREAD_GRID, VibrationModel, select_spread

    f, e = targets.f_hz, targets.e_dph
    odd = targets.bin_index % 2 == 1
    selection = None
    spread = cfg.spread_choice
    if spread == "validate":  # the spread with the least held-out RMSE
        selection = select_spread(f, e, odd, grid=SPREAD_GRID if cfg.spread_grid is None else cfg.spread_grid,
                                  goal=cfg.goal,
                                  centers=cfg.centers, max_neurons=cfg.max_neurons,
                                  rng=cfg.seed)
        spread = selection["chosen"]
    model = VibrationModel(level=level, wavelet_level=cfg.wavelet_level, spread=spread,
                           goal=cfg.goal, centers=cfg.centers, max_neurons=cfg.max_neurons,
                           rng=cfg.seed).fit(targets.f_hz, targets.e_dph)
    held = VibrationModel(level=level, wavelet_level=cfg.wavelet_level, spread=spread,
                          goal=cfg.goal, centers=cfg.centers, max_neurons=cfg.max_neurons,
                          rng=cfg.seed).fit(f[odd], e[odd])
    truth = _true_curve(run, f)
    fit = {}
    for name, est in (("rbf", model.rbf_), ("poly", model.poly_)):
        pred = est.predict(f)
        hpred = (held.rbf_ if name == "rbf" else held.poly_).predict(f[~odd])
        fit[name] = {
            "neurons": int(model.rbf_.n_neurons_) if name == "rbf" else None,
            "train_mse": _metrics.mse(e, pred),
            "train_rmse": _metrics.rmse(e, pred),
            "heldout_rmse": _metrics.rmse(e[~odd], hpred),
            "truth_rmse": None if truth is None else _metrics.rmse(truth, pred),
        }
    fit["poly"]["degree"] = int(model.poly_degree)
    fit["rbf"]["spread"] = float(spread)
    if selection is not None:
        fit["rbf"]["spread_selection"] = selection
    fit["rbf"]["goal"] = float(cfg.goal)
    fit["rbf"]["centers"] = cfg.centers
    fit["n_bins"] = int(f.size)
    fit["f_range_hz"] = [float(f.min()), float(f.max())]
    return model, fit, truth


def _views(run: VibrationRun, cfg: FitConfig) -> dict:
    from inertialab.noise.spectral.emd import emd, hilbert_frequency
    from inertialab.noise.spectral.spectra import alias_frequency, cwt_scalogram, welch_asd

    out = {"welch": {}}
    for name, sl in run.phase_slices().items():
        out["welch"][name] = welch_asd(run.rate_dph[sl], run.fs_hz)
    f_drive = float(np.median(run.freq_hz[run.p2]))
    out["alias_hz"] = alias_frequency(f_drive, run.fs_hz).tolist()
    out["drive_hz"] = f_drive
    # scalogram, optionally on a cropped record around the edges
    if cfg.scalogram_phase_s is None:
        idx = np.arange(run.n)
    else:
        c = int(round(cfg.scalogram_phase_s * run.fs_hz))
        parts = [np.arange(max(0, run.k_on - c), run.k_on),
                 np.arange(run.k_on, min(run.k_off + 1, run.k_on + c)),
                 np.arange(max(run.k_on + c, run.k_off + 1 - c), run.k_off + 1),
                 np.arange(run.k_off + 1, min(run.n, run.k_off + 1 + c))]
        idx = np.unique(np.concatenate(parts))
    sc = cwt_scalogram(run.rate_dph[idx], run.fs_hz)
    out["scalogram"] = sc
    out["scalogram_t0_s"] = float(idx[0] / run.fs_hz)
    out["scalogram_cropped"] = cfg.scalogram_phase_s is not None
    # EMD of a window centred on the vibration onset
    h = int(round(cfg.emd_window_s * run.fs_hz / 2))
    lo, hi = max(0, run.k_on - h), min(run.n, run.k_on + h)
    seg = run.rate_dph[lo:hi]
    r = emd(seg)  # spec §3.5: SD < 0.3 or 10 sifts, at most 10 IMFs
    out["emd"] = {"t_s": np.arange(lo, hi) / run.fs_hz, "x": seg, "imfs": r.imfs,
                  "inst_freq_hz": hilbert_frequency(r.imfs, run.fs_hz) if r.imfs.size else
                  np.zeros((0, seg.size)), "backend": r.backend}
    return out


def _settings(cfg: FitConfig) -> dict:
    """The settings :func:`analyse` reports."""
    return {
        "level": cfg.level_choice, "wavelet": "db4", "wavelet_level": cfg.wavelet_level,
        "spread": cfg.spread_choice, "goal": cfg.goal, "centers": cfg.centers,
        "max_neurons": cfg.max_neurons, "target_guard_s": cfg.target_guard_s,
        "level_guard_s": cfg.level_guard_s, "residual_guard_s": cfg.residual_guard_s,
        "edge_s": cfg.edge_s, "delta_threshold": cfg.delta_threshold,
        "bin_width_hz": cfg.bin_width_hz, "min_bin_count": cfg.min_bin_count,
        "targets": cfg.targets, "seed": cfg.seed,
        "methods": {"phases": "wls", "decomposition": "ols", "compensation": "wls"},
    }


def _compensate_fixed(fixed, a_fix, level: int, model, cfg, tmin_phys: float, tables: dict,
                      metrics: dict, views: dict, tables_step) -> dict:
    """Step 7 of :func:`analyse`: compensate the fixed run (RBF and polynomial), its noise
    tables and residual metrics (filled into ``tables``, ``metrics``, ``views``); returns
    the residual bias of each model, deg/h."""
    from inertialab.calib.vibration import residual_metrics

    comp = {"raw": fixed.rate_dph, f"A{level}": a_fix}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ExtrapolationWarning)
        comp["rbf"] = model.compensate(fixed.rate_dph, fixed.vib_on, fixed.freq_hz,
                                       model="rbf", approx=a_fix)
        comp["poly"] = model.compensate(fixed.rate_dph, fixed.vib_on, fixed.freq_hz,
                                        model="poly", approx=a_fix)
    clipped = any(issubclass(w.category, ExtrapolationWarning) for w in caught)
    if clipped:
        warnings.warn(f"{fixed.path}: drive frequencies outside the sweep's training range "
                      f"{model.f_range_hz_} Hz were clipped to it",
                      ExtrapolationWarning, stacklevel=3)
    metrics["clipped_frequencies"] = bool(clipped)
    tables_step()
    raw_row = None
    for sname, s in comp.items():
        tmin = None if sname == "raw" else tmin_phys
        row = noise_terms_row(s, fixed.fs_hz, method="wls", tau_min_s=tmin)
        tables["compensation"][sname] = row
        if sname == "raw":
            raw_row = row
        metrics["ratios"][f"compensation/{sname}/raw"] = _ratios(row, raw_row)
    # the paper's reading of Table 3: OLS over the full tau range (spec §3.4)
    metrics["compensation_paper"] = {
        sname: noise_terms_row(sig, fixed.fs_hz, method="ols") for sname, sig in comp.items()}
    metrics["ratios"]["compensation/rbf/A"] = _ratios(tables["compensation"]["rbf"],
                                                      tables["compensation"][f"A{level}"])
    metrics["ratios"]["compensation/poly/A"] = _ratios(tables["compensation"]["poly"],
                                                       tables["compensation"][f"A{level}"])
    metrics["residual"] = {name: residual_metrics(comp[name], fixed,
                                                  guard_s=cfg.residual_guard_s,
                                                  edge_s=cfg.edge_s)
                           for name in (f"A{level}", "rbf", "poly")}
    residual = {"rbf": metrics["residual"]["rbf"]["delta_b"],
                "poly": metrics["residual"]["poly"]["delta_b"]}
    views["fixed"] = {"rate": fixed.rate_dph, "approx": a_fix, "rbf": comp["rbf"],
                      "poly": comp["poly"], "fs_hz": fixed.fs_hz, "k_on": fixed.k_on,
                      "k_off": fixed.k_off}
    metrics["compensation_note"] = (
        f"rows raw (wls, tau >= tau0) and A{level}, rbf, poly (wls, tau >= "
        f"{tmin_phys:g} s = 2^(L+1) tau0), whole fixed record")
    return residual


def _checked_runs(sweep: VibrationRun, fixed: VibrationRun | None,
                  cfg: FitConfig) -> dict:
    """Step 0 of :func:`analyse`: the settings and records checked; ``{"sweep", "fixed"}``."""
    cfg.validate()
    runs = {"sweep": sweep}
    if fixed is not None:
        runs["fixed"] = fixed
    for r in runs.values():
        if r.n < 64:
            raise InputError(f"{r.path}: record too short ({r.n} samples)")
    if fixed is not None and abs(fixed.fs_hz - sweep.fs_hz) > 1e-9 * sweep.fs_hz:
        warnings.warn(f"sample rates differ (sweep {sweep.fs_hz:g} Hz, fixed "
                      f"{fixed.fs_hz:g} Hz)", DataQualityWarning, stacklevel=3)
    return runs


def _phase_tables(runs: dict, tables: dict, metrics: dict) -> None:
    """Steps 1-2: the noise terms of each phase of each record (seed Table 1)."""
    for rname, r in runs.items():
        ref = None
        for pname, sl in r.phase_slices().items():
            row = noise_terms_row(r.rate_dph[sl], r.fs_hz, method="wls")
            key = f"{rname}/{pname}"
            tables["phases"][key] = row
            if pname == "P1":
                ref = row
            metrics["ratios"][key + "/P1"] = _ratios(row, ref)


def _decompose(runs: dict, cfg: FitConfig, metrics: dict):
    """Step 4: the db4 decomposition of each record and the level L (the fixed run's
    §3.6 rule, or the sweep's); returns ``(decompositions, rule record, selection, L)``."""
    from inertialab.noise.spectral import wavelet as wv

    decs = {name: wv.decompose(r.rate_dph, level=cfg.wavelet_level) for name, r in runs.items()}
    sel_run = "fixed" if "fixed" in runs else "sweep"
    sel = _level_selection(runs[sel_run], decs[sel_run], cfg)
    level = sel.level if cfg.level_choice == "auto" else int(cfg.level_choice)
    J = min(d.level for d in decs.values())
    if level > J:
        warnings.warn(f"level {level} exceeds the decomposition depth {J}; using {J}",
                      DataQualityWarning, stacklevel=3)
        level = J
    metrics["level_rule"] = {
        "record": sel_run, "chosen_by_rule": int(sel.level), "rule_met": bool(sel.rule_met),
        "threshold": sel.threshold, "delta_j": {str(j): v for j, v in sel.delta.items()},
        "detail_power_P2": {str(j): v for j, v in sel.detail_power_window.items()},
        "detail_power_P1": {str(j): v for j, v in sel.detail_power_reference.items()},
        "wavelet_level": J,
    }
    return decs, sel_run, sel, level


def _decomposition_tables(runs: dict, decs: dict, level: int, tmin_phys: float,
                          tables: dict, metrics: dict) -> None:
    """Step 5: the Table-2 analogue (paper: "ols" over the full range; physical: wls,
    tau >= 2^(L+1) tau0) and the raw records' bias and 10-s stability per phase."""
    from inertialab.calib.vibration import phase_stats

    metrics["decomposition_physical"] = {}
    for rname, r in runs.items():
        a = decs[rname].approximation(level)
        sigs = {"raw": r.rate_dph, f"A{level}": a, f"x-A{level}": r.rate_dph - a}
        raw_row = None
        for sname, s in sigs.items():
            row = noise_terms_row(s, r.fs_hz, method="ols")
            tables["decomposition"][f"{rname}/{sname}"] = row
            if sname == "raw":
                raw_row = row
            metrics["ratios"][f"{rname}/{sname}/raw"] = _ratios(row, raw_row)
        metrics["decomposition_physical"][f"{rname}/A{level}"] = noise_terms_row(
            sigs[f"A{level}"], r.fs_hz, method="wls", tau_min_s=tmin_phys)
    metrics["tau_ranges_s"]["A_L_physical_min"] = tmin_phys
    metrics["raw_phases"] = {rname: phase_stats(r.rate_dph, r) for rname, r in runs.items()}


def _bias_model(sweep: VibrationRun, dec, level: int, cfg: FitConfig, views: dict):
    """Step 6: the sweep's bias targets, the RBF model and the polynomial baseline (their
    curves into ``views``); returns ``(model, fit block)``."""
    from inertialab.calib.vibration import bias_targets

    a_sweep = dec.approximation(level)
    targets = bias_targets(sweep, a_sweep, guard_s=cfg.target_guard_s,
                           bin_width_hz=cfg.bin_width_hz, min_count=cfg.min_bin_count,
                           mode=cfg.targets, level=level)
    model, fit, _ = _fit_block(targets, cfg, level, sweep)
    f_grid = np.linspace(targets.f_hz.min(), targets.f_hz.max(), 1000)
    views.update({"targets": targets, "curve_f_hz": f_grid,
                  "curve_rbf": model.rbf_.predict(f_grid),
                  "curve_poly": model.poly_.predict(f_grid),
                  "curve_truth": _true_curve(sweep, f_grid)})
    views["sweep"] = {"rate": sweep.rate_dph, "approx": a_sweep, "fs_hz": sweep.fs_hz,
                      "k_on": sweep.k_on, "k_off": sweep.k_off, "freq": sweep.freq_hz,
                      "dec": dec}
    return model, fit


def analyse(sweep: VibrationRun, fixed: VibrationRun | None = None,
            config: FitConfig | None = None, progress=None) -> VibrationResult:
    """Run the spec 001 pipeline (§3.11) on a sweep record and an optional fixed one.

    With the sweep alone, the phase tables, decomposition and level rule run on it and
    the compensation rows are omitted (``residual_bias_dph`` is None).
    """
    cfg = config or FitConfig()
    prog = progress or NullProgress()
    total = 8.0
    t_start = time.perf_counter()
    runs = _checked_runs(sweep, fixed, cfg)
    metrics: dict = {"tau_ranges_s": {}, "ratios": {}}
    tables: dict = {"phases": {}, "decomposition": {}, "compensation": {}}
    prog.update(0, total, "phase tables")
    _phase_tables(runs, tables, metrics)
    prog.update(1, total, "spectral views")  # 3: of the fixed run (or the sweep)
    views: dict = _views(fixed if fixed is not None else sweep, cfg) if cfg.views else {}
    prog.update(2, total, "db4 decomposition")
    decs, sel_run, sel, level = _decompose(runs, cfg, metrics)
    prog.update(3, total, "decomposition tables")
    tmin_phys = 2 ** (level + 1) / sweep.fs_hz
    _decomposition_tables(runs, decs, level, tmin_phys, tables, metrics)
    prog.update(4, total, "bias targets and models")
    model, fit = _bias_model(sweep, decs["sweep"], level, cfg, views)
    prog.update(5, total, "compensation")  # 7: of the fixed run
    residual = None
    if fixed is not None:
        residual = _compensate_fixed(fixed, decs["fixed"].approximation(level), level, model,
                                     cfg, tmin_phys, tables, metrics, views,
                                     lambda: prog.update(6, total, "compensation tables"))
    else:
        metrics["compensation_note"] = ("no fixed-frequency record: the compensation rows are "
                                        "omitted")
    views["level"] = level
    views["decomposition"] = {"run": sel_run, "dec": decs[sel_run],
                              "fs_hz": runs[sel_run].fs_hz, "k_on": runs[sel_run].k_on,
                              "k_off": runs[sel_run].k_off}
    prog.update(total, total, "done")
    metrics["wall_s"] = time.perf_counter() - t_start
    return VibrationResult(level=int(level), level_selection=sel, tables=tables,
                           residual_bias_dph=residual, fit=fit, metrics=metrics, model=model,
                           views=views, settings=_settings(cfg))


def fit(sweep: VibrationRun, fixed: VibrationRun | None = None,
        config: FitConfig | None = None, progress=None) -> VibrationResult:
    """The workflow's ``fit`` verb: :func:`analyse` (the model is ``result.model``)."""
    return analyse(sweep, fixed, config, progress)


@dataclass(frozen=True)
class CompensatedRecord:
    """What :func:`apply` returns: the compensated record and its residual metrics.

    ``data`` has ``t_s``, ``rate_dph``, ``rate_comp_dph`` (deg/h), ``vib_on`` and
    ``vib_freq_hz``; ``meta`` is the input sidecar plus the compensation settings;
    ``residual`` is :func:`residual_metrics` of ``rate_comp_dph`` (deg/h).
    """

    data: object
    meta: dict
    residual: dict


def apply(model: VibrationModel, record, *, model_name: str = "rbf",
          apply_to: str = "denoised", model_path: str | None = None) -> CompensatedRecord:
    """Compensate a ``gyro_log`` record with a fitted model (spec 001 §3.10).

    Parameters
    ----------
    model : VibrationModel
    record : inertialab.io.Record or VibrationRun
        The record to compensate (``vib_on``, ``vib_freq_hz``).
    model_name : {"rbf", "poly"}, default "rbf"
    apply_to : {"denoised", "raw"}, default "denoised" (the seed's ``A_L``)
    model_path : str, optional
        Recorded in the output sidecar (``compensated_with``).
    """
    import pandas as pd

    from inertialab.calib.vibration import VibrationRun, residual_metrics
    from inertialab.workflows.vibration_record import prepare

    run = record if isinstance(record, VibrationRun) else prepare(record)
    comp = model.compensate(run.rate_dph, run.vib_on, run.freq_hz, model=model_name,
                            apply_to=apply_to)
    metrics = residual_metrics(comp, run)
    df = pd.DataFrame({"t_s": np.arange(run.n) / run.fs_hz, "rate_dph": run.rate_dph,
                       "rate_comp_dph": comp, "vib_on": run.vib_on.astype(np.int8),
                       "vib_freq_hz": run.freq_hz})
    meta = dict(run.meta)
    meta.update({"compensated_with": None if model_path is None else str(model_path),
                 "compensation_model": model_name, "apply_to": apply_to})
    return CompensatedRecord(data=df, meta=meta, residual=metrics)


#: Units of the numeric keys of the ``vibration`` JSON.
JSON_UNITS = {
    "level": "1", "delta_j": "1", "residual_bias_dph": "deg/h",
    "fit.rbf.train_rmse": "deg/h", "fit.rbf.heldout_rmse": "deg/h",
    "fit.poly.train_rmse": "deg/h", "fit.poly.heldout_rmse": "deg/h",
    "fit.rbf.train_mse": "(deg/h)^2", "fit.poly.train_mse": "(deg/h)^2",
    "fit.rbf.truth_rmse": "deg/h", "fit.poly.truth_rmse": "deg/h",
    "fit.rbf.spread": "Hz", "fit.rbf.goal": "(deg/h)^2", "fit.f_range_hz": "Hz",
}


def _level(level: str):
    v = str(level).strip().lower()
    if v == "auto":
        return "auto"
    try:
        n = int(v)
    except ValueError:
        raise InputError(f"argument 'level' must be an integer 1..9 or 'auto', got "
                         f"'{level}'") from None
    if not 1 <= n <= 9:
        raise InputError(f"argument 'level' must be in 1..9 or 'auto', got {n}")
    return n


def _spread(spread: str):
    v = str(spread).strip().lower()
    if v == "validate":
        return "validate"
    try:
        x = float(v)
    except ValueError:
        raise InputError(f"argument 'spread' must be a positive number (Hz) or 'validate', "
                         f"got '{spread}'") from None
    if not x > 0 or x != x or x == float("inf"):
        raise InputError(f"argument 'spread' must be positive and finite, got {x}")
    return x


#: Fields of :class:`FitConfig` that ``settings`` does not write (how much of the views
#: to compute, the validation grid).
NOT_WRITTEN = ("spread_grid", "views", "scalogram_phase_s", "emd_window_s")


@dataclass(frozen=True)
class FitConfig(_Settings):
    """Settings of ``vibration fit`` and of the pipeline :func:`analyse` (one class: each
    field's name is its JSON key in ``settings`` and its flag with ``-``; spec 001 §3,
    the paper's values as defaults).

    ``level``: the approximation level L, an integer 1..9 (the paper's 6) or ``auto``
    (the §3.6 rule); ``spread``: the RBF spread in Hz (the paper's 1.2) or ``validate``,
    the spread of ``spread_grid`` (default: calib's ``SPREAD_GRID``) with the least
    held-out RMSE on the even bins (the paper "tuned 1.2 after many validations"),
    reported in ``fit["rbf"]["spread_selection"]``; :attr:`level_choice` and
    :attr:`spread_choice` read them (a number or the word). ``goal``: the RBF MSE goal
    (1e-4); ``centers``: RBF centre selection (the paper's wording "random fixed"; spec
    default newrb's ``max_error``); ``targets``: ``bins`` (1-Hz bin means) or ``samples``
    (every 2^L-th sample, spec §3.7 option); ``seed``: the random-fixed centre order.

    Library only: ``wavelet_level`` J (10); ``max_neurons`` (None: as many as the
    targets); guards ``target_guard_s`` (2 s, the E1 targets, §3.7), ``level_guard_s``
    (5 s, the level-rule window, §3.6), ``residual_guard_s`` and ``edge_s`` (10 s, the
    residual bias and the edge window, §4); ``delta_threshold`` (0.14), ``bin_width_hz``
    (1 Hz), ``min_bin_count`` (8); ``views``: compute the spectral views (Welch,
    scalogram, EMD); ``scalogram_phase_s``: crop each phase to at most this many seconds
    around the vibration edges for the scalogram (None: whole record; the CWT of 10^6
    samples costs ~20 s); ``emd_window_s``: the window around ``t_on`` shown with EMD
    (20 s). :data:`NOT_WRITTEN` stay out of ``settings``.
    """

    level: str = setting("6", help="Approximation level L (the paper's 6) or 'auto' (the paper's "
                                   "rule).")
    spread: str = setting("1.2", help="RBF spread in Hz (the paper's 1.2), or 'validate': the spread "
                                      "with the least held-out RMSE on the even 1-Hz bins "
                                      "(reported).")
    goal: float = setting(1e-4, help="RBF MSE goal (the paper's 1e-4).", unit="(deg/h)^2",
                          lo=1e-300, hi=1e12)
    centers: str = setting("max_error", help="RBF centres: max_error | ols | random_fixed | "
                                             "all.")
    targets: str = setting("bins", help="E1 training pairs: bins (1-Hz bin means) | samples "
                                        "(every 2^L-th sample).", choices=("bins", "samples"))
    seed: int = seed_setting("Random seed (same seed, same numbers).")
    wavelet_level: int = setting(10, help="Decomposition depth J.", lo=1, hi=30, cli=False)
    max_neurons: int | None = setting(None, help="RBF neuron cap.", lo=1, hi=100_000, cli=False)
    spread_grid: tuple | None = setting(None, help="Candidate spreads of 'validate'.", unit="Hz",
                                        lo=1e-12, hi=1e12, cli=False)
    target_guard_s: float = setting(2.0, help="Guards of the E1 targets.", unit="s", lo=0.0,
                                    hi=1e6, cli=False)
    level_guard_s: float = setting(5.0, help="Guards of the level-rule window.", unit="s",
                                   lo=0.0, hi=1e6, cli=False)
    residual_guard_s: float = setting(10.0, help="Guards of the residual bias.", unit="s",
                                      lo=0.0, hi=1e6, cli=False)
    edge_s: float = setting(10.0, help="Edge window.", unit="s", lo=0.0, hi=1e6, cli=False)
    delta_threshold: float = setting(0.14, help="Level-rule threshold.", lo=0.0, hi=1e6,
                                     cli=False)
    bin_width_hz: float = setting(1.0, help="Target bin width.", unit="Hz", lo=1e-9, hi=1e6,
                                  cli=False)
    min_bin_count: int = setting(8, help="Fewest samples of a target bin.", lo=1, hi=10**9,
                                 cli=False)
    views: bool = setting(True, help="Compute the spectral views.", cli=False)
    scalogram_phase_s: float | None = setting(None, help="Scalogram crop per phase.", unit="s",
                                              lo=0.0, hi=1e9, cli=False)
    emd_window_s: float = setting(20.0, help="EMD window.", unit="s", lo=0.0, hi=1e9, cli=False)

    @property
    def level_choice(self) -> int | str:
        """``level`` as an integer 1..9 or ``"auto"``."""
        return _level(self.level)

    @property
    def spread_choice(self) -> float | str:
        """``spread`` as a positive number (Hz) or ``"validate"``."""
        return _spread(self.spread)

    def validate(self) -> FitConfig:
        """The declared bounds and choices, ``level`` and ``spread``; one
        :class:`InputError` naming the argument."""
        super().validate()
        _level(self.level)
        _spread(self.spread)
        return self


def VibrationConfig(**settings) -> FitConfig:
    """Deprecated: :class:`FitConfig` under its former spelling (``rng`` for ``seed``),
    for one release."""
    warnings.warn("VibrationConfig is deprecated: use inertialab.workflows.vibration."
                  "FitConfig (seed for rng)", DeprecationWarning, stacklevel=2)
    if "rng" in settings:
        settings["seed"] = settings.pop("rng")
    return FitConfig(**settings)


@dataclass
class FitResult(ResultBase):
    """The analysis (:class:`~inertialab.workflows.vibration.VibrationResult`)."""

    res: object
    sha256: str | None = None
    units = JSON_UNITS

    @property
    def settings(self) -> dict:
        return self.res.settings

    def to_json(self) -> dict:
        return {**self.res.to_json(), "metrics": self.res.metrics}

    def artifacts(self) -> dict:
        from inertialab.calib.vibration import UNITS as MODEL_UNITS

        return {"models": [("model.json", self.res.model, MODEL_UNITS)]}

    def summary_rows(self) -> list:
        res = self.res
        rows = [[tname, rname] + [row[k]["value"] for k in "QNBKR"]
                for tname, table in res.tables.items() for rname, row in table.items()]
        f = res.fit
        out = [(f"FOG vibration analysis, level L = {res.level}",
                ["table", "row", "Q [arcsec]", "N [deg/sqrt(h)]", "B [deg/h]",
                 "K [deg/h/sqrt(h)]", "R [deg/h^2]"], rows),
               f"RBF: {f['rbf']['neurons']} neurons, train RMSE {f['rbf']['train_rmse']:.4g}, "
               f"held-out RMSE {f['rbf']['heldout_rmse']:.4g} deg/h; polynomial: train RMSE "
               f"{f['poly']['train_rmse']:.4g}, held-out {f['poly']['heldout_rmse']:.4g} deg/h"]
        rb = res.residual_bias_dph
        out.append(f"residual bias: RBF {rb['rbf']:.4g} deg/h, polynomial {rb['poly']:.4g} deg/h"
                   if rb is not None else res.metrics["compensation_note"])
        return out


def run_fit(sweep_record, fixed_record, config: FitConfig, *, views: bool = True,
            progress=None) -> FitResult:
    """Phase-wise Allan terms, db4 separation and the RBF bias model on the sweep; the
    fixed run compensated when given (``views``: also the multiscale figures' data)."""
    from inertialab.workflows.vibration_record import prepare

    c = replace(config, views=views).validate()
    sweep = prepare(sweep_record)
    fixed = prepare(fixed_record) if fixed_record is not None else None
    return FitResult(fit(sweep, fixed, c, progress), sha256=sweep_record.sha256)


@dataclass(frozen=True)
class ApplyConfig(_Settings):
    """Settings of ``vibration apply``."""

    model: str = setting("rbf", help="rbf | poly")
    apply_to: str = setting("denoised", help="denoised (A_L, seed) | raw")


@dataclass
class ApplyResult(ResultBase):
    """``vibration apply``: the compensated record
    (:class:`~inertialab.workflows.vibration.CompensatedRecord`) to write at ``out``."""

    res: object
    out: object
    settings: dict
    units = {"residual": "deg/h"}

    def to_json(self) -> dict:
        return {"output": str(self.out), "residual": self.res.residual}

    def artifacts(self) -> dict:
        return {"records": [(self.out, self.res.data, self.res.meta)]}

    def summary_rows(self) -> list:
        return [f"wrote {self.out}: residual bias {self.res.residual['delta_b']:.4g} deg/h"]


def run_apply(model, record, config: ApplyConfig, *, out, model_path=None) -> ApplyResult:
    """Apply a saved vibration-compensation model to a new record (spec 001 §3.10); the
    record to write at ``out`` has rate_comp_dph (deg/h)."""
    c = config.validate()
    res = apply(model, record, model_name=c.model, apply_to=c.apply_to,
                   model_path=None if model_path is None else str(model_path))
    return ApplyResult(res=res, out=out, settings=c.to_dict())
