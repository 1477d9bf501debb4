"""Study 000 workflow: thermal-tumble records in, a thermal-compensation model out, and
compensated records (spec 000 §2.3, §3, §3.7).

The verbs of every workflow:

- :func:`prepare` (``record -> ThermalSamples``): validation of a ``thermal_tumble``
  record (24 positions per set point, temperatures within ±2 °C, one set point at the
  reference temperature, taken from the sidecar's ``reference_temp_C`` when given), the
  averages per (ramp, set point, position), the 55 °C reference fit and the samples
  ``x = (T, N)``, ``y = Nc``; :func:`prepare_samples` does the same on a bare frame.
- :func:`fit` (``samples, config -> ThermalFit``): the requested models on the
  configured split, scored on the test set (:func:`fit_thermal`).
- :func:`apply` (``model, record -> ThermalApplied``): the compensated record with
  ``comp_output_mv``, ``comp_a_g`` and ``status``, and the reference-temperature
  policy (whose 55 °C coefficients form Ua: the model unit's or the record's own, §3.7).

The commands ``thermal fit|apply|export``, one call each: a
:class:`~inertialab.config.Config` of settings per command (:class:`FitConfig`,
:class:`ApplyConfig`, :class:`ExportConfig`) and ``run_*(record, config) -> result``
whose result (:class:`inertialab.result.Result`) knows ``to_json()``, ``settings``,
``units``, ``artifacts()`` (the saved model, one model per method, Tables 1 and 2, the
bias/scale-factor table) and ``summary_rows()``. ``FitConfig`` is the one settings class of the
command, of :func:`prepare`, :func:`make_splits`, :func:`fit` and of the estimator
(:func:`~inertialab.calib.thermal.fit_model` reads it): each setting has one name, its
flag and its JSON key in ``settings`` (``visual``, ``step``, ``try_number``, ``crowd`` ...);
``ThermalConfig`` is its deprecated former spelling (``fish_visual`` ...).

The estimators, the model artefact and compensation live in
:mod:`inertialab.calib.thermal`, imported (with pandas) inside the functions that use
them so that ``thermal fit --help`` starts light; their names re-exported here
(``METHODS``, ``compensate`` ...) load on first use. This module never
reads files, draws or imports the virtual lab.
"""

from __future__ import annotations

import time
import zlib
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from inertialab.blas import single_threaded_blas
from inertialab.config import Config as _Settings
from inertialab.config import seed_setting, setting
from inertialab.errors import InputError, MissingReferenceError
from inertialab.export.thermal_c import export_c
from inertialab.progress import NullProgress
from inertialab.result import ResultBase
from inertialab.seeding import as_generator
from inertialab.sensors.pendulous import (
    bias_scale_factor_drift,
    fit_single_axis,
    higher_order_terms,
    integrated_output,
    reference_target,
)
from inertialab.units import THERMAL_UNITS

if TYPE_CHECKING:
    import pandas as pd

    from inertialab.calib.thermal import (
        FUZZY,
        METHODS,
        PROPOSED,
        Compensation,
        DriftResult,
        Split,
        ThermalModel,
        ThermalSamples,
        compensate,
        drift,
    )

#: Names of :mod:`inertialab.calib.thermal` re-exported for callers of the workflow,
#: loaded on first use.
_CALIB = ("FUZZY", "METHODS", "PROPOSED", "STATUS_N_CLAMPED", "STATUS_OK", "STATUS_T_CLAMPED", "Compensation", "DriftResult", "ModelMetrics", "Split", "ThermalModel", "ThermalSamples", "compensate", "drift", "fit_model", "raw_drift_rms_ug", "recalibrate", "score")


def __getattr__(name: str):
    """The estimator floor's names (:data:`_CALIB`) on first use."""
    if name in _CALIB:
        from inertialab.calib import thermal

        return getattr(thermal, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# ---------------------------------------------------------------------------------------
# prepare: record -> samples
# ---------------------------------------------------------------------------------------
def _positions_ok(frame: pd.DataFrame, n_positions: int, path) -> None:
    for (rd, sp), g in frame.groupby(["ramp_dir", "temp_set_c"], sort=True):
        k = g.pos_index.nunique()
        if k < n_positions:
            raise InputError(
                f"set point {sp:g} °C ({rd}) has {k} distinct positions, need {n_positions}",
                path=path, column="pos_index")


def prepare_samples(frame: pd.DataFrame, config: FitConfig | None = None, *,
                    path="<frame>", n_positions: int = 24) -> ThermalSamples:
    """Validate a thermal-tumble frame and build the (T, N) -> Nc samples (spec 000 §2.3,
    §3.1).

    Raises
    ------
    MissingReferenceError
        No (or more than one) set point at the reference temperature.
    InputError
        Fewer than ``n_positions`` positions at a set point; a measured temperature more
        than ``temp_tolerance_c`` from its set point (the row is named).
    """
    from inertialab.calib.thermal import ThermalSamples

    cfg = (config or FitConfig()).validate()
    f = frame.copy()
    for col in ("temp_set_c", "temp_meas_c", "pos_index", "output_mv"):
        if col not in f.columns:
            raise InputError("missing required column", path=path, column=col)
    if "ramp_dir" not in f.columns:
        f["ramp_dir"] = "up"
    if "a_in_g" not in f.columns or "a_pend_g" not in f.columns:
        ang = np.deg2rad(15.0 * f["pos_index"].to_numpy() * 24.0 / n_positions)
        f["a_in_g"] = np.round(np.sin(ang), 15)
        f["a_pend_g"] = np.round(np.cos(ang), 15)
    off = np.abs(f.temp_meas_c.to_numpy() - f.temp_set_c.to_numpy())
    if np.any(off > cfg.temp_tolerance_c):
        rows = (np.flatnonzero(off > cfg.temp_tolerance_c) + 1)[:5].tolist()
        raise InputError(
            f"measured temperature more than {cfg.temp_tolerance_c:g} °C from its set point "
            f"(worst {off.max():.2f} °C)", path=path, column="temp_meas_c",
            row=rows[0] if len(rows) == 1 else rows)
    sps = np.unique(f.temp_set_c.to_numpy())
    is_ref = np.isclose(sps, cfg.reference_temp_c, atol=1e-6)
    if is_ref.sum() != 1:
        raise MissingReferenceError(
            f"no set point at the reference temperature {cfg.reference_temp_c:g} °C "
            f"(set points: {', '.join(f'{s:g}' for s in sps)})", path=path, column="temp_set_c")
    _positions_ok(f, n_positions, path)
    has_true = "true_a_in_g" in f.columns
    agg = {"temp_meas_c": "mean", "output_mv": "mean", "a_in_g": "first", "a_pend_g": "first"}
    if has_true:
        agg["true_a_in_g"] = "mean"
    g = (f.groupby(["ramp_dir", "temp_set_c", "pos_index"], sort=True).agg(agg).reset_index())
    # up pass first (the reference fit uses the first pass at 55 °C)
    g["_o"] = (g.ramp_dir != "up").astype(int)
    g = g.sort_values(["_o", "temp_set_c", "pos_index"], kind="stable").reset_index(drop=True)
    a_i = g.a_in_g.to_numpy(float)
    a_p = g.a_pend_g.to_numpy(float)
    U = g.output_mv.to_numpy(float)
    sp = g.temp_set_c.to_numpy(float)
    rd = g.ramp_dir.to_numpy(str)
    ref_rows = np.isclose(sp, cfg.reference_temp_c, atol=1e-6) & (rd == rd[0])
    # values near the float range overflow below; _plausible turns that into one error
    with np.errstate(all="ignore"):
        try:
            fit = fit_single_axis(a_i[ref_rows], a_p[ref_rows], U[ref_rows],
                                  include_kp=cfg.include_kp)
        except np.linalg.LinAlgError:
            raise InputError("the reference-temperature tumble cannot be fitted (values out "
                             "of range?)", path=path, column="output_mv") from None
        ref = fit.coefficients
        ua = integrated_output(U, a_i, a_p, ref)
        if cfg.target == "linear55":
            y = reference_target(a_i, ref)
        else:  # measured55: the 55 °C Ua at the same position (same pass)
            lut = {int(p): v for p, v in zip(g.pos_index.to_numpy()[ref_rows], ua[ref_rows])}
            y = np.array([lut[int(p)] for p in g.pos_index.to_numpy()])
        if cfg.input == "raw":
            n = U
            y = y + higher_order_terms(a_i, a_p, ref)
        else:
            n = ua
    _plausible(f, g, ref, fit.residual_rms, np.asarray(n, float), np.asarray(y, float), path)
    unit_id = str(f["unit_id"].iloc[0]) if "unit_id" in f.columns else ""
    return ThermalSamples(
        temp_c=g.temp_meas_c.to_numpy(float), set_point_c=sp,
        pos_index=g.pos_index.to_numpy(int), ramp_dir=rd, a_in_g=a_i, a_pend_g=a_p,
        output_mv=U, n_mv=np.asarray(n, float), y_mv=np.asarray(y, float),
        true_a_in_g=g.true_a_in_g.to_numpy(float) if has_true else np.full(len(g), np.nan),
        ref=ref, ref_stderr=fit.stderr, ref_residual_mv=fit.residual_rms, input=cfg.input,
        target=cfg.target, unit_id=unit_id, reference_temp_c=float(cfg.reference_temp_c))




#: Plausibility limits of a thermal tumble [ours]: a 55 °C tumble that
#: leaves more than 10 mg rms around eq. 1 (a healthy one leaves µg), or a sample whose
#: output differs from the 55 °C model by more than 1 g (the seed's drift is 5 mg), is
#: not a temperature drift but a broken cell; refusing it keeps NaN and nonsense out of
#: the models.
MAX_REFERENCE_RESIDUAL_G = 0.01
MAX_DRIFT_G = 1.0


def _rows_of(frame: pd.DataFrame, ramp: str, set_point: float, pos: int) -> list[int]:
    m = ((frame["ramp_dir"].to_numpy(str) == ramp) & (frame["temp_set_c"].to_numpy() == set_point)
         & (frame["pos_index"].to_numpy() == pos))
    return (np.flatnonzero(m) + 1)[:5].tolist()


def _plausible(frame, g, ref, residual_mv, n, y, path) -> None:
    """Refuse a record whose numbers cannot be a thermal tumble (values near the float
    range, a 55 °C tumble that does not fit eq. 1, a 1 g "drift")."""
    coef = np.array([ref.k0, ref.k1, ref.k2, ref.kip, ref.kp, residual_mv])
    if not np.all(np.isfinite(coef)) or ref.k1 == 0.0:
        raise InputError("the reference-temperature tumble gives no finite, non-zero scale "
                         "factor (values out of range?)", path=path, column="output_mv")
    if residual_mv / abs(ref.k1) > MAX_REFERENCE_RESIDUAL_G:
        raise InputError(f"the reference-temperature tumble leaves "
                         f"{residual_mv / abs(ref.k1) * 1e3:.4g} mg rms around eq. 1 (limit "
                         f"{MAX_REFERENCE_RESIDUAL_G * 1e3:g} mg): a broken output cell?",
                         path=path, column="output_mv")
    with np.errstate(over="ignore", invalid="ignore"):
        d = np.abs(n - y) / abs(ref.k1)
    bad = ~np.isfinite(d) | (d > MAX_DRIFT_G)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        rows = _rows_of(frame, g.ramp_dir.iloc[i], g.temp_set_c.iloc[i], g.pos_index.iloc[i])
        raise InputError(f"output at set point {g.temp_set_c.iloc[i]:g} °C, position "
                         f"{int(g.pos_index.iloc[i])} differs from the reference-temperature "
                         f"model by more than {MAX_DRIFT_G:g} g: not a temperature drift",
                         path=path, column="output_mv", row=rows[0] if len(rows) == 1 else rows)


def reference_temperature(meta: dict, path=None, default: float = 55.0) -> float:
    """The sidecar's reference temperature (``reference_temp_C``, any case), else 55 °C
    (spec 000 §2.3)."""
    for k, v in (meta or {}).items():
        if str(k).lower() == "reference_temp_c":
            try:
                return float(v)
            except (TypeError, ValueError):
                raise InputError(f"sidecar key {k} is not a number: {v!r}", path=path) from None
    return default


def prepare(record, config: FitConfig | None = None) -> ThermalSamples:
    """Samples of a ``thermal_tumble`` record (:class:`inertialab.io.Record`): the
    reference temperature comes from the record's sidecar (``reference_temp_C``) when
    it has one, else from ``config`` (55 °C)."""
    cfg = config or FitConfig()
    ref_t = reference_temperature(record.meta, record.path, default=cfg.reference_temp_c)
    return prepare_samples(record.data, replace(cfg, reference_temp_c=ref_t), path=record.path)


# ---------------------------------------------------------------------------------------
# fit: samples -> models and metrics
# ---------------------------------------------------------------------------------------
def strata_of(s: ThermalSamples) -> np.ndarray:
    """Stratum index of every sample: one stratum per (ramp pass, set point)."""
    keys = [f"{r}|{t:g}" for r, t in zip(s.ramp_dir, s.set_point_c)]
    _, inv = np.unique(keys, return_inverse=True)
    return inv


def validation_subset(train: np.ndarray, strata: np.ndarray, frac: float,
                      rng) -> tuple[np.ndarray, np.ndarray]:
    """Stratified validation subset of ``train`` (round(frac x members) per stratum,
    spec 000 §3.1 step 4): returns ``(fit, val)``."""
    val = []
    for k in np.unique(strata[train]):
        members = train[strata[train] == k]
        m = int(np.floor(frac * members.size + 0.5))
        if m:
            val.extend(rng.choice(members, size=m, replace=False).tolist())
    val = np.sort(np.asarray(val, dtype=int))
    fit = np.setdiff1d(train, val)
    return fit, val


def make_splits(samples: ThermalSamples, config: FitConfig, rng=None) -> list[Split]:
    """The split(s) of spec 000 §3.1 step 4 (one for random/interp_T/up_down, one per set
    point for leave_one_T_out; the reference set point is always in training)."""
    from inertialab.calib.thermal import Split

    cfg = config.validate()
    g = as_generator(rng)
    strata = strata_of(samples)
    idx = np.arange(samples.n)
    is_ref = np.isclose(samples.set_point_c, cfg.reference_temp_c, atol=1e-6)
    splits = []
    if cfg.split == "random":
        test = []
        for k in np.unique(strata):
            members = idx[strata == k]
            if cfg.test_positions >= members.size:
                raise InputError(f"test_positions {cfg.test_positions} leaves no training data")
            test.extend(g.choice(members, size=cfg.test_positions, replace=False).tolist())
        test = np.sort(np.asarray(test, dtype=int))
        train = np.setdiff1d(idx, test)
        fit, val = validation_subset(train, strata, cfg.val_fraction, g)
        splits.append(Split("random", train, test, fit, val))
    elif cfg.split == "interp_T":
        sps = np.unique(samples.set_point_c)
        lo = sps.min()
        step = np.min(np.diff(sps)) if sps.size > 1 else 1.0
        k = np.rint((samples.set_point_c - lo) / step).astype(int)
        train_mask = (k % 2 == 0) | is_ref
        train, test = idx[train_mask], idx[~train_mask]
        if test.size == 0:
            raise InputError("interp_T split: no intermediate set points to test on")
        fit, val = validation_subset(train, strata, cfg.val_fraction, g)
        splits.append(Split("interp_T", train, test, fit, val))
    elif cfg.split == "up_down":
        up = samples.ramp_dir == "up"
        train, test = idx[up], idx[~up]
        if test.size == 0 or train.size == 0:
            raise InputError("up_down split needs a record with an up and a down pass "
                             "(a virtual-lab record simulated with ramp='up_down')")
        fit, val = validation_subset(train, strata, cfg.val_fraction, g)
        splits.append(Split("up_down", train, test, fit, val))
    else:
        for sp in np.unique(samples.set_point_c[~is_ref]):
            test = idx[samples.set_point_c == sp]
            train = idx[samples.set_point_c != sp]
            fit, val = validation_subset(train, strata, cfg.val_fraction, g)
            splits.append(Split(f"leave_out_{sp:g}", train, test, fit, val))
    return splits


@dataclass
class ThermalFit:
    """Result of :func:`fit_thermal`.

    ``models``: method -> ThermalModel fitted on the (first) split; ``metrics``: method ->
    ModelMetrics on the test set (pooled over folds for leave_one_T_out); ``predictions``:
    method -> test predictions (mV) aligned with ``test_index``; ``splits``; ``samples``;
    ``raw_rms_ug`` = uncompensated RMS on the test set; ``search``: the IAFSA log.
    """

    samples: ThermalSamples
    splits: list[Split]
    models: dict
    metrics: dict
    predictions: dict
    test_index: np.ndarray
    raw_rms_ug: float
    config: FitConfig
    search: dict | None = None

    def table(self) -> dict:
        """JSON-ready per-model metrics (the CLI's ``models`` key)."""
        return {m: v.to_dict() for m, v in self.metrics.items()}

    @property
    def model_method(self) -> str:
        """The method saved as *the* model of a fit (``model.json``): the proposed
        IAFSA-SCM-ANFIS (spec 000 §3.6) when it was fitted, else the first requested."""
        from inertialab.calib.thermal import PROPOSED

        return PROPOSED if PROPOSED in self.models else self.config.methods[0]

    def own_drift(self, method: str | None = None) -> DriftResult:
        """Drift of the training unit compensated with its own model (default: the
        saved model's method)."""
        from inertialab.calib.thermal import drift

        return drift(self.models[method or self.model_method], self.samples, own_unit=True)

    def summary(self, own: DriftResult | None = None) -> dict:
        """JSON-ready result of a fit (the keys of ``thermal fit --json`` and
        ``result.json``): metrics per model, SCM parameters, the search log, the raw
        RMS drift, the 55 °C coefficients, the saved model's method and its drift."""
        keys = ("rmse_ug", "me_ug", "ae_ug", "mbe_ug", "maxe_ppm", "mare_ppm", "rmse_truth_ug",
                "rules", "wall_s")
        own = own if own is not None else self.own_drift()
        return {
            "models": {m: {k: v.to_dict()[k] for k in keys} for m, v in self.metrics.items()},
            "scm": {m: mod.scm for m, mod in self.models.items() if mod.scm is not None},
            "search": None if self.search is None else {
                k: self.search[k] for k in ("params", "fun", "f_default", "n_rules", "nfev",
                                            "nit", "wall_s", "message")},
            "raw_rms_ug": self.raw_rms_ug,
            "reference": self.samples.ref.to_dict(),
            "model_method": self.model_method,
            "drift": own.summary(),
            "n_samples": self.samples.n, "n_test": int(self.test_index.size),
            "fish": self.config.fish_table(),
            "bias_scale_factor": bias_scale_factor(self.samples).summary(),
        }

    def table2(self) -> pd.DataFrame:
        """The paper's Table 2 from this fit: per model ME, AE, MAXE, MARE and RMSE on the
        test set (spec 000 §5; absolute errors in µg and mg, relative in ppm), with MBE,
        the rule count, the SCM parameters and the wall time (spec 000 §8.2.6)."""
        import pandas as pd

        rows = []
        for m, v in self.metrics.items():
            scm = self.models[m].scm or {}
            radius = scm.get("radius")
            rows.append({
                "model": LABELS.get(m, m), "method": m,
                "me_ug": v.me_ug, "ae_ug": v.ae_ug, "maxe_ppm": v.maxe_ppm,
                "mare_ppm": v.mare_ppm, "rmse_ug": v.rmse_ug,
                "me_mg": v.me_ug / 1e3, "ae_mg": v.ae_ug / 1e3, "rmse_mg": v.rmse_ug / 1e3,
                "mbe_ug": v.mbe_ug, "n_test": v.n, "rules": v.rules,
                "radius": (None if radius is None else
                           " ".join(f"{r:.6g}" for r in np.atleast_1d(radius))),
                "squash": scm.get("squash"), "accept": scm.get("accept"),
                "reject": scm.get("reject"), "wall_s": v.wall_s})
        return pd.DataFrame(rows)

    def table1(self) -> pd.DataFrame:
        """The paper's Table 1: the fish-swarm parameters used (quantity, value)."""
        import pandas as pd

        t = self.config.fish_table()
        return pd.DataFrame({"quantity": list(t), "value": [t[k] for k in t]})


def bias_scale_factor(samples: ThermalSamples):
    """Bias (0°/180°) and eq.-3 scale factor per set point and input level, and their
    drift against the reference set point, from the first ramp pass of the samples (the
    seed's Figs. 3 and 4; :func:`inertialab.sensors.pendulous.bias_scale_factor_drift`)."""
    m = samples.ramp_dir == samples.ramp_dir[0]
    return bias_scale_factor_drift(samples.set_point_c[m], samples.temp_c[m],
                                   samples.a_in_g[m], samples.output_mv[m], k1_ref=samples.k1,
                                   reference_temp_c=samples.reference_temp_c)


def bias_scale_factor_table(bsf) -> pd.DataFrame:
    """The data of Figs. 3 and 4 as one long table: one row per (set point, input level)."""
    import pandas as pd

    n_t, n_l = bsf.scale_factor_mv_per_g.shape
    return pd.DataFrame({
        "set_point_c": np.repeat(bsf.set_point_c, n_l), "temp_c": np.repeat(bsf.temp_c, n_l),
        "bias_mv": np.repeat(bsf.bias_mv, n_l), "bias_drift_mg": np.repeat(bsf.bias_drift_mg, n_l),
        "a_in_g": np.tile(bsf.levels_g, n_t),
        "scale_factor_mv_per_g": bsf.scale_factor_mv_per_g.ravel(),
        "scale_factor_drift_mv_per_g": bsf.scale_factor_drift_mv_per_g.ravel(),
        "scale_factor_drift_ppm": bsf.scale_factor_drift_ppm.ravel()})


#: Display names of the methods (the paper's spelling).
LABELS = {"ann": "ANN", "fis": "FIS", "anfis": "ANFIS (grid)", "scm-anfis": "SCM-ANFIS",
          "iafsa-scm-anfis": "IAFSA-SCM-ANFIS", "poly-sep": "POLY-SEP", "poly-2d": "POLY-2D"}

_MD_HEAD = {"me_ug": "ME (µg)", "ae_ug": "AE (µg)", "maxe_ppm": "MAXE (ppm)",
            "mare_ppm": "MARE (ppm)", "rmse_ug": "RMSE (µg)", "me_mg": "ME (mg)",
            "ae_mg": "AE (mg)", "rmse_mg": "RMSE (mg)", "mbe_ug": "MBE (µg)",
            "n_test": "n", "wall_s": "wall (s)"}


def markdown_table(frame: pd.DataFrame, *, title: str = "", drop=("method",)) -> str:
    """A GitHub-flavoured Markdown table of ``frame`` (numbers to 4 significant digits,
    units in the headers)."""
    cols = [c for c in frame.columns if c not in drop]

    def cell(v):
        if v is None or (isinstance(v, float) and not np.isfinite(v)):
            return "–"
        if isinstance(v, (float, np.floating)):
            return f"{v:.4g}"
        return str(v).replace("|", "\\|")

    lines = [f"**{title}**", ""] if title else []
    lines.append("| " + " | ".join(_MD_HEAD.get(c, c) for c in cols) + " |")
    lines.append("|" + "---|" * len(cols))
    for _, r in frame.iterrows():
        lines.append("| " + " | ".join(cell(r[c]) for c in cols) + " |")
    return "\n".join(lines) + "\n"


def method_stream(parent: np.random.SeedSequence, fold: int, method: str) -> np.random.Generator:
    """The random stream of ``method`` on fold ``fold``: the child of ``parent`` with
    spawn key ``parent.spawn_key + (fold, crc32(method))`` (CRC-32 of the UTF-8 name,
    stable across runs and machines)."""
    key = zlib.crc32(str(method).encode("utf-8"))
    child = np.random.SeedSequence(parent.entropy,
                                   spawn_key=tuple(parent.spawn_key) + (int(fold), key))
    return np.random.Generator(np.random.PCG64(child))


def fit_thermal(samples: ThermalSamples, config: FitConfig | None = None, *,
                progress=None) -> ThermalFit:
    """Fit the requested models on the configured split and score them (spec 000 §3-§5).

    Random streams: ``SeedSequence(config.seed)`` spawns the split stream and a model
    stream; each (fold, method) draws from its own child of the model stream keyed by
    the fold index and the method's *name* (:func:`method_stream`), so a model gets the
    same numbers whether it is fitted alone or beside others, in any order. Without
    ``config``: :class:`FitConfig` with every method (``method="all"``).
    """
    from inertialab.calib.thermal import fit_model, raw_drift_rms_ug, score

    cfg = (config or FitConfig(method="all")).validate()
    progress = progress or NullProgress()
    ss = np.random.SeedSequence(cfg.seed)
    split_ss, model_ss = ss.spawn(2)
    splits = make_splits(samples, cfg, rng=np.random.Generator(np.random.PCG64(split_ss)))
    n_folds = len(splits)
    preds = {m: [] for m in cfg.methods}
    models, walls, search = {}, {m: 0.0 for m in cfg.methods}, None
    total = n_folds * len(cfg.methods)
    done = 0
    for f, sp in enumerate(splits):
        for m in cfg.methods:
            progress.update(done, total, f"{m} ({sp.name})")
            t0 = time.perf_counter()
            rng = method_stream(model_ss, f, m)
            with single_threaded_blas():
                model = fit_model(samples, sp, m, cfg, rng=rng)
            walls[m] += time.perf_counter() - t0
            preds[m].append(model.predict_nc(samples.temp_c[sp.test], samples.n_mv[sp.test]))
            if f == 0:
                models[m] = model
                if model.search is not None:
                    search = model.search
            done += 1
    progress.update(total, total, "done")
    test = np.concatenate([sp.test for sp in splits])
    metrics = {}
    for m in cfg.methods:
        pm = np.concatenate(preds[m])
        if not np.all(np.isfinite(pm)):
            # finite samples in, NaN out: an error, never a model with null metrics
            raise InputError(f"the {m} model gives non-finite predictions on finite data "
                             "(values out of range for this model)")
        proxy = _FixedPrediction(pm, test)
        met = score(proxy, samples, test, wall_s=walls[m])
        met = replace(met, rules=models[m].n_rules)
        metrics[m] = met
        models[m].metrics = met.to_dict()
        preds[m] = pm
    return ThermalFit(samples=samples, splits=splits, models=models, metrics=metrics,
                      predictions=preds, test_index=test, raw_rms_ug=raw_drift_rms_ug(samples, test),
                      config=cfg, search=search)


class _FixedPrediction:
    """Adapter so :func:`score` can score pooled fold predictions."""

    n_rules = None
    learn_drift = False

    def __init__(self, pred, idx):
        self._pred = pred

    def predict_nc(self, T, N):
        return self._pred


def fit(samples: ThermalSamples, config: FitConfig | None = None, *,
        progress=None) -> ThermalFit:
    """The workflow's ``fit`` verb: :func:`fit_thermal`."""
    return fit_thermal(samples, config, progress=progress)


# ---------------------------------------------------------------------------------------
# apply: model, record -> compensated record
# ---------------------------------------------------------------------------------------
REFERENCES = ("auto", "model", "record")


@dataclass(frozen=True)
class ThermalApplied:
    """A compensated record: ``frame`` (the input columns plus ``comp_output_mv``,
    ``comp_a_g``, ``status``), ``meta`` (the input's sidecar plus provenance),
    ``compensation``, ``reference`` ("model" or "record": whose 55 °C coefficients
    formed Ua), ``drift`` (raw and compensated drift vs the reference temperature when
    the record is a full tumble, else None) and ``samples`` (or None)."""

    frame: pd.DataFrame
    meta: dict
    compensation: Compensation
    reference: str
    drift: DriftResult | None
    samples: ThermalSamples | None

    def summary(self) -> dict:
        st = self.compensation.status
        counts = {str(k): int(v) for k, v in zip(*np.unique(st, return_counts=True))}
        return {"n_rows": int(len(self.frame)), "n_clamped": int(np.count_nonzero(st)),
                "status_counts": counts, "reference": self.reference,
                "drift": None if self.drift is None else self.drift.summary()}


def apply(model: ThermalModel, record, *, reference: str = "auto",
          source: str | None = None) -> ThermalApplied:
    """Compensate a ``thermal_tumble`` record with ``model`` (spec 000 §3.7).

    Parameters
    ----------
    reference : {"auto", "model", "record"}
        Whose 55 °C coefficients form Ua: the model unit's, or the record's own 55 °C
        tumble (transfer to another unit, §3.7). ``auto`` = the record's when it holds
        a full tumble with a reference set point and is another unit (its ``unit_id``
        differs from the model's).
    source : provenance written to the output sidecar (``compensated_with``)

    Raises
    ------
    InputError
        ``reference="record"`` without a usable tumble in the record; every reading
        outside the model's calibrated temperature range.
    """
    from inertialab.calib.thermal import compensate, drift

    ref_mode = str(reference).strip().lower()
    if ref_mode not in REFERENCES:
        raise InputError(f"argument 'reference' must be auto, model or record, got '{reference}'")
    d = record.data
    samples = None
    if ref_mode in ("auto", "record"):
        try:
            cfg = FitConfig(input=model.input, target=model.target,
                            reference_temp_c=model.reference_temp_c)
            samples = prepare_samples(d, cfg, path=record.path)
        except InputError:
            if ref_mode == "record":
                raise
    same_unit = "unit_id" in d and str(d["unit_id"].iloc[0]) == model.unit_id
    use_record = samples is not None and (ref_mode == "record" or not same_unit)
    unit_ref = samples.ref if use_record else None
    for col in ("temp_meas_c", "output_mv"):
        if col not in d.columns:
            raise InputError("missing required column", path=record.path, column=col)
    a_p = d["a_pend_g"].to_numpy() if "a_pend_g" in d else None
    comp = compensate(model, d["temp_meas_c"].to_numpy(), d["output_mv"].to_numpy(), a_p,
                      unit_ref=unit_ref, path=record.path)
    dr = drift(model, samples, own_unit=not use_record) if samples is not None else None
    out = d.copy()
    out["comp_output_mv"] = comp.nc_mv
    out["comp_a_g"] = comp.a_g
    out["status"] = comp.status
    meta = dict(record.meta)
    meta.update({"compensated_with": source, "model_method": model.method,
                 "reference": "record" if use_record else "model"})
    return ThermalApplied(frame=out, meta=meta, compensation=comp,
                          reference="record" if use_record else "model", drift=dr,
                          samples=samples)


def export(model: ThermalModel, *, prefix: str = "qfa", unit_record=None):
    """C99 source of a fuzzy thermal model (:func:`inertialab.export.thermal_c.export_c`).
    ``unit_record``: a thermal-tumble record of the unit the code will run on, when it is
    another unit of the lot; its 55 °C tumble gives the coefficients of the §3.7 mapping."""
    unit_ref, unit_id = None, ""
    if unit_record is not None:
        cfg = FitConfig(input=model.input, target=model.target,
                        reference_temp_c=model.reference_temp_c)
        s = prepare_samples(unit_record.data, cfg, path=unit_record.path)
        unit_ref, unit_id = s.ref, s.unit_id
    return export_c(model, prefix=prefix, unit_ref=unit_ref, unit_id=unit_id)


_CHOICES = ("iafsa-scm-anfis", "scm-anfis", "anfis", "fis", "ann", "poly-sep", "poly-2d",
            "all")


def methods_from(method: str | tuple) -> tuple[str, ...]:
    """The methods of a ``method`` text (one name, a comma list, or ``all``) or of a
    tuple of names."""
    from inertialab.calib.thermal import METHODS

    if isinstance(method, (tuple, list)):
        method = ",".join(str(p) for p in method)
    m = str(method).strip().lower()
    if m == "all":
        return METHODS
    parts = tuple(p.strip() for p in m.split(",") if p.strip())
    bad = [p for p in parts if p not in _CHOICES or p == "all"]
    if not parts or bad:
        raise InputError(f"argument 'method' must be one of {', '.join(_CHOICES)} (or a "
                         f"comma-separated list), got '{method}'")
    return parts


#: The former spellings of the estimator's settings class (``ThermalConfig``), each mapped
#: to the one name the command, the JSON ``settings`` and every layer now use.
OLD_SPELLINGS = {"methods": "method", "fish_visual": "visual", "fish_step": "step",
                 "fish_try_number": "try_number", "fish_crowd": "crowd"}

#: Fields of :class:`FitConfig` that ``settings`` does not write (the paper's fixed
#: choices, settable from the library only); ``reference_temp_c`` is written as the run
#: decided it (the record's sidecar, else the setting).
NOT_WRITTEN = ("imu", "test_positions", "val_fraction", "include_kp", "reference_temp_c",
               "temp_tolerance_c", "r_max", "ann_hidden", "ann_max_epochs", "poly_sep_degree",
               "poly2d_degrees", "range_margin_c", "range_margin_frac")

#: Settings that lie in (0, 1] (a lower bound the field's closed ``lo`` cannot say).
_UNIT_INTERVAL = ("visual", "step", "crowd")


@dataclass(frozen=True)
class FitConfig(_Settings):
    """Settings of ``thermal fit`` and of :func:`prepare`, :func:`make_splits`,
    :func:`fit` and the estimator :func:`~inertialab.calib.thermal.fit_model` (one class:
    each field's name is its JSON key in ``settings`` and its flag with ``-``; defaults:
    spec 000 §3-§4).

    ``method``: one name of :data:`METHODS`, a comma list, ``all`` or a tuple of names
    (:attr:`methods`). ``split``: ``random`` | ``interp_T`` | ``leave_one_T_out`` (§3.1
    step 4) | ``up_down`` (train on the up pass, test on the down pass: hysteresis, §8.4).
    ``target``: ``linear55`` (eq. 6) | ``measured55`` (the 55 °C Ua at the same position);
    ``input``: ``ua`` (eq. 5) | ``raw`` (N = U; the target keeps the fitted 55 °C terms);
    ``learn_drift``: learn ``Nc - N`` instead of ``Nc`` (§3.1 step 5). IAFSA: ``fish``
    and ``generations`` (N_fish 10, G_max 30), ``visual`` and ``step`` (initial visual
    range 0.30 and step 0.10 of the fish, unit-cube coordinates), ``try_number`` (prey
    attempts, 5) and ``crowd`` (crowd factor 0.618): spec 000 §3.5's values (the seed's
    Table 1 is lost); the floors Visual_min = 0.02, Step_min = 0.005 and the exponent
    s = 3 stay fixed. ``radii``: ``scalar`` (4-D search) | ``per_dim`` (6-D: r_T, r_N,
    r_y). ``epochs``: final ANFIS epochs (150); ``search_epochs``: ANFIS epochs inside
    IAFSA (20). ``seed``: master seed (split stream, then one stream per fold and method
    name).

    Library only (:data:`NOT_WRITTEN`): ``test_positions`` (positions per set point in
    the test set of the random split, 7 of 24); ``val_fraction`` (stratified validation
    share of the training set, 0.2); ``include_kp`` (fit Kp in the reference fit, §3.1
    step 1); ``reference_temp_c`` 55 °C and ``temp_tolerance_c`` ±2 °C around each set
    point (§2.3); ``r_max`` (rule cap, 40); ``ann_hidden``, ``ann_max_epochs`` (MLP
    2-10-1, up to 500 LM iterations, §4); ``poly_sep_degree`` (cubic K0(T), K1(T), §4);
    ``poly2d_degrees`` ((m, n) = (3, 1), §4); ``range_margin_c``, ``range_margin_frac``:
    the calibrated range used for clamping is the training range of T widened by 0.5 °C
    (chamber wander) and of N widened by 5 % of its span on each side [ours]. Clamping N
    exactly at the training maximum would saturate a +1 g reading whose position happened
    to fall in the test set (measured: 400 µg at 70 °C, +1 g), while the first-order
    consequents extrapolate benignly.
    """

    method: str = setting("iafsa-scm-anfis", help="iafsa-scm-anfis | scm-anfis | anfis "
                                                          "| fis | ann | poly-sep | poly-2d | "
                                                          "all (or a comma list)")
    imu: bool = setting(False, help="FILE is a drone IMU temperature ramp (PX4 .ulg, "
                        "ArduPilot .bin or table): fit every gyro and accelerometer "
                        "instance (docs/thermal-imu.md); the method is then one of poly | "
                        "scm-anfis | iafsa-scm-anfis.")
    split: str = setting("random", help="random | interp_T | leave_one_T_out | up_down",
                         choices=("random", "interp_T", "leave_one_T_out", "up_down"))
    target: str = setting("linear55", help="linear55 | measured55",
                          choices=("linear55", "measured55"))
    input: str = setting("ua", help="ua (eq. 5) | raw (N = U)", choices=("ua", "raw"))
    learn_drift: bool = setting(False, help="Learn Nc - N.")
    radii: str = setting("scalar", help="scalar | per_dim (IAFSA)", choices=("scalar", "per_dim"))
    fish: int = setting(10, help="IAFSA fish (the paper's 10).", lo=1, hi=10_000)
    generations: int = setting(30, help="IAFSA generations (30).", lo=1, hi=100_000)
    epochs: int = setting(150, help="Final ANFIS epochs (150).", lo=1, hi=1_000_000)
    search_epochs: int = setting(20, help="ANFIS epochs inside the IAFSA objective (20).",
                                 lo=1, hi=1_000_000)
    # visual, step and crowd lie in (0, 1] (_UNIT_INTERVAL, checked by validate)
    visual: float = setting(0.30, help="IAFSA initial visual range, unit-cube units (0.30).")
    step: float = setting(0.10, help="IAFSA initial step, unit-cube units (0.10).")
    # each try is a model evaluation per fish and generation: bounded
    try_number: int = setting(5, help="IAFSA prey attempts (5).", lo=1, hi=1000)
    crowd: float = setting(0.618, help="IAFSA crowd factor (0.618).")
    seed: int = seed_setting("Random seed (same seed, same numbers).")
    test_positions: int = setting(7, help="Test positions per set point (random split).",
                                  lo=1, hi=10_000, cli=False)
    val_fraction: float = setting(0.2, help="Validation share of the training set, in (0, 1).",
                                  lo=0.0, hi=1.0, cli=False)
    include_kp: bool = setting(True, help="Fit Kp in the reference fit.", cli=False)
    reference_temp_c: float = setting(55.0, help="Reference temperature.", unit="degC",
                                      cli=False)
    temp_tolerance_c: float = setting(2.0, help="Largest |measured - set point| temperature.",
                                      unit="degC", lo=0.0, hi=1000.0, cli=False)
    r_max: int = setting(40, help="IAFSA rule cap.", lo=1, hi=10_000, cli=False)
    ann_hidden: int = setting(10, help="ANN hidden neurons.", lo=1, hi=10_000, cli=False)
    ann_max_epochs: int = setting(500, help="ANN LM iterations.", lo=1, hi=1_000_000, cli=False)
    poly_sep_degree: int = setting(3, help="POLY-SEP degree of K0(T), K1(T).", lo=0, hi=20,
                                   cli=False)
    poly2d_degrees: tuple[int, int] = setting((3, 1), help="POLY-2D degrees (m, n) in T, N.",
                                              lo=0, hi=20, cli=False)
    range_margin_c: float = setting(0.5, help="Calibrated T range margin.", unit="degC",
                                    lo=0.0, hi=1000.0, cli=False)
    range_margin_frac: float = setting(0.05, help="Calibrated N range margin, share of the "
                                                  "span.", lo=0.0, hi=10.0, cli=False)

    @property
    def methods(self) -> tuple[str, ...]:
        """The methods of ``method`` (:func:`methods_from`)."""
        return methods_from(self.method)

    def validate(self) -> FitConfig:
        """The declared bounds and choices, the methods, the (0, 1] settings and what
        POLY-SEP needs; one :class:`InputError` naming the argument."""
        super().validate()
        if self.imu:  # the drone-IMU fit checks its own methods (thermal_imu.imu_config)
            return self
        methods = self.methods
        for name in _UNIT_INTERVAL:
            v = getattr(self, name)
            if not (np.isfinite(v) and 0 < v <= 1):
                raise InputError(f"argument '{name}' must be in (0, 1] (unit-cube "
                                 f"coordinates), got {v}")
        if not 0 < self.val_fraction < 1:
            raise InputError(f"argument 'val_fraction' must be in (0, 1), got "
                             f"{self.val_fraction}")
        if "poly-sep" in methods and (self.learn_drift or self.input == "raw"):
            raise InputError("poly-sep needs argument 'input' ua without argument "
                             "'learn_drift'")
        return self

    def written(self) -> dict:
        """The settings as ``settings`` writes them (every field but :data:`NOT_WRITTEN`)
        before the run fills in the methods as a list and the reference temperature."""
        return {k: v for k, v in self.to_dict().items() if k not in NOT_WRITTEN}

    def fish_table(self) -> dict:
        """Table 1 of the paper (fish-swarm parameters), with the values used."""
        from inertialab.learn.scm_search import FISH_DEFAULTS

        return {"n_fish": int(self.fish), "max_generations": int(self.generations),
                "visual": float(self.visual), "step": float(self.step),
                "visual_min": FISH_DEFAULTS["visual_min"],
                "step_min": FISH_DEFAULTS["step_min"],
                "try_number": int(self.try_number), "crowd": float(self.crowd),
                "adaptive_exponent": FISH_DEFAULTS["s"],
                "search_epochs": int(self.search_epochs), "r_max": int(self.r_max)}


def ThermalConfig(**settings) -> FitConfig:
    """Deprecated: :class:`FitConfig` under the estimator's former spellings
    (:data:`OLD_SPELLINGS`: ``methods``, ``fish_visual`` ...), for one release."""
    import warnings

    warnings.warn("ThermalConfig is deprecated: use inertialab.workflows.thermal.FitConfig "
                  "(method, visual, step, try_number, crowd)", DeprecationWarning, stacklevel=2)
    renamed = {OLD_SPELLINGS.get(k, k): v for k, v in settings.items()}
    if isinstance(renamed.get("method"), list):
        renamed["method"] = tuple(renamed["method"])
    return FitConfig(**renamed)


@dataclass
class FitResult(ResultBase):
    """The fit (:class:`~inertialab.workflows.thermal.ThermalFit`), its samples, the
    model's own drift and the bias/scale-factor curves."""

    result: object
    samples: object
    own: object
    bsf: object
    settings: dict
    sha256: str | None = None
    units = dict(THERMAL_UNITS)

    def to_json(self) -> dict:
        return self.result.summary(self.own)

    def artifacts(self) -> dict:
        r, u = self.result, {"temp": "degC", "output": "mV"}
        models = [("model.json", r.models[r.model_method], u)]
        models += [(f"models/{m}.json", mod, u) for m, mod in r.models.items()]
        files = {}
        for name, table, title in (
                ("table1", r.table1(), "Table 1: fish-swarm parameters"),
                ("table2", r.table2(), f"Table 2: test errors per model ({self.settings['split']}"
                                       f" split, {r.test_index.size} test samples)")):
            files[f"{name}.csv"] = table.to_csv(index=False)
            files[f"{name}.md"] = markdown_table(table, title=title)
        files["bias_scale_factor.csv"] = bias_scale_factor_table(self.bsf).to_csv(index=False)
        return {"models": models, "files": files}

    def summary_rows(self) -> list:
        r = self.result
        rows = [[m, v.rmse_ug, v.me_ug, v.ae_ug, v.maxe_ppm, v.mare_ppm, v.rules, v.wall_s]
                for m, v in r.metrics.items()]
        out = [(f"thermal fit ({self.settings['split']} split, raw drift RMS "
                f"{r.raw_rms_ug:.0f} µg)",
                ["model", "RMSE µg", "ME µg", "AE µg", "MAXE ppm", "MARE ppm", "rules",
                 "wall s"], rows)]
        if r.search:
            s, p = r.search, r.search["params"]
            out.append(f"IAFSA: radius={p['radius']}, squash={p['squash']:.4g}, "
                       f"accept={p['accept']:.4g}, reject={p['reject']:.4g}, "
                       f"rules={s['n_rules']}, F*={s['fun'] * 1e3:.2f} µg (default "
                       f"{s['f_default'] * 1e3:.2f})")
            out.append("fish swarm (Table 1): " + ", ".join(
                f"{k}={v:g}" for k, v in self.to_json()["fish"].items()))
        return out


def run_fit(record, config: FitConfig, *, progress=None) -> FitResult:
    """Fit integrated temperature-compensation models on a thermal tumble record."""
    c = config.validate()
    samples = prepare(record, c)
    result = fit(samples, c, progress=progress)
    settings = c.written() | {"method": list(c.methods),
                              "reference_temp_c": samples.reference_temp_c}
    return FitResult(result=result, samples=samples, own=result.own_drift(),
                     bsf=bias_scale_factor(samples), settings=settings,
                     sha256=record.sha256)


# -------------------------------------------------------------------------- apply

@dataclass(frozen=True)
class ApplyConfig(_Settings):
    """Settings of ``thermal apply``."""

    reference: str = setting("auto", help="model | record | auto: Ua with the model unit's "
                                          "55 °C coefficients, or with the record's own 55 °C "
                                          "tumble (transfer to another unit, spec 000); "
                                          "auto = record when it has a full 55 °C tumble of "
                                          "another unit.")
    force: bool = setting(False, help="Apply a model that fails its re-check at its training "
                                      "conditions (compensated drift beyond the raw) anyway; "
                                      "the output is flagged.")


@dataclass
class ApplyResult(ResultBase):
    """``thermal apply``: the compensated record (:class:`~inertialab.workflows.thermal.
    ThermalApplied`) to write at ``out``."""

    res: object
    out: object
    settings: dict
    sha256: str | None = None
    model: object = None
    units = {}

    def to_json(self) -> dict:
        return self.res.summary() | {"out": str(self.out)}

    def artifacts(self) -> dict:
        return {"records": [(self.out, self.res.frame, self.res.meta)]}

    def summary_rows(self) -> list:
        s, d = self.res.summary(), self.res.drift
        out = [f"compensated {s['n_rows']} rows ({s['n_clamped']} clamped) -> {self.out}"]
        if d is not None:
            out.append(f"drift vs 55 °C: raw max {d.raw_max_ug / 1e3:.3f} mg, compensated max "
                       f"{d.comp_max_ug:.2f} µg")
        return out


def run_apply(model, record, config: ApplyConfig, *, out, source: str | None = None
              ) -> ApplyResult:
    """Compensate a thermal-tumble record with a thermal model; the record to write at
    ``out`` has comp_output_mv (mV), comp_a_g (g) and status."""
    from inertialab.calib.model_checks import refuse_or_flag, thermal_findings
    c = config.validate()
    flags = refuse_or_flag(thermal_findings(model), "thermal", force=c.force, path=source)
    res = apply(model, record, reference=c.reference, source=source)
    if flags:
        res.meta["flags"] = flags
    return ApplyResult(res=res, out=out, settings={"reference": c.reference.strip().lower(),
                                                   "force": c.force},
                       sha256=record.sha256, model=model)


# ------------------------------------------------------------------------- export

@dataclass(frozen=True)
class ExportConfig(_Settings):
    """Settings of ``thermal export``."""

    prefix: str = setting("qfa", help="C identifier prefix.")
    unit_record: Path | None = setting(None, help="thermal_tumble record of the unit the code "
                                                  "will run on, when it is another unit of the "
                                                  "lot: its 55 °C tumble gives the transfer "
                                                  "mapping of spec 000.")


@dataclass
class ExportResult(ResultBase):
    """``thermal export``: the C99 pair of a fuzzy thermal model (``files``: the paths
    written by :meth:`write`)."""

    ex: object
    mapped: bool
    settings: dict
    files: list | None = None
    units = {}

    def write(self, directory) -> list:
        from inertialab.export import get

        self.files = get("thermal", "c99").write(self.ex, directory)
        return self.files

    def to_json(self) -> dict:
        p = self.settings["prefix"]
        return {"files": self.files, "n_rules": self.ex.n_rules,
                "exp_calls": self.ex.exp_calls, "flops": self.ex.flops,
                "functions": [f"{p}_comp_mV", f"{p}_comp_g"],
                "mapped_unit": self.ex.unit_id if self.mapped else None}

    def artifacts(self) -> dict:
        return {}

    def summary_rows(self) -> list:
        return [f"written: {self.files[0]}, {self.files[1]} ({self.ex.n_rules} rules, "
                f"{self.ex.exp_calls} exp calls per reading)"]


def run_export(model, config: ExportConfig, *, unit_record=None) -> ExportResult:
    """Dependency-free C99 of a fuzzy thermal model (inputs clamped, status flag);
    ``unit_record``: the record read from ``config.unit_record``."""
    c = config.validate()
    ex = export(model, prefix=c.prefix, unit_record=unit_record)
    return ExportResult(ex=ex, mapped=unit_record is not None, settings=c.to_dict())


__all__ = [
    "FUZZY", "METHODS", "PROPOSED", "REFERENCES", "ThermalApplied", "export", "ThermalConfig",
    "ThermalFit", "ThermalModel", "ThermalSamples", "apply", "compensate", "drift", "fit",
    "fit_thermal", "make_splits", "prepare", "prepare_samples", "reference_temperature",
    "strata_of", "validation_subset", "ApplyConfig", "ApplyResult", "ExportConfig",
    "ExportResult", "FitConfig", "FitResult", "methods_from", "run_apply", "run_export", "run_fit",
]
