"""Identifiability and plausibility of a triaxial calibration.

A fit that returns numbers is not a calibration: with poses that do not span the sphere,
a raw log whose rotations were taken for rests, or data in the wrong unit, least squares
still converges, to a model with bx = -162 m/s^2 and kx = 165. :func:`check_run` finds
such fits and says, per parameter, what is wrong and what to add:

- **not identifiable**: cond(J^T J) of the column-scaled Jacobian above
  :data:`~inertialab.calib.triaxial.COND_FLAG` (1e8, spec 002 §7.3); the parameters named
  are those carrying the weak directions (|component| > 0.3 of a right singular vector
  whose singular value is below s_max / sqrt(1e8)); the remedy names the gravity-up
  directions that most improve the design (:func:`suggest_orientations`). For the gyro:
  cond(J^T J) of the direction fit above 1e8, remedy: rotations about the axes whose
  columns of M_g are poorly determined.
- **implausible**: |bias| beyond the declared limit (default 0.5 g), scale factors outside
  0.5-2 (counts mode without a sensitivity: each axis' counts per m/s^2 relative to
  their median), non-orthogonality angles beyond 0.2 rad, or a pose whose calibrated
  |a| is further than the norm tolerance (default 0.02 g) from local gravity. Gyro:
  scale (relative to the sensitivity stated or found in the data) outside 0.5-2,
  misalignment beyond 0.2 rad, |bias| beyond the gyro bias limit (default 0.35 rad/s =
  20 deg/s).

**Counts logs** (``lsb``): the bias of a counts log is an ADC offset. Its zero is that
of the ADC's range (:func:`adc_range`: signed, zero at 0; unsigned, zero at mid-scale
2^(bits-1), 32768 for 16 bits), declared (``Limits.adc``, e.g. ``{"bits": 16, "signed":
false}``) or detected from the raw values (unsigned when no value is negative; the
fewest of 8-32 bits that hold them). A bias is judged as its offset from that zero:
against a quarter of the half range in counts, and, converted with the sensitivity,
against the physical limit; a refusal names the range and the zero it used.

The defaults are physical bounds for MEMS parts, not tolerances of a good
calibration: they catch garbage, not a mediocre unit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from inertialab.calib.triaxial import COND_FLAG, CalibrationFit, suggest_orientations
from inertialab.errors import ImplausibleCalibrationError, InputError  # noqa: F401 - re-exported
from inertialab.sensors import triaxial as tx

SCALE_RANGE = (0.5, 2.0)
"""Plausible scale factors."""
ANGLE_LIMIT = 0.2
"""Plausible |non-orthogonality| and |gyro misalignment|, rad."""
BIAS_LIMIT_G = 0.5
"""Default accelerometer bias limit, in units of local gravity."""
NORM_TOL_G = 0.02
"""Default tolerance on | |a_cal| - g | per pose, in units of local gravity."""
GYRO_BIAS_LIMIT = 0.35
"""Default gyro bias limit, rad/s (20 deg/s)."""
ADC_BIAS_FRACTION = 0.25
"""A counts bias further than this fraction of the half range from the ADC zero is
implausible (a zero-rate or zero-g output a quarter of full scale off)."""
_ADC_BITS = (8, 10, 12, 14, 16, 18, 20, 22, 24, 32)


@dataclass(frozen=True)
class AdcRange:
    """An ADC's output range: ``bits``, ``signed``, and whether it was ``declared`` or
    ``detected``; its zero (0 signed, 2^(bits-1) unsigned) and half range 2^(bits-1)."""

    bits: int
    signed: bool
    source: str = "detected"

    @property
    def zero(self) -> float:
        return 0.0 if self.signed else float(2 ** (self.bits - 1))

    @property
    def half(self) -> float:
        return float(2 ** (self.bits - 1))

    def text(self) -> str:
        return (f"{'signed' if self.signed else 'unsigned'} {self.bits}-bit ADC "
                f"({self.source}), zero at {self.zero:.0f}")


def adc_range(raw, declared=None) -> AdcRange:
    """The ADC range of counts ``raw`` (any shape): ``declared`` (an :class:`AdcRange` or
    ``{"bits": int, "signed": bool}``) when given, else detected (see the module text)."""
    if isinstance(declared, AdcRange):
        return declared
    if declared is not None:
        from inertialab.io.sidecar import check_adc

        d = check_adc(declared)  # "16" or "no" refused: bool("no") is True
        return AdcRange(d["bits"], d["signed"], "declared")
    v = np.asarray(raw, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return AdcRange(16, True)
    signed = bool(v.min() < 0)
    top = max(abs(float(v.min())), abs(float(v.max())))
    for bits in _ADC_BITS:
        if (signed and top <= 2 ** (bits - 1)) or (not signed and top < 2 ** bits):
            return AdcRange(bits, signed)
    return AdcRange(32, signed)


def _adc_finding(offset, adc: AdcRange, names) -> Finding | None:
    """The finding of counts biases further than a quarter of the half range from the
    ADC zero, or None."""
    lim = ADC_BIAS_FRACTION * adc.half
    bad = [(n, o) for n, o in zip(names, offset) if not np.isfinite(o) or abs(o) > lim]
    if not bad:
        return None
    return Finding("implausible", tuple(n for n, _ in bad),
                   ", ".join(f"{n} = {o:+.6g}" for n, o in bad) + " counts from the ADC "
                   f"zero ({adc.text()}) beyond ±{lim:.6g} counts",
                   "declare the ADC range (signed or unsigned, bits) if it differs")


@dataclass(frozen=True)
class Limits:
    """Bounds of :func:`check_run`; ``None`` takes the defaults of the module."""

    bias: float | None = None
    norm_tol: float | None = None
    gyro_bias: float | None = None
    scale: tuple = SCALE_RANGE
    angle: float = ANGLE_LIMIT
    cond: float = COND_FLAG
    adc: object = None  # AdcRange or {"bits", "signed"} of a counts log; None: detected


@dataclass(frozen=True)
class Finding:
    """One problem: the parameters concerned, what is wrong, and what to do."""

    kind: str  # "not identifiable" | "implausible"
    parameters: tuple
    what: str
    remedy: str = ""

    def text(self) -> str:
        s = f"{self.kind}: {', '.join(self.parameters)} ({self.what})"
        return s + (f"; {self.remedy}" if self.remedy else "")


def _fmt_dir(d) -> str:
    return "(" + ", ".join(f"{v:+.2f}" for v in d) + ")"


def weak_parameters(J: np.ndarray, names, cond_limit: float = COND_FLAG):
    """``(cond, names)``: cond(J^T J) of the column-scaled Jacobian and the parameters that
    carry its weak directions (see the module docstring)."""
    J = np.asarray(J, dtype=float)
    d = np.sqrt(np.sum(J * J, axis=0))
    d[d == 0] = 1.0
    s, vt = np.linalg.svd(J / d, full_matrices=False)[1:]
    if s[0] <= 0:
        return float("inf"), tuple(names)
    cond = float((s[0] / s[-1]) ** 2) if s[-1] > 0 else float("inf")
    weak = s < s[0] / np.sqrt(cond_limit)
    picked = [n for i, n in enumerate(names) if np.any(np.abs(vt[weak, i]) > 0.3)]
    # a column of zeros (a parameter the data never touch) is weak too
    zero = np.sum(np.asarray(J) ** 2, axis=0) == 0
    picked += [n for i, n in enumerate(names) if zero[i] and n not in picked]
    return cond, tuple(picked)


def accel_jacobian(fit: CalibrationFit, a, ref, g):
    """Jacobian of the fit's residual at its solution (the records the fit used)."""
    a = np.asarray(a, dtype=float)
    xp = fit.x if fit.phi is None else np.r_[fit.x, fit.phi]
    if fit.method == "six-position":
        rows = np.asarray(fit.extra["face_rows"], dtype=int)
        return tx.jacobian(xp, a[rows], objective="scalar", g=g, ref=ref[rows])
    obj = "norm" if fit.method == "ellipsoid" else fit.objective
    return tx.jacobian(xp, a, objective=obj, g=g, ref=ref if obj in ("scalar", "scalar12") else None)


def check_accel(fit: CalibrationFit, a, ref, g: float, *, counts: bool = False,
                limits: Limits | None = None) -> list[Finding]:
    """Findings for the accelerometer part of a fit (working unit: m/s^2 or counts)."""
    lim = limits or Limits()
    out: list[Finding] = []
    names = list(tx.PARAM_NAMES) + (list(tx.PHI_NAMES) if fit.phi is not None else [])
    try:
        J = accel_jacobian(fit, a, ref, g)
        cond, weak = weak_parameters(J, names, lim.cond)
    except (KeyError, ValueError, np.linalg.LinAlgError):
        cond, weak = float("inf"), tuple(names)
    if not np.isfinite(cond) or cond > lim.cond:
        remedy = "add poses spread over the sphere"
        try:
            sug = suggest_orientations(fit.x, a, g=g, objective=fit.objective, n=3)
            remedy = ("add poses with gravity-up along " + ", ".join(_fmt_dir(d) for d in sug)
                      + " in the sensor frame")
        except (InputError, ValueError, np.linalg.LinAlgError):
            pass
        out.append(Finding("not identifiable", weak or tuple(names),
                           f"cond(J^T J) = {cond:.3g} > {lim.cond:.0e}", remedy))
    x = np.asarray(fit.x, dtype=float)
    k = x[3:6]
    adc_note = ""
    if counts:
        ref_k = float(np.median(np.abs(k)))
        rel = k / ref_k if ref_k > 0 else np.full(3, np.nan)
        adc = adc_range(a, lim.adc)
        b = x[:3] - adc.zero  # the bias of a counts log is an offset from the ADC's zero
        found = _adc_finding(b, adc, [f"b{c}" for c in "xyz"])
        if found is not None:
            out.append(found)
        bias_si = b / np.where(k != 0, k, np.nan)
        scale_what = "counts per m/s^2 relative to the median axis"
        adc_note = f" ({adc.text()})"
    else:
        rel = k
        bias_si = x[:3]
        scale_what = "scale factor"
    bias_lim = lim.bias if lim.bias is not None else BIAS_LIMIT_G * g
    bad = [f"b{c} = {b:.4g} m/s^2" for c, b in zip("xyz", bias_si)
           if not np.isfinite(b) or abs(b) > bias_lim]
    if bad:
        out.append(Finding("implausible", tuple(s.split(" ")[0] for s in bad),
                           f"{'; '.join(bad)}{adc_note} beyond the bias limit "
                           f"±{bias_lim:.3g} m/s^2",
                           "check the accelerometer unit and argument 'bias_limit_mps2'"))
    lo, hi = lim.scale
    bad = [f"k{c} = {r:.4g}" for c, r in zip("xyz", rel) if not np.isfinite(r) or not lo <= r <= hi]
    if bad:
        out.append(Finding("implausible", tuple(s.split(" ")[0] for s in bad),
                           f"{'; '.join(bad)}: {scale_what} outside {lo:g}-{hi:g}",
                           "check the accelerometer unit (argument 'unit') and the poses"))
    th = x[6:9]
    bad = [f"{n} = {v:.4g} rad" for n, v in zip(tx.PARAM_NAMES[6:9], th)
           if not np.isfinite(v) or abs(v) > lim.angle]
    if bad:
        out.append(Finding("implausible", tuple(s.split(" ")[0] for s in bad),
                           f"{'; '.join(bad)} beyond ±{lim.angle:g} rad", "add poses"))
    tol = lim.norm_tol if lim.norm_tol is not None else NORM_TOL_G * g
    cor = tx.correct(x, np.asarray(a, dtype=float))
    err = np.abs(np.linalg.norm(cor, axis=1) - g)
    if err.size and (not np.all(np.isfinite(err)) or err.max() > tol):
        worst = int(np.nanargmax(err)) if np.any(np.isfinite(err)) else 0
        n_bad = int(np.sum(~(err <= tol)))
        out.append(Finding("implausible", ("|a|",),
                           f"{n_bad} of {err.size} poses off local gravity by more than "
                           f"{tol:.3g} m/s^2 after calibration (worst: pose {worst + 1}, "
                           f"{err[worst]:.3g} m/s^2)",
                           "check that every detected interval is a rest (argument 't_init_s', argument "
                           "'k_thr') and argument 'norm_tol_mps2'"))
    return out


def check_gyro(gfit, nominal: np.ndarray, *, limits: Limits | None = None,
               raw=None) -> list[Finding]:
    """Findings for a gyro fit (``gfit`` with ``matrix``, ``bias``, ``cond``,
    ``stderr_matrix``); ``nominal`` is the nominal raw -> rad/s matrix (M0), the
    sensitivity stated or found in the data. ``raw``: the raw gyro samples of a counts
    log (their ADC range gives the zero the bias is an offset from)."""
    lim = limits or Limits()
    out: list[Finding] = []
    M = np.asarray(gfit.matrix, dtype=float)
    M0 = np.asarray(nominal, dtype=float)
    rel = M @ np.linalg.inv(M0)
    names = [f"m{i + 1}{j + 1}" for i in range(3) for j in range(3)]
    cond = float(gfit.cond)
    if not np.isfinite(cond) or cond > lim.cond:
        se = None if gfit.stderr_matrix is None else np.asarray(gfit.stderr_matrix) @ np.abs(
            np.linalg.inv(M0))
        cols = [0, 1, 2]
        if se is not None and np.all(np.isfinite(se)):
            poor = sorted({j for i in range(3) for j in range(3) if se[i, j] > 0.05})
            cols = poor or cols
        which = tuple(n for n in names if int(n[2]) - 1 in cols)
        out.append(Finding("not identifiable", which,
                           f"gyro cond(J^T J) = {cond:.3g} > {lim.cond:.0e}",
                           "add rotations about the sensor's "
                           + ", ".join("xyz"[j] for j in cols) + " axis"
                           + ("es" if len(cols) > 1 else "")))
    lo, hi = lim.scale
    d = np.diag(rel)
    bad = [f"m{i + 1}{i + 1} = {d[i]:.4g}" for i in range(3)
           if not np.isfinite(d[i]) or not lo <= d[i] <= hi]
    if bad:
        out.append(Finding("implausible", tuple(s.split(" ")[0] for s in bad),
                           f"gyro scale {'; '.join(bad)} (relative to nominal) outside {lo:g}-{hi:g}",
                           "check the gyro unit and the rotations"))
    off = rel - np.diag(d)
    bad = [f"m{i + 1}{j + 1} = {off[i, j]:.4g}" for i in range(3) for j in range(3)
           if i != j and (not np.isfinite(off[i, j]) or abs(off[i, j]) > lim.angle)]
    if bad:
        out.append(Finding("implausible", tuple(s.split(" ")[0] for s in bad),
                           f"gyro misalignment {'; '.join(bad)} beyond ±{lim.angle:g} rad",
                           "add rotations about all three axes"))
    offset = np.asarray(gfit.bias, dtype=float)
    adc_note = ""
    if raw is not None or lim.adc is not None:
        adc = adc_range(raw if raw is not None else offset, lim.adc)
        offset = offset - adc.zero  # a counts bias is an offset from the ADC's zero
        adc_note = f" ({adc.text()})"
        found = _adc_finding(offset, adc, [f"bg{c}" for c in "xyz"])
        if found is not None:
            out.append(found)
            return out
    b = M0 @ offset
    blim = lim.gyro_bias if lim.gyro_bias is not None else GYRO_BIAS_LIMIT
    bad = [f"bg{c} = {v:.4g} rad/s" for c, v in zip("xyz", b) if not np.isfinite(v) or abs(v) > blim]
    if bad:
        out.append(Finding("implausible", tuple(s.split(" ")[0] for s in bad),
                           f"{'; '.join(bad)}{adc_note} beyond ±{blim:.3g} rad/s",
                           "start the log at rest (argument 't_init_s')"))
    return out


def refusal(findings: list[Finding]) -> str:
    """The one-line message of a refused fit."""
    return ("calibration refused, nothing written: " + " | ".join(f.text() for f in findings)
            + "; set argument 'force' to write it flagged")
