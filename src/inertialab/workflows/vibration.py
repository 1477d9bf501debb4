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

The model itself (estimator on arrays, model file) is :mod:`inertialab.calib.vibration`;
the virtual-lab demo is :mod:`inertialab.studies.vibration`. This module neither reads
arguments nor draws (figures are in :mod:`inertialab.report.figures.vibration`).
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np

from inertialab import metrics as _metrics
from inertialab import units
from inertialab.calib.vibration import (
    SPREAD_GRID,
    BiasTargets,
    VibrationModel,
    VibrationRun,
    bias_targets,
    phase_stats,
    residual_metrics,
    select_spread,
)
from inertialab.errors import DataQualityWarning, ExtrapolationWarning, InputError
from inertialab.noise import wavelet as wv
from inertialab.progress import NullProgress

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
]

TERMS = ("Q", "N", "B", "K", "R")
#: Report units of the five terms (docs/vibration.md).
TERM_UNITS = {"Q": "arcsec", "N": "deg/sqrt(h)", "B": "deg/h", "K": "deg/h/sqrt(h)",
              "R": "deg/h^2"}


def _bad_rows(mask: np.ndarray) -> list[int]:
    return (np.flatnonzero(mask)[:5] + 1).tolist()


def run_from_frame(df, meta: dict | None = None, *, path="<frame>", sha256: str = "",
                   units_map: dict | None = None, timebase=None) -> VibrationRun:
    """Validate a record frame for the vibration pipeline (spec 001 §2.2 loader checks).

    Checks: a rate column (``rate_*``, converted to deg/h) or angle increments
    (``dtheta_*``, rate = dtheta/tau0); the time base (``timebase``, the record's; for a
    bare frame decided from ``t_s`` and the sidecar ``fs_hz`` by
    :func:`inertialab.io.timestamps.decide_timebase`) without lost samples; no NaN; ``vib_on`` present with one contiguous block of 1s after
    a static phase; ``vib_freq_hz > 0`` exactly where ``vib_on = 1``; ``phase`` (if
    given) 1 -> 2 -> 3 and consistent with ``vib_on``.

    Raises
    ------
    InputError
        Naming the file, column and rows.
    """
    meta = dict(meta or {})
    path = str(path)
    cols = {c.lower(): c for c in df.columns}
    rate_col = next((c for c in cols if c.startswith("rate_") and units.split_suffix(c)[1]),
                    None)
    dth_col = next((c for c in cols if c.startswith("dtheta_") and units.split_suffix(c)[1]),
                   None)
    if rate_col is None and dth_col is None:
        raise InputError("needs a rate column (e.g. rate_dph) or angle increments "
                         "(dtheta_arcsec)", path=path)
    # time base: the record's (decided once in io), or decided here for a bare frame
    if timebase is None:
        from inertialab.io.timestamps import decide_timebase

        t = np.asarray(df[cols["t_s"]], dtype=float) if "t_s" in cols else None
        timebase = decide_timebase(t, n=len(df), nominal_hz=meta.get("fs_hz"), path=path)
    if timebase is None:
        raise InputError("needs a t_s column or the sidecar key fs_hz", path=path)
    if timebase.n_missing or timebase.back_rows:
        raise InputError(f"{timebase.n_missing} sample(s) lost in gaps or stamps that go back: "
                         "the vibration analysis needs a contiguous log", path=path,
                         column="t_s")
    fs, tau0 = timebase.rate_hz, timebase.tau0_s
    if rate_col is not None:
        suf = (units_map or {}).get(cols[rate_col]) or units.split_suffix(rate_col)[1]
        x = units.convert(np.asarray(df[cols[rate_col]], dtype=float), suf, "dph")
        xname = cols[rate_col]
    else:
        suf = (units_map or {}).get(cols[dth_col]) or units.split_suffix(dth_col)[1]
        x = units.convert(np.asarray(df[cols[dth_col]], dtype=float), suf, "arcsec") / tau0
        xname = cols[dth_col]
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise InputError("NaN or infinite rate values", path=path, column=xname,
                         row=_bad_rows(~np.isfinite(x)))
    if "vib_on" not in cols:
        raise InputError("record has no vibration phases: column vib_on is missing "
                         "(1 while the shaker drives, else 0)", path=path, column="vib_on")
    on_raw = np.asarray(df[cols["vib_on"]], dtype=float)
    if not np.all(np.isin(on_raw, (0.0, 1.0))):
        raise InputError("vib_on must be 0 or 1", path=path, column="vib_on",
                         row=_bad_rows(~np.isin(on_raw, (0.0, 1.0))))
    on = on_raw == 1.0
    if not on.any():
        raise InputError("record has no vibration phase (vib_on is never 1)", path=path,
                         column="vib_on")
    idx = np.flatnonzero(on)
    k_on, k_off = int(idx[0]), int(idx[-1])
    if idx.size != k_off - k_on + 1:
        gaps = np.flatnonzero(~on[k_on:k_off + 1]) + k_on
        raise InputError("vibration must be one contiguous block (P1 static, P2 vibration, "
                         "P3 static); vib_on drops to 0 inside it", path=path, column="vib_on",
                         row=(gaps[:5] + 1).tolist())
    if k_on == 0:
        raise InputError("no static phase before vibration (P1 is empty): the reference bias "
                         "needs one", path=path, column="vib_on")
    if "vib_freq_hz" not in cols:
        raise InputError("column vib_freq_hz (drive frequency, Hz) is missing", path=path,
                         column="vib_freq_hz")
    f = np.asarray(df[cols["vib_freq_hz"]], dtype=float)
    badf = on & ~(np.isfinite(f) & (f > 0))
    if badf.any():
        raise InputError("drive frequency missing or <= 0 while vibrating", path=path,
                         column="vib_freq_hz", row=_bad_rows(badf))
    bad_off = ~on & ~(f == 0)
    if bad_off.any():
        raise InputError("drive frequency must be 0 while vib_on = 0", path=path,
                         column="vib_freq_hz", row=_bad_rows(bad_off))
    if "phase" in cols:
        ph = np.asarray(df[cols["phase"]], dtype=float)
        expect = np.where(np.arange(x.size) < k_on, 1, np.where(on, 2, 3))
        badp = ph != expect
        if badp.any():
            raise InputError("phase must run 1 -> 2 -> 3 and equal 2 exactly where vib_on = 1",
                             path=path, column="phase", row=_bad_rows(badp))
    if k_off + 1 >= x.size:
        warnings.warn(f"{path}: record ends while vibrating (no P3); P3 rows are omitted",
                      DataQualityWarning, stacklevel=2)
    return VibrationRun(rate_dph=x, vib_on=on, freq_hz=np.where(on, f, 0.0), fs_hz=float(fs),
                        k_on=k_on, k_off=k_off, path=path, sha256=sha256,
                        experiment=meta.get("experiment"), meta=meta)


def prepare(record) -> VibrationRun:
    """A ``gyro_log`` :class:`~inertialab.io.Record` validated and segmented for the
    pipeline (:func:`run_from_frame`)."""
    from inertialab.io.preflight import preflight

    preflight(record, "vibration")  # the checks `validate --kind vibration` runs
    return run_from_frame(record.data, record.meta, path=record.path, sha256=record.sha256,
                          timebase=record.timebase,
                          units_map=record.units)


def load_run(path, *, options=None) -> VibrationRun:
    """Read a ``gyro_log`` record (``options``: :class:`~inertialab.io.mapping.ReadOptions`)
    and :func:`prepare` it."""
    from inertialab.io import read_record

    return prepare(read_record(path, "gyro_log", options=options))


# ----------------------------------------------------------------------------- noise terms

def _oadev(x: np.ndarray, fs: float):
    from inertialab.noise.allan import oadev

    # alpha=0 before any model exists (spec §3.2); the WLS fit re-derives the edf
    return oadev(x, rate_hz=fs, taus="octave", alpha=0)


def noise_terms_row(x, fs_hz: float, *, method: str = "wls", tau_min_s: float | None = None
                    ) -> dict:
    """Q N B K R of a rate signal (deg/h) as a JSON-ready table row.

    OADEV on octave taus, identification on ``[max(tau0, tau_min), T/8]``
    (spec 001 §3.4) with ``method`` "wls" (default), "ols" (paper-compatible) or "slope".
    Each term is ``{"value", "unit", "ci", "method", "tau_range_s"}`` in the report unit.
    """
    from inertialab.noise.terms import fit_noise_terms

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
class VibrationConfig:
    """Settings of the pipeline (spec 001 §3; seed values as defaults).

    Attributes
    ----------
    level : int or "auto", default=6
        Approximation level L (seed: 6) or the §3.6 rule.
    wavelet_level : int, default=10
        J (seed: 10).
    spread, goal : float, default 1.2 and 1e-4
        RBF settings of the seed; ``spread="validate"`` picks it from ``spread_grid`` by
        the held-out RMSE on the even bins (the seed "tuned 1.2 after many
        validations"), reported in ``fit["rbf"]["spread_selection"]``.
    centers : str, default="max_error"
        RBF centre selection (seed wording "random fixed"; spec default newrb's).
    max_neurons : int or None
    spread_grid : tuple of float, default SPREAD_GRID
        Candidate spreads (Hz) for ``spread="validate"``.
    target_guard_s : float, default=2.0
        Guards of the E1 targets (§3.7).
    level_guard_s : float, default=5.0
        Guards of the level-rule window (§3.6).
    residual_guard_s, edge_s : float, default 10.0
        Guards of the residual bias and the edge window (§4).
    delta_threshold : float, default=0.14
    bin_width_hz : float, default=1.0
    min_bin_count : int, default=8
    targets : {"bins", "samples"}, default="bins"
        1-Hz bin means, or every 2^L-th sample (spec §3.7 option).
    rng : int, default=0
        Seed of the random-fixed centre order.
    views : bool, default=True
        Compute the spectral views (Welch, scalogram, EMD).
    scalogram_phase_s : float or None, default=None
        Crop each phase to at most this many seconds around the vibration edges for
        the scalogram (None: whole record; the CWT of 10^6 samples costs ~20 s).
    emd_window_s : float, default=20.0
        Length of the window around ``t_on`` shown with EMD.
    """

    level: int | str = 6
    wavelet_level: int = 10
    spread: float | str = 1.2
    goal: float = 1e-4
    centers: str = "max_error"
    max_neurons: int | None = None
    spread_grid: tuple = SPREAD_GRID
    target_guard_s: float = 2.0
    level_guard_s: float = 5.0
    residual_guard_s: float = 10.0
    edge_s: float = 10.0
    delta_threshold: float = 0.14
    bin_width_hz: float = 1.0
    min_bin_count: int = 8
    targets: str = "bins"
    rng: int = 0
    views: bool = True
    scalogram_phase_s: float | None = None
    emd_window_s: float = 20.0


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


def _level_selection(run: VibrationRun, dec, cfg: VibrationConfig):
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


def _fit_block(targets: BiasTargets, cfg: VibrationConfig, level: int, run: VibrationRun):
    f, e = targets.f_hz, targets.e_dph
    odd = targets.bin_index % 2 == 1
    selection = None
    spread = cfg.spread
    if spread == "validate":  # the spread with the least held-out RMSE
        selection = select_spread(f, e, odd, grid=cfg.spread_grid, goal=cfg.goal,
                                  centers=cfg.centers, max_neurons=cfg.max_neurons,
                                  rng=cfg.rng)
        spread = selection["chosen"]
    model = VibrationModel(level=level, wavelet_level=cfg.wavelet_level, spread=spread,
                           goal=cfg.goal, centers=cfg.centers, max_neurons=cfg.max_neurons,
                           rng=cfg.rng).fit(targets.f_hz, targets.e_dph)
    held = VibrationModel(level=level, wavelet_level=cfg.wavelet_level, spread=spread,
                          goal=cfg.goal, centers=cfg.centers, max_neurons=cfg.max_neurons,
                          rng=cfg.rng).fit(f[odd], e[odd])
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


def _views(run: VibrationRun, cfg: VibrationConfig) -> dict:
    from inertialab.noise.emd import emd, hilbert_frequency
    from inertialab.noise.spectra import alias_frequency, cwt_scalogram, welch_asd

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


def _settings(cfg: VibrationConfig) -> dict:
    """The settings :func:`analyse` reports."""
    return {
        "level": cfg.level, "wavelet": "db4", "wavelet_level": cfg.wavelet_level,
        "spread": cfg.spread, "goal": cfg.goal, "centers": cfg.centers,
        "max_neurons": cfg.max_neurons, "target_guard_s": cfg.target_guard_s,
        "level_guard_s": cfg.level_guard_s, "residual_guard_s": cfg.residual_guard_s,
        "edge_s": cfg.edge_s, "delta_threshold": cfg.delta_threshold,
        "bin_width_hz": cfg.bin_width_hz, "min_bin_count": cfg.min_bin_count,
        "targets": cfg.targets, "seed": cfg.rng,
        "methods": {"phases": "wls", "decomposition": "ols", "compensation": "wls"},
    }


def _compensate_fixed(fixed, a_fix, level: int, model, cfg, tmin_phys: float, tables: dict,
                      metrics: dict, views: dict, tables_step) -> dict:
    """Step 7 of :func:`analyse`: compensate the fixed run (RBF and polynomial), its noise
    tables and residual metrics (filled into ``tables``, ``metrics``, ``views``); returns
    the residual bias of each model, deg/h."""
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
                      f"{model.f_range_hz_} Hz were clipped to it (spec §3.10)",
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


def analyse(sweep: VibrationRun, fixed: VibrationRun | None = None,
            config: VibrationConfig | None = None, progress=None) -> VibrationResult:
    """Run the spec 001 pipeline (§3.11) on a sweep record and an optional fixed one.

    With the sweep alone, the phase tables, decomposition and level rule run on it and
    the compensation rows are omitted (``residual_bias_dph`` is None).
    """
    cfg = config or VibrationConfig()
    prog = progress or NullProgress()
    total = 8.0
    t_start = time.perf_counter()
    if not (cfg.spread == "validate" or (isinstance(cfg.spread, (int, float, np.number))
                                         and np.isfinite(cfg.spread) and cfg.spread > 0)):
        raise InputError(f"spread must be a positive number (Hz) or 'validate', "
                         f"got {cfg.spread!r}")
    if cfg.level != "auto" and not (isinstance(cfg.level, (int, np.integer))
                                    and 1 <= int(cfg.level) <= 9):
        raise InputError(f"level must be an integer in 1..9 or 'auto', got {cfg.level!r}")
    runs = {"sweep": sweep}
    if fixed is not None:
        runs["fixed"] = fixed
    for r in runs.values():
        if r.n < 64:
            raise InputError(f"{r.path}: record too short ({r.n} samples)")
    if fixed is not None and abs(fixed.fs_hz - sweep.fs_hz) > 1e-9 * sweep.fs_hz:
        warnings.warn(f"sample rates differ (sweep {sweep.fs_hz:g} Hz, fixed "
                      f"{fixed.fs_hz:g} Hz)", DataQualityWarning, stacklevel=2)
    metrics: dict = {"tau_ranges_s": {}, "ratios": {}}
    tables: dict = {"phases": {}, "decomposition": {}, "compensation": {}}

    # 1-2: per-phase Allan tables
    prog.update(0, total, "phase tables")
    for rname, r in runs.items():
        ref = None
        for pname, sl in r.phase_slices().items():
            row = noise_terms_row(r.rate_dph[sl], r.fs_hz, method="wls")
            key = f"{rname}/{pname}"
            tables["phases"][key] = row
            if pname == "P1":
                ref = row
            metrics["ratios"][key + "/P1"] = _ratios(row, ref)

    # 3: spectral views of the fixed run (or the sweep)
    prog.update(1, total, "spectral views")
    views: dict = {}
    view_run = fixed if fixed is not None else sweep
    if cfg.views:
        views.update(_views(view_run, cfg))

    # 4: decomposition and level
    prog.update(2, total, "db4 decomposition")
    decs = {name: wv.decompose(r.rate_dph, level=cfg.wavelet_level) for name, r in runs.items()}
    sel_run = "fixed" if fixed is not None else "sweep"
    sel = _level_selection(runs[sel_run], decs[sel_run], cfg)
    level = sel.level if cfg.level == "auto" else int(cfg.level)
    J = min(d.level for d in decs.values())
    if level > J:
        warnings.warn(f"level {level} exceeds the decomposition depth {J}; using {J}",
                      DataQualityWarning, stacklevel=2)
        level = J
    metrics["level_rule"] = {
        "record": sel_run, "chosen_by_rule": int(sel.level), "rule_met": bool(sel.rule_met),
        "threshold": sel.threshold, "delta_j": {str(j): v for j, v in sel.delta.items()},
        "detail_power_P2": {str(j): v for j, v in sel.detail_power_window.items()},
        "detail_power_P1": {str(j): v for j, v in sel.detail_power_reference.items()},
        "wavelet_level": J,
    }

    # 5: Table-2 analogue (paper: "ols" over the full range; physical: wls, tau >= 2^(L+1))
    prog.update(3, total, "decomposition tables")
    tmin_phys = 2 ** (level + 1) / sweep.fs_hz
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
    # bias and 10-s stability per phase of the raw records
    metrics["raw_phases"] = {rname: phase_stats(r.rate_dph, r) for rname, r in runs.items()}

    # 6: targets and models
    prog.update(4, total, "bias targets and models")
    a_sweep = decs["sweep"].approximation(level)
    targets = bias_targets(sweep, a_sweep, guard_s=cfg.target_guard_s,
                           bin_width_hz=cfg.bin_width_hz, min_count=cfg.min_bin_count,
                           mode=cfg.targets, level=level)
    model, fit, truth = _fit_block(targets, cfg, level, sweep)
    f_grid = np.linspace(targets.f_hz.min(), targets.f_hz.max(), 1000)
    views["targets"] = targets
    views["curve_f_hz"] = f_grid
    views["curve_rbf"] = model.rbf_.predict(f_grid)
    views["curve_poly"] = model.poly_.predict(f_grid)
    views["curve_truth"] = _true_curve(sweep, f_grid)
    views["sweep"] = {"rate": sweep.rate_dph, "approx": a_sweep, "fs_hz": sweep.fs_hz,
                      "k_on": sweep.k_on, "k_off": sweep.k_off, "freq": sweep.freq_hz,
                      "dec": decs["sweep"]}

    # 7: compensation of the fixed run
    prog.update(5, total, "compensation")
    residual = None
    if fixed is not None:
        residual = _compensate_fixed(fixed, decs["fixed"].approximation(level), level, model,
                                     cfg, tmin_phys, tables, metrics, views,
                                     lambda: prog.update(6, total, "compensation tables"))
    else:
        metrics["compensation_note"] = ("no fixed-frequency record: the compensation rows are "
                                        "omitted (spec §3.11)")
    views["level"] = level
    views["decomposition"] = {"run": sel_run, "dec": decs[sel_run],
                              "fs_hz": runs[sel_run].fs_hz, "k_on": runs[sel_run].k_on,
                              "k_off": runs[sel_run].k_off}
    prog.update(total, total, "done")
    settings = _settings(cfg)
    metrics["wall_s"] = time.perf_counter() - t_start
    return VibrationResult(level=int(level), level_selection=sel, tables=tables,
                           residual_bias_dph=residual, fit=fit, metrics=metrics, model=model,
                           views=views, settings=settings)



def fit(sweep: VibrationRun, fixed: VibrationRun | None = None,
        config: VibrationConfig | None = None, progress=None) -> VibrationResult:
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
