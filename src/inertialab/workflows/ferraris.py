"""Workflow ``ferraris``: a Ferraris calibration session -> model.

- :func:`prepare` (record -> :class:`FerrarisSession`): raw accelerometer and gyro
  columns of a ``triaxial_raw`` record, the sample rate (from ``t_s`` or the header's
  ``fs_hz``), local gravity and the nine sections: from imucal's section list (argument
  ``sections``: a dict or a JSON file) or detected from the accelerometer and the gyro
  (:func:`inertialab.calib.ferraris.detect_sections`).
- :func:`fit` (session, :class:`FerrarisConfig` -> :class:`FerrarisRun`): the estimator of
  :mod:`inertialab.calib.ferraris`, its plausibility checks (refused unless ``force``),
  and the model, a :class:`~inertialab.calib.ferraris.FerrarisCalibration` (model type
  ``ferraris-calibration``, a triaxial calibration with a typed gyro block) that
  :func:`inertialab.workflows.triaxial.apply` applies.

The command ``triaxial ferraris`` is one call: :class:`FerrarisConfig` (the settings of
:func:`prepare` and :func:`fit` too) and ``run_ferraris(record, config) ->
FerrarisResult``. The estimator (:mod:`inertialab.calib.ferraris`, scipy) and the
record floor (pandas) are imported inside the functions, so that ``--help`` starts light.
"""

from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from inertialab import units
from inertialab.config import Config as _Settings
from inertialab.config import setting
from inertialab.errors import DataQualityWarning, InputError
from inertialab.result import ResultBase
from inertialab.workflows.triaxial import _acc_cols, _g_from, _gyro_cols, _matrix_lines

if TYPE_CHECKING:
    from inertialab.calib import ferraris as fr
    from inertialab.io.readers import Record

__all__ = ["FerrarisConfig", "FerrarisResult", "FerrarisRun", "FerrarisSession", "fit",
           "prepare", "result_payload", "result_units", "run_ferraris"]


def __getattr__(name: str):
    """``Config``, the fit's settings before :class:`FerrarisConfig` was the one class,
    with a DeprecationWarning."""
    if name == "Config":
        warnings.warn("inertialab.workflows.ferraris.Config is deprecated: use FerrarisConfig "
                      "(no_g_sensitivity, bias_limit_mps2 in place of g_sensitivity, limits)",
                      DeprecationWarning, stacklevel=2)
        return FerrarisConfig
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass(frozen=True)
class FerrarisSession:
    """Raw arrays of a Ferraris session and its sections (``{name: (start, end)}``)."""

    acc: np.ndarray
    gyro: np.ndarray
    t: np.ndarray
    fs: float
    g: float
    acc_unit: str
    gyro_unit: str
    sections: dict
    detection: fr.Detection | None = None
    meta: dict = dataclasses.field(default_factory=dict)


def _nominal(suffix: str, *, g: float) -> float | None:
    """Raw units per SI unit for a known unit; None for counts."""
    if suffix == "lsb":
        return None
    return 1.0 / float(units.to_si(1.0, suffix, g_local=g))


def prepare(record: Record, *, sections=None, g_local: float | None = None) -> FerrarisSession:
    """Record -> :class:`FerrarisSession`.

    ``sections``: imucal's section list as a dict, or the path of its JSON file; None
    detects them from the accelerometer and the gyro.
    """
    from inertialab.calib import ferraris as fr
    from inertialab.io.record import naming
    from inertialab.workflows.preflight import preflight

    preflight(record, "ferraris")  # the checks `validate --kind ferraris` runs
    acols = _acc_cols(record)
    gcols = _gyro_cols(record)
    if gcols is None:
        raise InputError("a Ferraris session needs gyro columns gx, gy, gz (with a unit suffix)",
                         path=record.path)
    if "t_s" not in record.data.columns:
        raise InputError("a Ferraris session is a continuous log: it needs a time column t_s",
                         path=record.path)
    meta = dict(record.meta)
    g = _g_from(meta, g_local)
    t = record.column("t_s").astype(float)
    tb = record.timebase  # the one time base, decided on reading (io.timestamps)
    if tb is None or tb.back_rows:
        raise InputError("time stamps must increase", path=record.path, column="t_s",
                         row=list(tb.back_rows) if tb is not None else None)
    fs = tb.rate_hz
    acc = record.data[acols].to_numpy(dtype=float)
    gyro = record.data[gcols].to_numpy(dtype=float)
    det = None
    if sections is None:
        with naming(record.path):  # every error names the file
            det = fr.detect_sections(acc, gyro, fs)
        secs = det.sections
    elif isinstance(sections, dict):
        secs = fr.sections_from_dict(sections, len(acc))
    else:
        secs = fr.load_sections(sections, len(acc))
    return FerrarisSession(acc=acc, gyro=gyro, t=t, fs=fs, g=g,
                           acc_unit=units.split_suffix(acols[0])[1],
                           gyro_unit=units.split_suffix(gcols[0])[1], sections=secs,
                           detection=det, meta=meta)


@dataclass(frozen=True)
class FerrarisConfig(_Settings):
    """Settings of ``triaxial ferraris`` and of :func:`fit`: the turn angle (deg, sense
    detected), the accelerometer face refinement and its placement tilt (deg), the
    g-sensitivity, the plausibility bound ``bias_limit_mps2`` with ``force`` (write a
    refused fit flagged)."""

    sections: str | None = setting(None, help="imucal section list (JSON {\"x_p\": {\"start\": "
                                              "i, \"end\": j}, ..., \"z_rot\": ...}); default: "
                                              "detected from the accelerometer and the gyro.")
    rotation_deg: float = setting(360.0, help="Angle of every turn (the sense is detected).",
                                  unit="deg", lo=1.0, hi=3600.0)
    placement_deg: float = setting(2.0, help="Standard deviation of a face's hand-placement "
                                             "tilt.", unit="deg", lo=0.0, hi=45.0)
    no_g_sensitivity: bool = setting(False, help="Do not estimate the gyro's g-sensitivity.")
    g_local: float | None = setting(None, help="Local gravity (else header, else 9.80665 with "
                                               "a warning).", unit="m/s^2", lo=1.0, hi=100.0)
    unit: str | None = setting(None, help="Unit of suffix-less ax/ay/az (mps2 | g | lsb).")
    bias_limit_mps2: float | None = setting(None, help="Largest plausible |accelerometer "
                                                       "bias|.", unit="m/s^2", flag="bias-limit",
                                            lo=0.0, hi=1e6)
    force: bool = setting(False, help="Write an implausible calibration anyway, flagged.")
    refine: bool = setting(True, help="Refine the accelerometer on the six faces (placement "
                                      "tilt).", cli=False)


@dataclass(frozen=True)
class FerrarisRun:
    """The model, the fit and the session it came from."""

    model: fr.FerrarisCalibration
    fit: fr.FerrarisFit
    session: FerrarisSession


def fit(session: FerrarisSession, config: FerrarisConfig | None = None) -> FerrarisRun:
    """Calibrate accelerometer and gyro from the session (refused when implausible)."""
    from inertialab.calib import ferraris as fr
    from inertialab.calib.triaxial_checks import ImplausibleCalibrationError, Limits, refusal

    config = config or FerrarisConfig()
    f = fr.fit_ferraris(session.acc, session.gyro, session.fs, session.sections, g=session.g,
                        rotation_deg=config.rotation_deg, refine=config.refine,
                        placement_rad=float(np.deg2rad(config.placement_deg)),
                        g_sensitivity=not config.no_g_sensitivity)
    model = fr.to_model(f, acc_unit=session.acc_unit, gyro_unit=session.gyro_unit, g=session.g,
                        n_samples=len(session.acc))
    findings = fr.check_ferraris(f, acc_nominal=_nominal(session.acc_unit, g=session.g),
                                 gyro_nominal=_nominal(session.gyro_unit, g=session.g),
                                 g=session.g, limits=Limits(bias=config.bias_limit_mps2))
    if findings:
        if not config.force:
            raise ImplausibleCalibrationError(refusal(findings))
        flags = [x.text() for x in findings]
        warnings.warn("calibration written flagged: " + " | ".join(flags), DataQualityWarning,
                      stacklevel=2)
        model = dataclasses.replace(model, flags=flags)
    return FerrarisRun(model=model, fit=f, session=session)


def result_payload(run: FerrarisRun) -> dict:
    """The JSON result of a Ferraris calibration (``result.json`` and ``--json``).

    Besides the model: the sections used (imucal's format), how they were found, the
    turns' senses and axes, each face's calibrated |a| - g and tilt, and for known gyro
    units each turn's angle as the raw gyro (nominal sensitivity) integrates it.
    """
    from inertialab.calib import ferraris as fr

    f, s = run.fit, run.session
    d = run.model.to_dict()
    gn = _nominal(s.gyro_unit, g=s.g)
    out = {
        "method": "ferraris", "params": d["params"], "stderr": d["stderr"],
        "correction_matrix": d["correction_matrix"], "offset": d["offset"],
        "raw_unit": d["raw_unit"], "g_local": s.g, "fs_hz": s.fs, "gyro": d["gyro"],
        "sections": fr.sections_to_dict(s.sections),
        "sections_detected": s.detection is not None,
        "faces": {name: {"norm_error_mps2": float(f.faces.norm_residual[i]),
                         "tilt_deg": float(np.rad2deg(f.faces.tilt_rad[i]))}
                  for i, name in enumerate(fr.FACE_SECTIONS)},
        "turns": {name: {"sense": int(f.senses[j]), "axis": f.turn_axes[j].tolist(),
                         "raw_angle_deg": None if gn is None else
                         float(np.rad2deg(np.linalg.norm(f.integrated[j]) / gn))}
                  for j, name in enumerate(fr.ROT_SECTIONS)},
        "gyro_static_rms": f.gyro_static_rms, "rotation_deg": f.rotation_deg,
        "flags": d["flags"], "ci95": _intervals(run),
    }
    return out


def _intervals(run: FerrarisRun) -> dict:
    """95 % intervals: accelerometer (b, k, theta) from the face fit's covariance (its
    residuals are in units of their stated sigmas, so normal quantiles), gyro bias and
    g-sensitivity from the static least squares (Student t, 2 degrees of freedom per axis:
    six faces, four unknowns). The gyro T_g is exactly determined by three turns: no
    interval (its error is the turn-angle error, see docs/ferraris.md)."""
    from scipy import stats

    out = {}
    for name, v in run.model.params.items():
        se = (run.model.stderr or {}).get(name)
        if se is not None and np.isfinite(se):
            out[name] = [float(v - 1.959964 * se), float(v + 1.959964 * se)]
    cov = run.fit.cov_gyro_static
    if cov is not None:
        t = float(stats.t.ppf(0.975, 2))
        se = np.sqrt(np.maximum(np.diag(cov), 0.0))
        vals = np.r_[run.fit.b_g, run.fit.K_ga.ravel()]
        names = [f"bg{c}" for c in "xyz"] + [f"kga{i + 1}{j + 1}" for i in range(3)
                                             for j in range(3)]
        for n, v, s in zip(names, vals, se):
            out[n] = [float(v - t * s), float(v + t * s)]
    return out


def result_units(run: FerrarisRun) -> dict:
    s = run.session
    return {"correction_matrix": f"m/s^2 per {s.acc_unit}", "offset": s.acc_unit,
            "gyro.correction_matrix": f"rad/s per {s.gyro_unit}", "gyro.offset": s.gyro_unit,
            "gyro.g_sensitivity": f"{s.gyro_unit} per m/s^2", "g_local": "m/s^2",
            "fs_hz": "Hz", "sections": "sample index [start, end)",
            "gyro_static_rms": s.gyro_unit, "faces.norm_error_mps2": "m/s^2"}


@dataclass
class FerrarisResult(ResultBase):
    """``triaxial ferraris``: the run (:class:`~inertialab.workflows.ferraris.FerrarisRun`)."""

    run: object
    session: object
    settings: dict
    name: str = ""
    sha256: str | None = None

    @property
    def units(self) -> dict:
        return result_units(self.run)

    def to_json(self) -> dict:
        return result_payload(self.run)

    def artifacts(self) -> dict:
        import json

        return {"models": [("model.json", self.run.model, self.units)],
                "files": {"sections.json": json.dumps(self.to_json()["sections"], indent=1)
                          + "\n"}}

    def summary_rows(self) -> list:
        p, s = self.to_json(), self.session
        how = "detected" if s.detection is not None else f"from {self.settings['sections']}"
        out = [f"triaxial ferraris: {self.name}, sections {how}, {s.fs:g} Hz, g = {s.g:g}",
               ("faces", ["face", "|a| - g (m/s^2)", "tilt (deg)"],
                [[n, f"{d['norm_error_mps2']:+.2e}", f"{d['tilt_deg']:.2f}"]
                 for n, d in p["faces"].items()])]
        for n, d in p["turns"].items():
            sense = "counterclockwise" if d["sense"] > 0 else "clockwise"
            out.append(f"{n}: {sense} seen from above, axis ("
                       + ", ".join(f"{v:+.3f}" for v in d["axis"]) + ")")
        out += _matrix_lines("accelerometer: a = correction_matrix @ (raw - offset)   [m/s^2]",
                             p["correction_matrix"])
        out += _matrix_lines("gyro: rate = M_g @ (raw - offset - g_sensitivity @ a)   [rad/s]",
                             p["gyro"]["correction_matrix"])
        return out + [f"FLAGGED: {flag}" for flag in self.run.model.flags]


def run_ferraris(record, config: FerrarisConfig, *, name: str = "", progress=None):
    """Accelerometer (12 parameters) and gyro (scale, misalignment, bias, g-sensitivity)
    from six static faces and a turn about each axis."""
    c = config.validate()
    session = prepare(record, sections=c.sections, g_local=c.g_local)
    if progress is not None:
        progress.update(0.5, 1.0, "sections ready")
    run = fit(session, c)
    settings = {"sections": c.sections, "rotation_deg": c.rotation_deg,
                "placement_deg": c.placement_deg, "g_sensitivity": not c.no_g_sensitivity,
                "g_local": session.g, "unit": c.unit, "bias_limit_mps2": c.bias_limit_mps2,
                "force": c.force}
    return FerrarisResult(run=run, session=session, settings=settings, name=name,
                          sha256=record.sha256)
