"""``vibration fit`` as one call (spec 001; docs/vibration.md): :class:`FitConfig` and
``run_fit(sweep, fixed, config) -> FitResult`` whose result knows ``to_json()`` (the
``--json`` keys and the metrics), ``settings``, ``units``, ``artifacts()`` (the model)
and ``summary_rows()``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from inertialab.config import Config, seed_setting, setting
from inertialab.errors import InputError
from inertialab.result import ResultBase

if TYPE_CHECKING:  # the study's floors load when a command runs, not for --help
    from inertialab.workflows import vibration as wf

__all__ = ["ApplyConfig", "ApplyResult", "FitConfig", "FitResult", "run_apply", "run_fit"]

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


@dataclass(frozen=True)
class FitConfig(Config):
    """Settings of ``vibration fit``."""

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

    def vibration_config(self, *, views: bool) -> wf.VibrationConfig:
        from inertialab.workflows import vibration as wf

        return wf.VibrationConfig(level=_level(self.level), spread=_spread(self.spread),
                                  goal=self.goal, centers=self.centers, targets=self.targets,
                                  rng=self.seed, views=views)


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
    from inertialab.workflows import vibration as wf

    c = config.validate()
    cfg = c.vibration_config(views=views)
    sweep = wf.prepare(sweep_record)
    fixed = wf.prepare(fixed_record) if fixed_record is not None else None
    return FitResult(wf.fit(sweep, fixed, cfg, progress), sha256=sweep_record.sha256)


@dataclass(frozen=True)
class ApplyConfig(Config):
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
    from inertialab.workflows import vibration as wf

    c = config.validate()
    res = wf.apply(model, record, model_name=c.model, apply_to=c.apply_to,
                   model_path=None if model_path is None else str(model_path))
    return ApplyResult(res=res, out=out, settings=c.to_dict())
