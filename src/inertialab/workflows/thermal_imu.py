"""``thermal fit --imu`` and ``thermal apply`` of a ``thermal-imu`` model (docs/thermal-imu.md):
a drone's temperature-ramp log in, per sensor instance and axis the temperature model of
the offset, the PX4 and ArduPilot parameter files, and corrected logs.

- :func:`run_imu_fit` (``log, config -> ImuFitResult``): the fit of
  :func:`inertialab.calib.thermal_imu.fit_imu_model` with the command's settings
  (``thermal fit``'s Config as :func:`imu_config` gives it), its per-axis report (order, lag,
  residual RMS in-sample and held-out, temperature span, samples per °C, hysteresis),
  ``model.json`` and ``report.csv``/``report.md``.
- :func:`write_exports`: ``--export px4 FILE`` / ``--export ardupilot FILE`` through
  the exporter registry (kind ``thermal-imu``).
- :func:`run_imu_apply` (``model, log -> ImuApplyResult``): the six corrected columns
  (same names as the table format) per instance, at the accelerometer's time stamps (a
  gyro logged at other instants is interpolated linearly), clamped outside the
  calibrated range with a warning.

This module never reads files, draws or imports the virtual lab.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from inertialab.config import Config, seed_setting, setting
from inertialab.errors import InputError
from inertialab.result import ResultBase

if TYPE_CHECKING:  # pandas and the fit load when a command runs, not when it starts
    import pandas as pd

__all__ = ["EXPORT_HELP", "EXPORT_TARGETS", "FIT_SETTINGS_TAKEN", "given",
           "ImuApplyResult", "ImuFitResult", "ThermalImuSimConfig", "fit_settings",
           "imu_config", "pair_exports", "report_table", "run_imu_apply", "run_imu_fit",
           "simulated", "write_exports"]

EXPORT_TARGETS = ("px4", "ardupilot")
#: Help of the export option of ``thermal fit`` (its IMU switch is ``FitConfig.imu``).
EXPORT_HELP = "With the IMU switch: px4 | ardupilot, its FILE after the log (repeatable)."
#: The fit settings of ``thermal fit`` the IMU fit takes when given (else its defaults).
FIT_SETTINGS_TAKEN = ("method", "epochs", "fish", "generations")


def given(source_of) -> set:
    """The names of :data:`FIT_SETTINGS_TAKEN` the user gave; ``source_of(name)`` is the
    command line's parameter source (its ``name`` is ``DEFAULT`` when not given)."""
    return {k for k in FIT_SETTINGS_TAKEN if getattr(source_of(k), "name", "DEFAULT") != "DEFAULT"}


def imu_config(config, given):
    """``thermal fit``'s ``config`` as the IMU fit takes it: each setting of
    :data:`FIT_SETTINGS_TAKEN` the user did not give (``given``: the names given) takes the
    IMU fit's default (:class:`~inertialab.calib.thermal_imu.FitSettings`: poly, 50
    epochs, 5 fish, 5 generations; the ANFIS study's 150/10/30 would cost minutes per
    axis); checked by those settings' rules (one-line error naming the argument)."""
    from dataclasses import replace

    from inertialab.calib.thermal_imu import FitSettings

    imu_default = FitSettings()
    out = replace(config, **{k: getattr(imu_default, k) for k in FIT_SETTINGS_TAKEN
                             if k not in given})
    FitSettings.of(out)
    return out


def pair_exports(targets, files) -> list:
    """``--export TARGET FILE`` pairs from the targets and the files given after them;
    one-line error for an unknown target or a missing file."""
    targets, files = list(targets or ()), list(files or ())
    if files and not targets:
        raise InputError(f"unexpected argument {str(files[0])[:60]!r}")
    if len(targets) != len(files):
        raise InputError("argument 'export' takes a target and a file each time "
                         f"(px4 FILE), got targets {targets} and files {files}")
    out = []
    for t, f in zip(targets, files):
        t = str(t).strip().lower()
        if t not in EXPORT_TARGETS:
            raise InputError(f"argument 'export' must be one of {', '.join(EXPORT_TARGETS)}, "
                             f"got {t[:40]!r}")
        out.append((t, f))
    return out


def report_table(model) -> pd.DataFrame:
    """One row per sensor axis: order, tau (s), residual RMS in-sample and held-out
    (reading units), span (°C), samples per °C, hysteresis before and after the lag
    term, the order-3 form kept for the firmware and its held-out RMS, and the scale
    factor's tempco at mid-range (ppm/°C; an accelerometer logged in several
    orientations only)."""
    import pandas as pd

    from inertialab.calib.thermal_imu import UNITS

    rows = []
    for s in model.sensors:
        for ax, form in zip(s["axes"], s["px4"]["forms"]):
            rows.append({"sensor": s["kind"], "instance": s["instance"],
                         "device_id": s["device_id"], "axis": ax["axis"],
                         "unit": UNITS[s["kind"]], "method": model.method,
                         "order": ax["order"] if ax.get("anfis") is None else None,
                         "tau_s": ax["tau_s"], "rms_in": ax["rms_in"], "rms_cv": ax["rms_cv"],
                         "span_c": s["span_c"], "t_min_c": s["t_min"], "t_max_c": s["t_max"],
                         "samples_per_c": s["samples_per_c"],
                         "hysteresis": ax["hysteresis"],
                         "hysteresis_without_lag": ax["hysteresis_tau0"],
                         "firmware_form": form, "firmware_rms_cv": ax["form_rms"][form],
                         "scale_ppm_per_c": None if ax.get("scale") is None else
                         1e6 * ax["scale"][1] / s["half"]})
    return pd.DataFrame(rows)


def _markdown(table: pd.DataFrame) -> str:
    head = ("| sensor | axis | order | tau s | RMS in | RMS held-out | span °C | samples/°C | "
            "hysteresis (no lag term) | order-3 form, held-out RMS |")
    lines = [head, "|---" * 10 + "|"]
    fmt = lambda v: "–" if v is None or (isinstance(v, float) and np.isnan(v)) else f"{v:.3g}"  # noqa: E731
    for r in table.itertuples():
        lines.append(f"| {r.sensor} {r.instance} | {r.axis} | {fmt(r.order)} | {r.tau_s:g} | "
                     f"{fmt(r.rms_in)} | {fmt(r.rms_cv)} | {r.span_c:.1f} | "
                     f"{r.samples_per_c:.0f} | {fmt(r.hysteresis)} "
                     f"({fmt(r.hysteresis_without_lag)}) | {r.firmware_form} "
                     f"{fmt(r.firmware_rms_cv)} |")
    return "\n".join(lines) + "\n"


@dataclass
class ImuFitResult(ResultBase):
    """``thermal fit --imu``: the fit (:class:`~inertialab.calib.thermal_imu.ImuFit`) and
    its report table."""

    fit: object
    table: pd.DataFrame
    settings: dict
    sha256: str | None = None
    exports: list = field(default_factory=list)
    units = {"temperature": "degC", "accel": "m/s^2", "gyro": "rad/s", "tau": "s"}

    @property
    def warnings(self) -> list:
        return list(self.fit.warnings)

    def to_json(self) -> dict:
        return {"method": self.fit.model.method, "source": self.fit.model.source,
                "axes": self.table.replace({np.nan: None}).to_dict(orient="records"),
                "exports": self.exports}

    def artifacts(self) -> dict:
        return {"models": [("model.json", self.fit.model, dict(self.units))],
                "files": {"report.csv": self.table.to_csv(index=False),
                          "report.md": _markdown(self.table)}}

    def summary_rows(self) -> list:
        t = self.table
        rows = [[f"{r.sensor} {r.instance}", r.axis, "–" if r.order is None else r.order,
                 r.tau_s, f"{r.rms_in:.3g}", f"{r.rms_cv:.3g}", f"{r.span_c:.1f}",
                 f"{r.samples_per_c:.0f}",
                 "–" if r.hysteresis is None or np.isnan(r.hysteresis) else f"{r.hysteresis:.2g}",
                 f"{r.firmware_form} {r.firmware_rms_cv:.3g}"] for r in t.itertuples()]
        return [(f"drone IMU thermal fit ({self.fit.model.method}; SI units: m/s^2, rad/s)",
                 ["sensor", "axis", "order", "tau s", "RMS in", "RMS held-out", "span °C",
                  "samples/°C", "hysteresis", "order-3 form (held-out RMS)"], rows)]


def run_imu_fit(log, config, *, exports=(), caltemp_c: float | None = None
                ) -> ImuFitResult:
    """Fit every sensor instance of a read log (module docstring) with ``config``, the
    command's settings read by their flags' names (``thermal fit``'s Config as
    :func:`imu_config` gives it, or any object with the names of
    :class:`~inertialab.calib.thermal_imu.FitSettings`; what it lacks takes the defaults
    there), and write the ``exports`` ``(target, path)`` pairs (:func:`pair_exports`)."""
    from inertialab.calib.thermal_imu import fit_imu_model

    fit = fit_imu_model(log, config)
    for s in fit.model.sensors:
        if s["span_c"] < 30.0:
            fit.warnings.append(f"{s['kind']} {s['instance']}: the log spans only "
                                f"{s['span_c']:.1f} °C; outside it the firmware clamps")
    used = fit.settings
    st = {"imu": True, "method": used.method, "bin_s": used.bin_s,
          "max_order": used.max_order, "min_span_c": used.min_span_c,
          "n_blocks": used.n_blocks, "seed": used.seed}
    if used.method != "poly":
        st.update(epochs=used.epochs, fish=used.fish, generations=used.generations)
    res = ImuFitResult(fit=fit, table=report_table(fit.model), settings=st, sha256=log.sha256)
    res.exports = write_exports(fit.model, exports, caltemp_c=caltemp_c)
    return res


def write_exports(model, pairs, *, caltemp_c: float | None = None) -> list:
    """Write each ``(target, path)`` through the exporter registry; returns the paths."""
    from inertialab.export import get

    out = []
    for target, path in pairs:
        out += get("thermal-imu", target).write(model, path, {"caltemp_c": caltemp_c})
    return out


@dataclass
class ImuApplyResult(ResultBase):
    """``thermal apply`` of a ``thermal-imu`` model: the corrected table to write."""

    frame: pd.DataFrame
    out: object
    n_outside: dict
    settings: dict
    sha256: str | None = None
    units = {"accel": "m/s^2", "gyro": "rad/s", "temperature": "degC"}

    @property
    def warnings(self) -> list:
        return [f"{k}: {v} samples outside the calibrated temperature range (clamped there, "
                f"as the firmware does)" for k, v in self.n_outside.items() if v]

    def to_json(self) -> dict:
        return {"out": str(self.out), "n_rows": int(len(self.frame)),
                "outside_calibrated_range": self.n_outside}

    def artifacts(self) -> dict:
        meta = {"source": "inertialab thermal apply (thermal-imu)", "units": self.units}
        return {"records": [(self.out, self.frame, meta)]}

    def summary_rows(self) -> list:
        n = sum(self.n_outside.values())
        return [f"corrected {len(self.frame)} rows ({n} sensor samples clamped) -> {self.out}"]


def _instance_frame(model, inst: int, streams: dict) -> pd.DataFrame:
    import pandas as pd

    from inertialab.calib.thermal_imu import AXES

    acc, gyr = streams.get(("accel", inst)), streams.get(("gyro", inst))
    base = acc if acc is not None else gyr
    frame = {"instance": np.full(base.t_s.size, inst), "t_s": base.t_s, "temp_c": base.temp_c}
    for kind, st in (("accel", acc), ("gyro", gyr)):
        names = [f"{a}_mps2" if kind == "accel" else f"{a}_rps" for a in AXES[kind]]
        if st is None:
            continue
        corr, _ = model.correct(model.sensor(kind, inst), st.t_s, st.temp_c, st.values)
        for a, name in enumerate(names):
            frame[name] = (corr[:, a] if st is base else np.interp(base.t_s, st.t_s, corr[:, a]))
    return pd.DataFrame(frame)


def run_imu_apply(model, log, *, out, source: str | None = None) -> ImuApplyResult:
    """Correct every sensor of ``log`` that the model knows (by kind and instance)."""
    import pandas as pd

    streams = {(s.kind, s.instance): s for s in log.streams}
    known = {(s["kind"], s["instance"]) for s in model.sensors}
    missing = sorted(set(streams) - known)
    if missing:
        raise InputError(f"the model has no {missing[0][0]} {missing[0][1]} (it has "
                         + ", ".join(f"{k} {i}" for k, i in sorted(known)) + ")",
                         path=log.path)
    n_outside = {}
    for (kind, inst), st in streams.items():
        _, n = model.correct(model.sensor(kind, inst), st.t_s, st.temp_c, st.values)
        n_outside[f"{kind} {inst}"] = n
    frames = [_instance_frame(model, i, streams) for i in sorted({i for _, i in streams})]
    return ImuApplyResult(frame=pd.concat(frames, ignore_index=True), out=out,
                          n_outside=n_outside, settings={"model": source},
                          sha256=log.sha256)


def fit_settings(config, given):
    """Deprecated (:class:`DeprecationWarning`): :func:`run_imu_fit` takes the command's
    Config itself; ``imu_config(config, given)`` gives it with the IMU fit's defaults.
    Returns that as a :class:`~inertialab.calib.thermal_imu.FitSettings`."""
    import warnings

    from inertialab.calib.thermal_imu import FitSettings

    warnings.warn("fit_settings is deprecated: pass imu_config(config, given) to run_imu_fit",
                  DeprecationWarning, stacklevel=2)
    return FitSettings.of(imu_config(config, given))


@dataclass(frozen=True)
class ThermalImuSimConfig(Config):
    """Settings of ``simulate thermal-imu``."""

    unit_seed: int = setting(0, help="Seed of the board (its IMUs' temperature models).",
                             lo=0, hi=2**63 - 1)
    ramp: str = setting("calibration", help="calibration | holdout | heat",
                        choices=("calibration", "holdout", "heat"))
    rate: float = setting(10.0, help="Logged samples per second per sensor.", lo=0.01, hi=1000)
    instances: int = setting(2, help="IMU instances (1 or 2).", lo=1, hi=2)
    faces: int = setting(1, help="1: level; 6: turned through six faces every 120 s "
                                 "(accelerometer scale factors drift too).", choices=(1, 6))
    seed: int | None = seed_setting("Run-noise seed (default: the unit seed).", default=None)


def simulated(log, ulog_bytes, c: ThermalImuSimConfig, out):
    """``simulate thermal-imu``: the table record at ``out`` and the same log as a PX4
    ULog at ``<stem>.ulg`` (``ulog_bytes(log)``, written here, beside the record)."""
    from pathlib import Path

    from inertialab.io.writers import atomic_write_bytes
    from inertialab.workflows.simulate import Written

    ulg = Path(out).with_suffix(".ulg")
    atomic_write_bytes(ulg, ulog_bytes(log))
    return Written(payload={"out": str(out), "ulog": str(ulg), "n_rows": int(len(log.frame))},
                   settings=c.to_dict(), records=[(out, log.frame, log.meta)],
                   line=f"written: {out} and {ulg} ({len(log.frame)} rows, ramp {c.ramp})")
