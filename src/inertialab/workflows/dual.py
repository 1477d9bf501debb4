"""Workflow ``dual`` (spec 003): dual-meter dividing-head records to a calibration.

Thin, one verb set over :mod:`inertialab.calib.dual`:

* :func:`prepare` — a validated ``dual_tumble`` record to a
  :class:`~inertialab.calib.dual_reduce.Reduced` (one run per file; §2.3);
* :func:`load_prior` — the prior named on the command line: none, certificate, an
  ``inertialab.prior/1`` JSON file or a CSV of past calibrations;
* :func:`fit` — the chosen methods on one tumble, the two-orientation fit when a second
  tumble is given, errors vs truth for a virtual-lab record, and the head-error
  sensitivity when asked; :class:`DualResult` carries the command's JSON payload;
* :func:`design` — D-optimal positions (§7.2);
* the commands, one call each: :class:`FitConfig` and ``run_fit(records, config) ->
  FitResult``, :class:`DesignConfig` and ``run_design(config) -> DesignResult``
  (:class:`inertialab.result.Result`: ``to_json()``, ``settings``, ``units``,
  ``warnings``, ``artifacts()``, ``summary_rows()``).

The estimators (:mod:`inertialab.calib.dual`, pandas, scipy) are imported inside the
functions that use them, so that ``dual fit --help`` starts light.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from inertialab.config import Config, setting
from inertialab.errors import InputError
from inertialab.result import ResultBase
from inertialab.sensors.dual_meter import COEF_UNITS, PAPER_ALIASES

if TYPE_CHECKING:
    from inertialab.calib.dual import DualFit, MethodResult
    from inertialab.calib.dual_prior import DualPrior
    from inertialab.calib.dual_reduce import Reduced

__all__ = ["METHOD_CHOICES", "PAPER_ALIASES", "UNITS", "DesignConfig", "DesignResult",
           "DualConfig", "DualResult", "FitConfig", "FitResult", "design", "fit",
           "load_prior", "parse_methods", "prepare", "prior_from_history", "run_design",
           "run_fit"]

#: The methods of :func:`fit`, in :data:`inertialab.calib.dual.METHODS`'s order (the
#: calib module checks that both agree).
_ALL_METHODS = ("single-ls", "ls", "ebr", "ridge-hkb", "ridge-gcv")


def prior_from_history(*args, **kw):
    """:func:`inertialab.calib.dual_prior.prior_from_history` (imported when called)."""
    from inertialab.calib.dual_prior import prior_from_history as _from_history

    return _from_history(*args, **kw)

#: Values of the ``method`` argument ("all" = every method of :data:`METHODS`).
METHOD_CHOICES = ("ebr", "ls", "single-ls", "ridge-hkb", "ridge-gcv", "all")
#: Units of the numeric keys of the result (coefficients, residuals).
UNITS = {**COEF_UNITS, "delta_A": "rad", "delta_B": "rad", "residual": "g",
         "residual_raw": "g", "residual_val": "g"}


def parse_methods(method: str) -> tuple:
    """``"all"`` or one method name (case-insensitive) to a tuple of :data:`METHODS`."""
    m = str(method).strip().lower()
    if m not in METHOD_CHOICES:
        raise InputError(f"argument 'method' must be one of {', '.join(METHOD_CHOICES)}, "
                         f"got '{method}'")
    return _ALL_METHODS if m == "all" else (m,)


def load_prior(spec) -> DualPrior | None:
    """``None``/"none" (paper-faithful beta0 = 0, W = I), "certificate", a JSON prior file,
    a CSV of past calibrations (one row per calibration, columns ``COEF_NAMES``; mean
    and SD floored at tau/2 of spec §6.5), or a DualPrior."""
    import pandas as pd

    from inertialab.calib.dual_prior import (
        DualPrior,
        history_prior,
        prior_from_dict,
        resolve_prior,
    )
    if spec is None or isinstance(spec, DualPrior):
        return spec
    s = str(spec)
    if s.lower() in ("none", "certificate"):
        return resolve_prior(s)
    p = Path(s)
    if not p.exists():
        raise InputError("no such prior file (use none, certificate, a JSON prior or a CSV "
                         "of past calibrations)", path=p)
    if p.is_dir():
        raise InputError("prior is a directory, expected a JSON or CSV file", path=p)
    if p.suffix.lower() == ".csv":
        try:
            hist = pd.read_csv(p)
        except (OSError, ValueError) as exc:  # UnicodeDecodeError and ParserError too
            raise InputError(f"cannot read the calibration history: {' '.join(str(exc).split())}",
                             path=p) from None
        try:
            return history_prior(hist)
        except InputError as exc:
            raise InputError(str(exc), path=p) from None
        except (TypeError, ValueError):
            raise InputError("the calibration history must hold numbers only in the "
                             "coefficient columns", path=p) from None
    try:
        from inertialab.io.modelfile import unique_keys

        d = json.loads(p.read_text(encoding="utf-8"), object_pairs_hook=unique_keys)
    except UnicodeDecodeError:
        raise InputError("prior file is not UTF-8 JSON", path=p) from None
    except json.JSONDecodeError as exc:
        raise InputError(f"prior file is not JSON (line {exc.lineno}: {exc.msg})",
                         path=p) from None
    except RecursionError:
        raise InputError("prior file is nested too deeply to be a prior", path=p) from None
    except (OSError, ValueError) as exc:  # e.g. an integer of more than 4300 digits
        raise InputError(f"prior file cannot be read as JSON ({' '.join(str(exc).split())})",
                         path=p) from None
    prior = prior_from_dict(d, path=p)
    return replace(prior, kind="file")


# ------------------------------------------------------------------------------ prepare

def prepare(record, *, g_local: float | None = None) -> Reduced:
    """Reduce a validated ``dual_tumble`` :class:`~inertialab.io.Record` (spec §2.3)."""
    import pandas as pd

    from inertialab.calib.dual_reduce import reduce_stops

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
    if unsorted:  # per-test tables are sorted, with a warning
        red = replace(red, warnings=red.warnings + (
            f"{path}: the {' and '.join(unsorted)} rows were not in time order; sorted by t_s",))
    return red


# ---------------------------------------------------------------------------------- fit

@dataclass
class DualResult:
    """What :func:`fit` returns: the fit of the first tumble, the two-orientation fit,
    errors vs truth (virtual-lab record) and the head-error sensitivity (if asked)."""

    fit: DualFit
    two_orientation: MethodResult | None = None
    errors_vs_truth: dict | None = None
    sensitivity: dict | None = None

    @property
    def model(self):
        return self.fit.model

    @property
    def warnings(self) -> list:
        return self.fit.warnings

    def payload(self) -> dict:
        """The command's JSON keys (``methods``, ``diagnostics``, ``model_method``,
        ``paper_aliases`` (canonical name -> the paper's "Kip" spelling, spec §1.3),
        ``two_orientation``, ``errors_vs_truth``)."""
        out = {"methods": {k: v.to_json() for k, v in self.fit.methods.items()},
               "diagnostics": self.fit.diagnostics,
               "model_method": self.fit.model.method,
               "paper_aliases": dict(PAPER_ALIASES)}
        if self.two_orientation is not None:
            out["two_orientation"] = self.two_orientation.to_json()
        if self.errors_vs_truth is not None:
            out["errors_vs_truth"] = self.errors_vs_truth
        return out


def fit(data: Reduced | Sequence[Reduced], config: FitConfig | None = None, *,
        truth: dict | None = None) -> DualResult:
    """Fit one tumble, or two (opposite OA signs) for the two-orientation fit (spec §7.2).

    ``config`` defaults to :class:`FitConfig` (spec 003 defaults); ``truth`` (the
    virtual lab's coefficients) adds the errors vs truth (spec §4).
    """
    from inertialab.calib.dual import (
        calibrate,
        errors_vs_truth,
        fit_two_orientation,
        head_error_sensitivity,
    )
    from inertialab.calib.dual_reduce import Reduced

    config = (FitConfig() if config is None else config).validate()
    reds = [data] if isinstance(data, Reduced) else list(data)
    if not 1 <= len(reds) <= 2:
        raise InputError("give one record, or two for the two-orientation fit")
    prior = load_prior(config.prior)
    f = calibrate(reds[0], methods=config.methods, prior=prior,
                  second_order=config.second_order, ebr_method=config.ebr_rule.upper(),
                  lambda_combination=config.lambda_combination.lower(),
                  cross_fit=config.cross_fit)
    two = fit_two_orientation(reds[0], reds[1]) if len(reds) == 2 else None
    evt = errors_vs_truth(f, truth) if isinstance(truth, dict) else None
    sens = None
    if config.sensitivity:
        sm = tuple(x for x in ("single-ls", "ls", "ebr") if x in f.methods) or ("ls",)
        sens = head_error_sensitivity(reds[0], methods=sm, prior=prior)
    return DualResult(f, two, evt, sens)


# ------------------------------------------------------------------------------- design

def design(n_positions: int = 20, *, range_deg=(0.0, 360.0), step_deg: float = 1.0) -> dict:
    """D-optimal positions for the identifiable g^2 harmonic model
    (:func:`inertialab.calib.dual.design_dual`)."""
    from inertialab.calib.dual import design_dual

    return design_dual(n_positions, range_deg=range_deg, step_deg=step_deg)


# ------------------------------------------------------ the commands, one call each

#: Display factor and unit of each coefficient in the summary table.
_SCALE = {"KA0": (1e6, "ug"), "KB0": (1e6, "ug"), "kA1": (1e6, "ppm"),
          "kB1": (1e6, "ppm"), "eta": (1e6, "urad"), "KA2": (1e6, "ug/g^2"),
          "KB2": (1e6, "ug/g^2"), "KAx": (1e6, "ug/g^2"), "KBx": (1e6, "ug/g^2")}


@dataclass(frozen=True)
class FitConfig(Config):
    """Settings of ``dual fit`` and of :func:`fit` (one class: each field's name is its
    JSON key in ``settings`` and its flag with ``-``; spec 003 defaults).

    ``method``: one of :data:`METHOD_CHOICES` (``all``: every method) or, from the
    library, a tuple of method names (:attr:`methods`); ``prior``: ``none`` (paper:
    beta0 = 0, W = I), ``certificate``, a prior file or, from the library, a
    :class:`~inertialab.calib.dual_prior.DualPrior`; ``second_order``: the [X]
    correction of §1.5; ``ebr_rule`` E1 (Stein) | E2 | E3; ``lambda_combination`` star
    | max | min; ``g_local``: local gravity (m/s^2; default: the record's). Library only
    (not written to ``settings``): ``cross_fit`` computes R_val (§4); ``sensitivity``
    adds the head-error sensitivity of single-ls/ls/ebr (the figure of ``--out``).
    """

    method: str = setting("all", help="ebr | ls | single-ls | ridge-hkb | ridge-gcv | all")
    prior: str = setting("none", help="none (paper: beta0 = 0, W = I) | certificate | FILE "
                                      "(inertialab.prior/1 JSON, or a CSV of past "
                                      "calibrations)")
    ebr_rule: str = setting("E1", help="E1 (Stein) | E2 (ML) | E3 (SURE)")
    lambda_combination: str = setting("star", help="star | max | min of lambda* and lambda0")
    second_order: bool = setting(False, help="Iterated second-order correction of y (spec 003).")
    g_local: float | None = setting(None, help="Local gravity, m/s^2.", lo=1.0, hi=100.0)
    cross_fit: bool = setting(True, help="Compute the cross-fitted R_val.", cli=False)
    sensitivity: bool = setting(False, help="Add the head-error sensitivity.", cli=False)

    @property
    def methods(self) -> tuple:
        """The methods of ``method`` (:func:`parse_methods`; a tuple of names as given)."""
        if isinstance(self.method, (tuple, list)):
            return tuple(parse_methods(m)[0] for m in self.method)
        return parse_methods(self.method)

    def validate(self) -> FitConfig:
        """The declared bounds and the methods; one :class:`InputError` naming the
        argument."""
        super().validate()
        self.methods  # noqa: B018 - parsed to refuse
        return self

    def written(self) -> dict:
        """The settings as ``settings`` writes them (spelled as the run read them)."""
        return {"method": str(self.method).strip().lower(), "prior": self.prior,
                "ebr_rule": self.ebr_rule.upper(),
                "lambda_combination": self.lambda_combination.lower(),
                "second_order": self.second_order, "g_local": self.g_local, "seed": None}


def DualConfig(**settings) -> FitConfig:
    """Deprecated: :class:`FitConfig` under its former spelling (``methods`` for
    ``method``), for one release."""
    import warnings

    warnings.warn("DualConfig is deprecated: use inertialab.workflows.dual.FitConfig "
                  "(method for methods)", DeprecationWarning, stacklevel=2)
    if "methods" in settings:
        settings["method"] = tuple(settings.pop("methods"))
    return FitConfig(**settings)


def _cell(v, sd, f) -> str:
    if v is None:
        return "-"
    sds = "n/e" if sd is None or sd != sd or sd == float("inf") else f"{sd * f:.3g}"
    return f"{v * f:+.4g} +- {sds}"


@dataclass
class FitResult(ResultBase):
    """The dual fit (:class:`~inertialab.workflows.dual.DualResult`)."""

    res: object
    settings: dict
    sha256: str | None = None

    @property
    def units(self) -> dict:

        return UNITS

    @property
    def warnings(self) -> list:
        return list(self.res.fit.warnings)

    def to_json(self) -> dict:
        return self.res.payload()

    def artifacts(self) -> dict:
        return {"models": [("model.json", self.res.model, UNITS)]}

    def summary_rows(self) -> list:
        fit = self.res.fit
        cols = list(fit.methods)
        rows = []
        for n, (f, u) in _SCALE.items():
            label = f"{n} = {PAPER_ALIASES[n]}" if n in PAPER_ALIASES else n
            rows.append([f"{label} ({u})"] + [_cell(fit.methods[k].coef.get(n),
                                                    fit.methods[k].sd.get(n), f) for k in cols])
        rows.append(["R (ug)"] + [f"{fit.methods[k].residual * 1e6:.3g}" for k in cols])
        rows.append(["R_val (ug)"] + [f"{fit.methods[k].r_val * 1e6:.3g}" for k in cols])
        rows.append(["rank"] + [str(fit.methods[k].rank) for k in cols])
        out = [("dual fit (n/e: not estimable; EBR SD = posterior)", ["coefficient", *cols],
                rows)]
        if "ls" in fit.methods:
            out += [f"  estimable {c['name']:>9s} = {c['value']:+.4e} +- {c['sd']:.2e}"
                    for c in fit.methods["ls"].estimable]
        two = self.res.two_orientation
        if two is not None:
            out.append("two-orientation LS: " + ", ".join(
                f"{n} = {two.coef[n]:+.3e} +- {two.sd[n] or float('nan'):.1e}"
                for n in ("KA2", "KB2", "KAx", "KBx")))
        return out


def run_fit(records, config: FitConfig, *, sensitivity: bool = False) -> FitResult:
    """Calibrate two accelerometers tumbled on a dividing head (one record, or two with
    opposite OA signs for the two-orientation fit)."""
    c = config.validate()
    if not 1 <= len(records) <= 2:
        raise InputError("give one record, or two for the two-orientation fit")
    reds = [prepare(r, g_local=c.g_local) for r in records]
    res = fit(reds, replace(c, sensitivity=sensitivity), truth=records[0].meta.get("truth"))
    return FitResult(res=res, settings=c.written(), sha256=records[0].sha256)


@dataclass(frozen=True)
class DesignConfig(Config):
    """Settings of ``dual design`` (bounds checked by the design itself, with the
    candidate count)."""

    positions: int = setting(20, help="Number of positions (7 to 360).")
    range_deg: tuple[float, float] = setting((0.0, 360.0), help="Allowed angle range LO HI "
                                                                "(deg).", lo=-720.0, hi=720.0)
    step_deg: float = setting(1.0, help="Candidate grid step (deg; at most 3601 candidates).")


@dataclass
class DesignResult(ResultBase):
    """``dual design``: the D-optimal positions beside the equally spaced ones."""

    res: dict
    settings: dict
    units = {"positions_deg": "deg"}

    def to_json(self) -> dict:
        return self.res

    def artifacts(self) -> dict:
        return {}

    def summary_rows(self) -> list:
        c, e = self.res["criteria"], self.res["equally_spaced"]["criteria"]
        keys = ("log_det", "a_trace_inv", "e_min_eig", "cond")
        return ["positions (deg): " + " ".join(f"{a:g}" for a in self.res["positions_deg"]),
                (None, ["design", "log det (D)", "trace inv (A)", "min eig (E)", "cond"],
                 [["D-optimal", *(c[k] for k in keys)],
                  ["equally spaced", *(e[k] for k in keys)]]),
                self.res["note"]]


def run_design(config: DesignConfig) -> DesignResult:
    """D-optimal dividing-head positions for the identifiable g^2 harmonic model."""
    c = config.validate()
    res = design(c.positions, range_deg=c.range_deg, step_deg=c.step_deg)
    return DesignResult(res=res, settings=c.to_dict())
