"""``batch CMD --inputs GLOB`` as one prepared job and one call: :class:`BatchConfig`
(the settings the command line offers), :func:`parse_tolerance` (the pass/fail rules),
:func:`prepare` (command, files and rules checked before any work) and :func:`run`
(:func:`inertialab.workflows.batch.run_batch` on Dask) -> :class:`BatchRun`, whose
``artifacts()`` are ``units.csv`` and ``summary.json`` (docs/batch.md).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from inertialab.config import Config, setting
from inertialab.errors import InputError
from inertialab.jsonable import to_jsonable
from inertialab.result import ResultBase

if TYPE_CHECKING:  # the study's floors load when a command runs, not for --help
    from inertialab.workflows import batch as wb

__all__ = ["BatchConfig", "BatchJob", "BatchRun", "parse_tolerance", "prepare", "run"]

#: The commands a batch runs (and their old spellings, one release) -> the runner's name.
ALIASES = {"allan": "allan", "triaxial fit": "calibrate-triaxial",
           "thermal apply": "thermal-compensate",
           "calibrate-triaxial": "calibrate-triaxial", "calibrate triaxial": "calibrate-triaxial",
           "thermal-compensate": "thermal-compensate", "thermal compensate": "thermal-compensate"}

_CHECK = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_.]*)\s*(<=|>=|<|>|=)\s*(.+?)\s*$")


def _check(raw: str) -> wb.Check:
    from inertialab.workflows import batch as wb

    s, is_abs = raw.strip(), False
    m_abs = re.match(r"^abs\(\s*([^)]+?)\s*\)(.*)$", s)
    if m_abs:
        is_abs, s = True, m_abs.group(1) + m_abs.group(2)
    m = _CHECK.match(s)
    if m is None:
        raise InputError(f"argument 'tolerance': {raw.strip()!r} is not KEY<=VALUE, "
                         "KEY>=VALUE or KEY=LO..HI")
    key, op, val = m.groups()
    try:
        if op == "=":
            lo, hi = (_finite(v) for v in val.split(".."))
            if lo > hi:
                raise ValueError
            return wb.Check(key, lo, hi, is_abs)
        if op in ("<=", "<"):
            return wb.Check(key, hi=_finite(val), abs=is_abs)
        return wb.Check(key, lo=_finite(val), abs=is_abs)
    except ValueError:
        raise InputError(f"argument 'tolerance': bad number or range in "
                         f"{raw.strip()!r} (bounds are finite numbers)") from None


def _finite(text: str) -> float:
    """A rule's bound: a finite number (``nan`` or ``inf`` would make the rule always
    fail or always pass)."""
    v = float(text)
    if not math.isfinite(v):
        raise ValueError(text)
    return v


def parse_tolerance(text: str | Sequence[str] | None) -> tuple:
    """The pass/fail rules of ``"adev_1s<=0.01,abs(bx)<=0.05,kx=0.99..1.01"`` (repeated
    texts or a list are joined) as :class:`inertialab.workflows.batch.Check` rules."""
    if text is None:
        return ()
    parts = [text] if isinstance(text, str) else list(text)
    return tuple(_check(raw) for part in parts for raw in str(part).split(",") if raw.strip())


@dataclass(frozen=True)
class BatchConfig(Config):
    """Settings of ``batch``."""

    scheduler: str = setting("local", help="local (a LocalCluster), serial (no Dask), or a "
                                           "scheduler address tcp://host:8786.")
    workers: int = setting(2, help="Worker processes of the LocalCluster.", lo=1, hi=256)
    tolerance: list[str] | None = setting(None, help="Pass/fail rules: KEY<=V, KEY>=V, "
                                                     "abs(KEY)<=V, KEY=LO..HI (comma-separated "
                                                     "or repeated).")
    strict: bool = setting(False, help="Exit 2 when any unit could not be processed.")
    unit: str | None = setting(None, help="Unit suffix for columns without one.")
    rate: float | None = setting(None, help="Sample rate in Hz (allan).", lo=1e-9, hi=1e9)
    gaps: str = setting("error", help="error | split (allan logs).", choices=("error", "split"))
    g_local: float | None = setting(None, help="Local gravity, m/s^2.", lo=1.0, hi=100.0)
    model: Path | None = setting(None, help="Model file (thermal compensate).")


@dataclass(frozen=True)
class BatchJob:
    """A checked batch: the command's name, the files, the rules and the per-unit
    options (the reading options in their plain-text form, for the workers)."""

    name: str
    paths: list
    checks: tuple
    options: dict
    config: BatchConfig


def prepare(command: Sequence[str], inputs, config: BatchConfig, read) -> BatchJob:
    """Check a batch before any work: the command (``allan``, ``triaxial fit``, ``thermal
    apply``), the files of the ``inputs`` globs, the rules and the model file; ``read``
    (:class:`~inertialab.io.mapping.ReadOptions`, built and checked once here: a bad map
    is one error, not one per unit)."""
    from inertialab.workflows import batch as wb

    c = config.validate()
    name = ALIASES.get(" ".join(command).strip().lower())
    if name is None:
        raise InputError(f"batch: unknown command '{' '.join(command)}' (allan, triaxial fit, "
                         "thermal apply)")
    paths = wb.expand_inputs(inputs)
    checks = parse_tolerance(c.tolerance)
    if c.unit is not None:
        from inertialab.io.mapping import parse_unit_option

        parse_unit_option(c.unit)  # ',,' or an unknown unit: one line, before any unit
    options = {k: v for k, v in {
        "map": read.column_map.to_text() or None, "sep": read.parse.sep,
        "decimal": read.parse.decimal, "skip_rows": read.parse.skip_rows, "unit": c.unit,
        "rate": c.rate, "gaps": c.gaps if name == "allan" else None, "g_local": c.g_local,
        "model": str(c.model) if c.model else None}.items() if v is not None}
    if c.model is not None and not Path(c.model).is_file():
        raise InputError("no such model file", path=c.model)
    if c.model is not None and name == "thermal-compensate":  # once, before any unit
        from inertialab.calib.model_checks import refuse_or_flag, thermal_findings
        from inertialab.workflows.registries import load_model

        model = load_model(c.model, expected_type="thermal-compensation")
        refuse_or_flag(thermal_findings(model), "thermal", force=False, path=c.model,
                       forceable=False)
    return BatchJob(name=name, paths=paths, checks=checks, options=options, config=c)


@dataclass
class BatchRun(ResultBase):
    """The fleet's :class:`~inertialab.workflows.batch.BatchResult` and its settings."""

    res: object
    settings: dict
    units = {"wall_s": "s", "yield": "1"}

    @property
    def warnings(self) -> list:
        return [f"unit {u.unit}: {u.reason}" for u in self.res.units if u.status == "error"]

    def to_json(self) -> dict:
        return {"summary": self.res.summary(), "units": [u.to_dict() for u in self.res.units]}

    def artifacts(self) -> dict:
        return {"files": {"units.csv": self.res.table().to_csv(index=False),
                          "summary.json": json.dumps(to_jsonable(self.res.to_dict()),
                                                     indent=2, allow_nan=False)}}

    def summary_rows(self) -> list:
        res, s = self.res, self.res.summary()
        keys = [k for k in res.figure_keys() if k not in ("n_samples", "n_positions")][:6]
        rows = [[u.unit, u.status, *[u.figures.get(k) for k in keys],
                 "; ".join(u.failed) or u.reason] for u in res.units]
        return [(f"batch {self.settings['command']}: {s['n_pass']}/{s['n_units']} pass "
                 f"(yield {100 * s['yield']:.1f} %)", ["unit", "status", *keys, "why"], rows)]


def run(job: BatchJob, *, progress=None) -> BatchRun:
    """Run the job's command on every file (Dask, or serially); with ``strict`` a unit
    that could not be processed fails the whole batch (one line)."""
    from inertialab.workflows import batch as wb

    c = job.config
    res = wb.run_batch(job.name, job.paths, options=job.options, checks=job.checks,
                       scheduler=c.scheduler, workers=c.workers, progress=progress)
    errors = [u for u in res.units if u.status == "error"]
    if errors and c.strict:
        raise InputError(f"{len(errors)} of {len(res.units)} units could not be processed "
                         f"(argument 'strict'); first: {errors[0].unit}: {errors[0].reason}")
    settings = {"command": job.name, "scheduler": c.scheduler, "workers": c.workers,
                "tolerance": [k.text() for k in job.checks], "strict": c.strict,
                **job.options}
    return BatchRun(res=res, settings=settings)
