"""``dual fit`` as one call (spec 003; docs/dual.md): :class:`FitConfig` and
``run_fit(records, config) -> FitResult`` whose result knows ``to_json()``,
``settings``, ``units``, ``warnings`` (the fit's own), ``artifacts()`` (the model) and
``summary_rows()``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from inertialab.config import Config, setting
from inertialab.errors import InputError
from inertialab.result import ResultBase

if TYPE_CHECKING:  # the study's floors load when a command runs, not for --help
    from inertialab.workflows import dual as wf

__all__ = ["DesignConfig", "DesignResult", "FitConfig", "FitResult", "run_design", "run_fit"]

#: Display factor and unit of each coefficient in the summary table.
_SCALE = {"KA0": (1e6, "ug"), "KB0": (1e6, "ug"), "kA1": (1e6, "ppm"),
          "kB1": (1e6, "ppm"), "eta": (1e6, "urad"), "KA2": (1e6, "ug/g^2"),
          "KB2": (1e6, "ug/g^2"), "KAx": (1e6, "ug/g^2"), "KBx": (1e6, "ug/g^2")}


@dataclass(frozen=True)
class FitConfig(Config):
    """Settings of ``dual fit``."""

    method: str = setting("all", help="ebr | ls | single-ls | ridge-hkb | ridge-gcv | all")
    prior: str = setting("none", help="none (paper: beta0 = 0, W = I) | certificate | FILE "
                                      "(inertialab.prior/1 JSON, or a CSV of past "
                                      "calibrations)")
    ebr_rule: str = setting("E1", help="E1 (Stein) | E2 (ML) | E3 (SURE)")
    lambda_combination: str = setting("star", help="star | max | min of lambda* and lambda0")
    second_order: bool = setting(False, help="Iterated second-order correction of y (spec "
                                             "§1.5).")
    g_local: float | None = setting(None, help="Local gravity, m/s^2.", lo=1.0, hi=100.0)

    def dual_config(self, *, sensitivity: bool) -> wf.DualConfig:
        from inertialab.workflows import dual as wf

        return wf.DualConfig(methods=wf.parse_methods(self.method), prior=self.prior,
                             second_order=self.second_order, ebr_rule=self.ebr_rule,
                             lambda_combination=self.lambda_combination,
                             sensitivity=sensitivity)


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
        from inertialab.workflows import dual as wf


        return wf.UNITS

    @property
    def warnings(self) -> list:
        return list(self.res.fit.warnings)

    def to_json(self) -> dict:
        return self.res.payload()

    def artifacts(self) -> dict:
        from inertialab.workflows import dual as wf

        return {"models": [("model.json", self.res.model, wf.UNITS)]}

    def summary_rows(self) -> list:
        from inertialab.workflows import dual as wf

        fit = self.res.fit
        cols = list(fit.methods)
        rows = []
        for n, (f, u) in _SCALE.items():
            label = f"{n} = {wf.PAPER_ALIASES[n]}" if n in wf.PAPER_ALIASES else n
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
    from inertialab.workflows import dual as wf

    c = config.validate()
    if not 1 <= len(records) <= 2:
        raise InputError("give one record, or two for the two-orientation fit")
    cfg = c.dual_config(sensitivity=sensitivity)
    reds = [wf.prepare(r, g_local=c.g_local) for r in records]
    res = wf.fit(reds, cfg, truth=records[0].meta.get("truth"))
    settings = {"method": c.method.strip().lower(), "prior": c.prior,
                "ebr_rule": c.ebr_rule.upper(), "lambda_combination": c.lambda_combination.lower(),
                "second_order": c.second_order, "g_local": c.g_local, "seed": None}
    return FitResult(res=res, settings=settings, sha256=records[0].sha256)


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
    from inertialab.workflows import dual as wf

    c = config.validate()
    res = wf.design(c.positions, range_deg=c.range_deg, step_deg=c.step_deg)
    return DesignResult(res=res, settings=c.to_dict())
