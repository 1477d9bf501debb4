"""``simulate KIND`` as one call per rig: each rig's settings as a :class:`Config`
(flags, help, bounds) and the function that turns the virtual lab's output into
:class:`Written`: the record(s) to write at ``--out`` (data and sidecar), the files
beside them, the JSON keys and the summary line.

The rigs themselves live in :mod:`inertialab.sim` (only the command line and the studies
import it); :mod:`inertialab.cli.simulate` runs the rig with these settings and hands
its output here. Units: seconds, hertz, degrees and g as the flag names say.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from inertialab.config import Config, seed_setting, setting
from inertialab.errors import InputError
from inertialab.result import ResultBase

__all__ = ["DualTumbleConfig", "FerrarisSessionConfig", "FogVibrationConfig",
           "GyroStaticConfig", "StorageDriftConfig", "ThermalTumbleConfig",
           "TriaxialPosesConfig", "Written", "dual_tumble", "ferraris_session", "fog_vibration",
           "gyro_static", "storage_drift",
           "thermal_tumble", "triaxial_poses"]


@dataclass
class Written(ResultBase):
    """What a ``simulate`` command writes and reports: ``records`` ``[(path, frame,
    meta)]``, ``files`` ``{path: text}``, the JSON keys (``payload``), ``settings``,
    ``units`` and the one summary ``line``."""

    payload: dict
    settings: dict
    line: str
    records: list
    files: dict = field(default_factory=dict)
    units: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return self.payload

    def artifacts(self) -> dict:
        return {"records": self.records, "files": self.files}

    def summary_rows(self) -> list:
        return [self.line]


# ------------------------------------------------------------------ thermal tumble (spec 000)

@dataclass(frozen=True)
class ThermalTumbleConfig(Config):
    """Settings of ``simulate thermal-tumble``."""

    preset: str = setting("paper", help="paper | realistic")
    lot_seed: int = setting(0, help="Seed of the lot and its units.", lo=0, hi=2**63 - 1)
    unit: int = setting(0, help="Unit index within the lot.", lo=0)
    seed: int | None = seed_setting("Run-noise seed (default: the lot seed).", default=None)
    ramp: str = setting("up", help="up | up_down")


def thermal_tumble(run, c: ThermalTumbleConfig, out: Path) -> Written:
    """A thermal tumble record (``TumbleRun`` of the rig)."""
    n = int(len(run.frame))
    return Written(
        payload={"out": str(out), "n_rows": n, "unit_id": run.unit.unit_id,
                 "noise_floor_ug": run.noise_floor_ug, "noise_only_ug": run.noise_only_ug},
        settings={"preset": c.preset, "lot_seed": c.lot_seed, "unit": c.unit,
                  "seed": run.meta["seed"], "ramp": c.ramp},
        line=f"written: {out} ({n} rows, unit {run.unit.unit_id}, noise floor "
             f"{run.noise_floor_ug:.2f} µg)", records=[(out, run.frame, run.meta)])


# ------------------------------------------------------------- FOG at rest (Allan family)

@dataclass(frozen=True)
class GyroStaticConfig(Config):
    """Settings of ``simulate gyro-static``."""

    preset: str = setting("allan-test", help="allan-test | allan-rrw | allan-bi | mid | nav | "
                                             "tactical.")
    hours: float = setting(1.0, help="Record length in hours.", lo=1e-6, hi=1e4)
    rate: float = setting(10.0, help="Output rate in Hz.", lo=1e-9, hi=1e9)
    seed: int = seed_setting()


def gyro_static(r, c: GyroStaticConfig, out: Path) -> Written:
    """A FOG at rest with known Q N B K R (``GyroStaticRun`` of the rig)."""
    return Written(
        payload={"output": str(out), "n_samples": len(r.record),
                 "truth_terms": r.meta["truth_terms"]},
        settings={"preset": c.preset, "hours": c.hours, "rate_hz": c.rate, "seed": c.seed},
        line=f"wrote {out} ({len(r.record)} samples at {c.rate:g} Hz, preset {c.preset})",
        records=[(out, r.record, r.meta)], units={"n_samples": "1"})


# ------------------------------------------------------------------ FOG vibration (spec 001)

@dataclass(frozen=True)
class FogVibrationConfig(Config):
    """Settings of ``simulate fog-vibration``."""

    experiment: str = setting("fixed", help="sweep (E1, 1-500 Hz log sweep) | fixed (E2, "
                                            "500 Hz).", choices=("sweep", "fixed"))
    seed: int = seed_setting()
    preset: str = setting("mid", help="FOG grade: mid | nav | tactical.")
    truth: Path | None = setting(None, help="Also write the truth table (CSV) here.")
    p1_s: float | None = setting(None, help="P1 duration, s (default 1800).", lo=0, hi=1e6)
    p3_s: float | None = setting(None, help="P3 duration, s (default 1800).", lo=0, hi=1e6)
    p2_s: float | None = setting(None, help="Fixed-run P2 duration, s (default 1800).",
                                 lo=0, hi=1e6)
    acc_g: float | None = setting(None, help="Acceleration amplitude, g peak (default 5).",
                                  lo=0, hi=1_000)
    sweep_oct_per_min: float | None = setting(None, help="Sweep rate, octaves per minute "
                                                         "(default 1).")

    def overrides(self) -> dict:
        """The rig's overrides that were given (``p2_s`` is the fixed run's P2)."""
        return {k: v for k, v in (("p1_s", self.p1_s), ("p3_s", self.p3_s),
                                  ("p2_fixed_s", self.p2_s), ("acc_g", self.acc_g),
                                  ("sweep_oct_per_min", self.sweep_oct_per_min))
                if v is not None}


def fog_vibration(r, c: FogVibrationConfig, out: Path) -> Written:
    """A FOG-on-a-shaker record (``FogVibrationRun``) and, with ``truth``, its truth table."""
    files = ({} if c.truth is None else
             {c.truth: r.truth.to_csv(index=False, lineterminator="\n")})
    return Written(
        payload={"output": str(out), "n_samples": len(r.record), "t_on_s": r.meta["t_on_s"],
                 "t_off_s": r.meta["t_off_s"]},
        settings={"experiment": c.experiment, "seed": c.seed, "preset": c.preset,
                  **c.overrides()},
        line=f"wrote {out} ({len(r.record)} samples, P2 {r.meta['t_on_s']:g}-"
             f"{r.meta['t_off_s']:g} s)",
        records=[(out, r.record, r.meta)], files=files,
        units={"t_on_s": "s", "t_off_s": "s"})


# --------------------------------------------------------------- triaxial poses (spec 002)

@dataclass(frozen=True)
class TriaxialPosesConfig(Config):
    """Settings of ``simulate triaxial-poses``."""

    scenario: str = setting("turntable62", help=(
        "sphere1000-clean | sphere100-clean | sphere1000-noisy | turntable62 | "
        "turntable62-mount | turntable62-realistic | sixface | rawlog62 | rawlog62-gyro | "
        "rawlog62-counts | line5000"))
    seed: int = seed_setting()
    g_local: float = setting(9.8, help="Gravity of the virtual rig, m/s^2 (paper: 9.8).",
                             lo=1, hi=100)
    n_units: int = setting(5000, help="Units in line5000.", lo=1, hi=1_000_000)


def triaxial_poses(rec, c: TriaxialPosesConfig, out: Path) -> Written:
    """A triaxial-poses record; a raw log also writes ``<stem>.schedule.csv``."""
    from inertialab.io.sidecar import schedule_path

    meta, files = dict(rec.meta), {}
    if rec.schedule is not None:
        files[schedule_path(out)] = rec.schedule[["pos_id", "pitch_deg", "heading_deg"]] \
            .to_csv(index=False, lineterminator="\n")
    written = [str(out)] + [str(p) for p in files]
    opts = {"n_units": c.n_units} if c.scenario == "line5000" else {}
    return Written(
        payload={"written": written, "scenario": c.scenario, "rows": int(len(rec.data)),
                 "kind": rec.kind, "seed": c.seed, "true_params": meta.get("true_params"),
                 **opts},
        settings={"scenario": c.scenario, "seed": c.seed, "g_local": c.g_local},
        line="written: " + ", ".join(written), records=[(out, rec.data, meta)], files=files,
        units={"true_params": "m/s^2 (b), 1 (k), rad (theta)"})


@dataclass(frozen=True)
class FerrarisSessionConfig(Config):
    """Settings of ``simulate ferraris-session``."""

    seed: int = seed_setting()
    placement_deg: float = setting(2.0, help="Hand-placement tilt per axis, deg (1 sigma).",
                                   lo=0, hi=45)
    angle_sigma_deg: float = setting(1.0, help="Error of each 360-deg turn, deg (1 sigma).")
    counts: bool = setting(False, help="16-bit counts instead of m/s^2, deg/s.")


def ferraris_session(rec, c: FerrarisSessionConfig, out: Path) -> Written:
    """A Ferraris session record and its true sections (``<stem>.sections.json``)."""
    sp = out.with_name(out.name.split(".")[0] + ".sections.json")
    written = [str(out), str(sp)]
    return Written(
        payload={"written": written, "rows": int(len(rec.data)), "seed": c.seed,
                 "senses": rec.truth["senses"].tolist(),
                 "angles_deg": [float(v) for v in np.rad2deg(rec.truth["angles_rad"])]},
        settings={"seed": c.seed, "placement_deg": c.placement_deg,
                  "angle_sigma_deg": c.angle_sigma_deg, "counts": c.counts},
        line="written: " + ", ".join(written), records=[(out, rec.data, rec.meta)],
        files={sp: json.dumps(rec.truth["sections"], indent=1) + "\n"},
        units={"angles_deg": "deg"})


# ------------------------------------------------------------------- dual tumble (spec 003)

@dataclass(frozen=True)
class DualTumbleConfig(Config):
    """Settings of ``simulate dual-tumble``."""

    scenario: str = setting("S1", help="S0 ... S5 (the virtual-lab scenarios of docs/dual.md).")
    seed: int = seed_setting(default=20240603)
    h: float | None = setting(None, help="Head-error scale (S2 sweep; default 1).")
    positions: int | None = setting(None, help="Positions per pass (S4).", lo=1, hi=100_000)
    draw_unit: bool = setting(False, help="Draw the unit around table 6.1 and write its "
                                          "historical prior as <stem>.prior.json.")

    def overrides(self) -> dict:
        """The scenario's overrides that were given."""
        return {k: v for k, v in (("h", self.h), ("n_positions", self.positions))
                if v is not None}


def dual_tumble(runs: list, cfg, c: DualTumbleConfig, out: Path) -> Written:
    """The dual-tumble record(s) of scenario ``cfg`` (S5: ``<stem>_orient2`` too) and,
    with ``draw_unit``, the unit's historical prior."""
    from inertialab.workflows.dual import UNITS, prior_from_history

    paths = [out] + [out.with_name(f"{out.stem}_orient{i + 1}{out.suffix}")
                     for i in range(1, len(runs))]
    for p in paths:
        if p.is_dir():
            raise InputError("is a directory, not a record file", path=p)
    records = [(p, r.to_frame(), {**r.meta, "seed": c.seed, "truth": r.truth})
               for r, p in zip(runs, paths)]
    files = {}
    if c.draw_unit and "history" in runs[0].head:
        pj = {"schema": "inertialab.prior/1", "kind": "history",
              "coef": prior_from_history(runs[0].head["history"])}
        files[out.with_name(out.stem + ".prior.json")] = json.dumps(pj, indent=2) + "\n"
    written = [str(p) for p in paths] + [str(p) for p in files]
    return Written(
        payload={"written": written, "truth": runs[0].truth},
        settings={"scenario": cfg.scenario, "seed": c.seed, "h": cfg.h,
                  "n_positions": cfg.n_positions, "draw_unit": c.draw_unit},
        line="written: " + ", ".join(written), records=records, files=files, units=UNITS)


# ------------------------------------------------------------------ storage drift (spec 004)

@dataclass(frozen=True)
class StorageDriftConfig(Config):
    """Settings of ``simulate storage-drift``."""

    preset: str = setting("paper", help="paper | nav")
    units: int = setting(12, help="Number of accelerometers.", lo=1, hi=10_000)
    days: int = setting(120, help="Programme length in days.", lo=1, hi=36_500)
    seed: int = seed_setting()
    no_outliers: bool = setting(False, help="No ±8σ outliers.")
    missing_prob: float | None = setting(None, help="Probability a day is missing "
                                                    "(default 0.05).")
    skip_weekends: bool = setting(False, help="No tests on Saturdays and Sundays.")

    def validate(self):
        if self.missing_prob is not None and not 0.0 <= self.missing_prob < 1.0:
            raise InputError(f"argument 'missing_prob' must lie in [0, 1), got "
                             f"{self.missing_prob}")
        return super().validate()


def storage_drift(batch, c: StorageDriftConfig, out: Path) -> Written:
    """A storage programme's record with ground-truth columns."""
    n = len(batch.frame)
    return Written(
        payload={"path": str(out), "rows": n, "units": c.units, "days": c.days,
                 "preset": c.preset},
        settings={"preset": c.preset, "units": c.units, "days": c.days, "seed": c.seed,
                  "outliers": not c.no_outliers, "missing_prob": c.missing_prob,
                  "skip_weekends": c.skip_weekends},
        line=f"written: {out} ({n} tests of {c.units} units, preset {c.preset})",
        records=[(out, batch.frame, batch.meta)], units={"days": "day"})
