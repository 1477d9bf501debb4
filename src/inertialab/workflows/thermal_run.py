"""``thermal fit`` as one call (spec 000; docs/thermal.md): :class:`FitConfig` (the
settings the command line offers, with their bounds) and ``run_fit(record, config) ->
FitResult`` whose result knows ``to_json()``, ``settings``, ``units``, ``artifacts()``
(the saved model, one model per method, Tables 1 and 2, the bias/scale-factor table)
and ``summary_rows()``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from inertialab.config import Config, seed_setting, setting
from inertialab.errors import InputError
from inertialab.result import ResultBase
from inertialab.units import THERMAL_UNITS

if TYPE_CHECKING:  # the study's floors load when a command runs, not for --help
    from inertialab.workflows import thermal as wf

__all__ = ["ApplyConfig", "ApplyResult", "ExportConfig", "ExportResult", "FitConfig", "FitResult",
           "run_apply", "run_export", "run_fit"]

_CHOICES = ("iafsa-scm-anfis", "scm-anfis", "anfis", "fis", "ann", "poly-sep", "poly-2d",
            "all")


def methods_from(method: str) -> tuple[str, ...]:
    """The methods of a ``method`` text: one name, a comma list, or ``all``."""
    from inertialab.workflows import thermal as wf

    m = method.strip().lower()
    if m == "all":
        return wf.METHODS
    parts = tuple(p.strip() for p in m.split(",") if p.strip())
    bad = [p for p in parts if p not in _CHOICES or p == "all"]
    if not parts or bad:
        raise InputError(f"argument 'method' must be one of {', '.join(_CHOICES)} (or a "
                         f"comma-separated list), got '{method}'")
    return parts


@dataclass(frozen=True)
class FitConfig(Config):
    """Settings of ``thermal fit``."""

    method: str = setting("iafsa-scm-anfis", help="iafsa-scm-anfis | scm-anfis | anfis | fis | "
                                                  "ann | poly-sep | poly-2d | all (or a comma "
                                                  "list)")
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
    # visual, step and crowd lie in (0, 1]: checked with that message by ThermalConfig
    visual: float = setting(0.30, help="IAFSA initial visual range, unit-cube units (0.30).")
    step: float = setting(0.10, help="IAFSA initial step, unit-cube units (0.10).")
    try_number: int = setting(5, help="IAFSA prey attempts (5).", lo=1, hi=1000)
    crowd: float = setting(0.618, help="IAFSA crowd factor (0.618).")
    seed: int = seed_setting("Random seed (same seed, same numbers).")

    def thermal_config(self) -> wf.ThermalConfig:
        from inertialab.workflows import thermal as wf

        methods = methods_from(self.method)
        if "poly-sep" in methods and (self.learn_drift or self.input == "raw"):
            raise InputError("poly-sep needs argument 'input' ua without argument "
                             "'learn_drift'")
        return wf.ThermalConfig(methods=methods, split=self.split, target=self.target,
                                input=self.input, learn_drift=self.learn_drift,
                                radii=self.radii, fish=self.fish, generations=self.generations,
                                epochs=self.epochs, search_epochs=self.search_epochs,
                                fish_visual=self.visual, fish_step=self.step,
                                fish_try_number=self.try_number, fish_crowd=self.crowd,
                                seed=self.seed).validate()


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
        from inertialab.workflows import thermal as wf

        r, u = self.result, {"temp": "degC", "output": "mV"}
        models = [("model.json", r.models[r.model_method], u)]
        models += [(f"models/{m}.json", mod, u) for m, mod in r.models.items()]
        files = {}
        for name, table, title in (
                ("table1", r.table1(), "Table 1: fish-swarm parameters"),
                ("table2", r.table2(), f"Table 2: test errors per model ({self.settings['split']}"
                                       f" split, {r.test_index.size} test samples)")):
            files[f"{name}.csv"] = table.to_csv(index=False)
            files[f"{name}.md"] = wf.markdown_table(table, title=title)
        files["bias_scale_factor.csv"] = wf.bias_scale_factor_table(self.bsf).to_csv(index=False)
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
    from inertialab.workflows import thermal as wf

    c = config.validate()
    cfg = c.thermal_config()
    samples = wf.prepare(record, cfg)
    result = wf.fit(samples, cfg, progress=progress)
    settings = {"method": list(cfg.methods), "split": c.split, "target": c.target,
                "input": c.input, "learn_drift": c.learn_drift, "radii": c.radii,
                "fish": c.fish, "generations": c.generations, "epochs": c.epochs,
                "search_epochs": c.search_epochs, "visual": c.visual, "step": c.step,
                "try_number": c.try_number, "crowd": c.crowd, "seed": c.seed,
                "reference_temp_c": samples.reference_temp_c}
    return FitResult(result=result, samples=samples, own=result.own_drift(),
                     bsf=wf.bias_scale_factor(samples), settings=settings,
                     sha256=record.sha256)


# -------------------------------------------------------------------------- apply

@dataclass(frozen=True)
class ApplyConfig(Config):
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
    from inertialab.workflows import thermal as wf

    c = config.validate()
    flags = refuse_or_flag(thermal_findings(model), "thermal", force=c.force, path=source)
    res = wf.apply(model, record, reference=c.reference, source=source)
    if flags:
        res.meta["flags"] = flags
    return ApplyResult(res=res, out=out, settings={"reference": c.reference.strip().lower(),
                                                   "force": c.force},
                       sha256=record.sha256, model=model)


# ------------------------------------------------------------------------- export

@dataclass(frozen=True)
class ExportConfig(Config):
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
        from inertialab.io.exporters import get

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
    from inertialab.workflows import thermal as wf

    c = config.validate()
    ex = wf.export(model, prefix=c.prefix, unit_record=unit_record)
    return ExportResult(ex=ex, mapped=unit_record is not None, settings=c.to_dict())
