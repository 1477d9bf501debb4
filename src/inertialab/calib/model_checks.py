"""A fitted model re-checked at its training conditions before it is applied.

A model file is data a user can edit: a thermal model whose regressor was scaled, or a
triaxial correction matrix multiplied by 1e6, still passes the payload schema (finite
numbers of the right shapes) and would write a "compensated" record of garbage. Each
function here evaluates the model where it was trained (the file stores that span) and
returns the findings, one line each; the apply workflows refuse a model with findings
unless ``force`` (then the output is flagged):

- **thermal** (:func:`thermal_findings`): on a 23 x 25 grid over the training span
  ``t_range_c`` x ``n_range_mv`` the correction ``|t(T, N) - N|`` must stay within twice
  the largest raw error of the training samples (``raw_drift_max_mv``; at least 0.1 % of
  the output range). The compensated error is at least ``|correction| - raw``, so a
  larger correction makes the compensated drift exceed the raw drift. Measured on the
  virtual lab's tumble: the largest grid correction is 0.97-1.08 times the raw maximum
  for ann, poly-2d, poly-sep and scm-anfis. Files written before the raw maximum was
  stored are held to 5 % of the output range (a thermal drift of 0.1 g on a +-1 g
  tumble is no drift).
- **triaxial** (:func:`triaxial_findings`): the static means the fit used (``rest_raw``,
  in the raw unit) calibrated: every |a| within the fit's default norm gate
  (:data:`~inertialab.calib.triaxial_checks.NORM_TOL_G`, 0.02 g) of ``g_local``. Files
  without ``rest_raw``: the scale of the correction matrix (its singular values, over
  the raw unit's own factor to m/s^2) within the plausible scale factors 0.5-2; for
  counts, between 1 and 2^31 counts per g.
"""

from __future__ import annotations

import warnings

import numpy as np

from inertialab.errors import DataQualityWarning, InputError

#: Grid over a thermal model's training span (temperatures x outputs).
THERMAL_GRID = (23, 25)
#: Largest correction, in units of the training raw maximum.
RAW_FACTOR = 2.0
#: Floor of the limit, and the limit of files without a stored raw maximum, as a
#: fraction of the calibrated output range.
SPAN_FLOOR, SPAN_FALLBACK = 1e-3, 0.05


def thermal_findings(model) -> list[str]:
    """Findings of a :class:`~inertialab.calib.thermal.ThermalModel` (module text)."""
    tlo, thi = (float(v) for v in model.t_range_c)
    nlo, nhi = (float(v) for v in model.n_range_mv)
    T, N = np.meshgrid(np.linspace(tlo, thi, THERMAL_GRID[0]),
                       np.linspace(nlo, nhi, THERMAL_GRID[1]))
    with np.errstate(all="ignore"):
        corr = np.abs(model.predict_nc(T.ravel(), N.ravel()) - N.ravel())
    span = f"T {tlo:.4g}..{thi:.4g} °C, N {nlo:.4g}..{nhi:.4g} mV"
    if not np.all(np.isfinite(corr)):
        return [f"non-finite output inside its training span ({span})"]
    raw = model.raw_drift_max_mv
    if raw is not None:
        limit = max(RAW_FACTOR * float(raw), SPAN_FLOOR * (nhi - nlo))
        basis = f"twice the largest raw error of its training samples ({float(raw):.4g} mV)"
    else:
        limit, basis = SPAN_FALLBACK * (nhi - nlo), "5 % of its output range"
    worst = float(corr.max())
    if worst <= limit:
        return []
    k1 = abs(float(model.ref.k1)) or 1.0
    return [f"inside its training span ({span}) it corrects the output by up to "
            f"{worst:.4g} mV ({1e3 * worst / k1:.4g} mg), beyond {basis}, {limit:.4g} mV: "
            "the compensated drift would exceed the raw drift"]


def triaxial_findings(model) -> list[str]:
    """Findings of a :class:`~inertialab.calib.triaxial.TriaxialCalibration`."""
    from inertialab.calib.triaxial_checks import NORM_TOL_G, SCALE_RANGE

    C = np.asarray(model.correction_matrix, dtype=float)
    g = float(model.g_local)
    rest = model.rest_raw
    if rest is not None and np.asarray(rest).size:
        with np.errstate(all="ignore"):
            a = (np.asarray(rest, dtype=float) - np.asarray(model.offset)) @ C.T
            dev = np.abs(np.linalg.norm(a, axis=1) - g)
        worst = int(np.nanargmax(np.where(np.isfinite(dev), dev, np.inf)))
        if not np.isfinite(dev[worst]) or dev[worst] > NORM_TOL_G * g:
            return [f"its training pose {worst + 1} at rest calibrates to |a| = "
                    f"{float(np.linalg.norm(a[worst])):.6g} m/s^2, off local gravity "
                    f"{g:g} m/s^2 by more than the {NORM_TOL_G:g} g gate"]
        return []
    with np.errstate(all="ignore"):
        sv = np.linalg.svd(C, compute_uv=False)
    if model.raw_unit == "lsb":
        per_g = g / sv
        if np.all((per_g >= 1.0) & (per_g <= 2.0 ** 31)):
            return []
        return [f"its correction matrix gives {per_g.min():.4g}..{per_g.max():.4g} counts per "
                "g, outside 1..2^31: at rest |a| would be far off local gravity"]
    from inertialab import units as U

    try:
        unit = U.convert(1.0, model.raw_unit, "mps2", g_local=g)
    except (InputError, KeyError, ValueError):
        return []
    scale = sv / unit
    lo, hi = SCALE_RANGE
    if np.all((scale >= lo) & (scale <= hi)):
        return []
    off = max(float(scale.max()), 1.0 / float(scale.min()))
    return [f"its correction matrix scales {model.raw_unit} by {scale.min():.4g}.."
            f"{scale.max():.4g} (plausible {lo:g}..{hi:g}): at rest |a| would be off local "
            f"gravity by a factor of up to {off:.3g}"]


def refuse_or_flag(findings: list[str], what: str, *, force: bool, path=None,
                   forceable: bool = True) -> list[str]:
    """Raise one :class:`InputError` naming the model file for ``findings`` unless
    ``force``; with ``force`` warn and return the flags the output carries.
    ``forceable``: whether the caller offers ``force`` (the message says so)."""
    if not findings:
        return []
    text = f"the {what} model is implausible at its training conditions: " + \
        " | ".join(findings)
    if not force:
        raise InputError(text + ("; set argument 'force' to apply it anyway" if forceable
                                 else ""), path=path)
    warnings.warn(text + " (applied anyway, flagged)", DataQualityWarning, stacklevel=2)
    return [f"forced: {f}" for f in findings]


__all__ = ["RAW_FACTOR", "SPAN_FALLBACK", "SPAN_FLOOR", "THERMAL_GRID", "refuse_or_flag",
           "thermal_findings", "triaxial_findings"]
