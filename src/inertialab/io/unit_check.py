"""Units that cannot be silently wrong: infer an undeclared unit only when the data
decide it, and refuse an accelerometer whose magnitude contradicts its declared unit.

A column mapped to ``gx_rps`` with no source unit used to be taken in rad/s whatever it
held: a log in deg/s was then 57 times too large, with no word. Now such a column is an
error naming it and the units it could be, unless the data decide:

* an accelerometer triad (three axes mapped together): at rest or in slow motion the
  median norm of the samples is gravity, so a median norm within 25 % of 1 is in g and
  within 25 % of 9.81 is in m/s^2 (a single axis decides only with its own median
  within those bands, as an axis along gravity does);
* an angle (``dtheta``, ``theta``) is never inferred: it must be declared;
* a gyro: its samples sit on the grid of its ADC's quantisation step (the smallest step
  between the distinct values, every value a whole number of steps from the first), and
  the steps of real gyros do not overlap between units: 5e-6 to 1.5e-3 rad/s
  (0.0003 to 0.086 deg/s), 3e-3 to 0.1 deg/s, 5 to 400 deg/h (MEMS data sheets: an
  ADIS16405 steps 0.05 deg/s, a BMI088 0.061 deg/s at 2000 deg/s full scale, an MPU-6000
  0.0076 deg/s at 250 deg/s). A float log without such a grid, a step that is a power
  of ten (the decimal rounding of an export, 1e-6 for six decimals), or a step between
  the bands decides nothing.

An inferred unit converts the column like a declared one, is printed as a
``DataQualityWarning`` and recorded in ``meta["inferred_units"]``.

:func:`check_accel_magnitude` refuses a declared accelerometer triad whose median norm
reads about 1 in m/s^2 (it is in g) or about 9.8 in g (it is in m/s^2).
"""

from __future__ import annotations

import numpy as np

from inertialab import units as U
from inertialab.errors import InputError

__all__ = ["check_accel_magnitude", "infer_unit", "quantisation_step"]

#: candidate units of the dimensions whose unit can be inferred
CANDIDATES = {"acceleration": ("g", "mps2"), "angular_rate": ("rps", "dps", "dph"),
              "angle": ("arcsec", "deg", "rad")}
#: quantisation steps of real gyros per unit (see the module text)
GYRO_STEP = {"rps": (5e-6, 1.5e-3), "dps": (3e-3, 0.1), "dph": (5.0, 400.0)}
#: a median norm within this fraction of 1 g reads in g (of 9.81 in m/s^2)
G_BAND = 0.25
_SAMPLE = 200_000


def quantisation_step(x) -> float | None:
    """The ADC step of a column, or None when its values do not sit on one grid."""
    v = np.asarray(x, dtype=float)
    v = v[np.isfinite(v)][:_SAMPLE]
    if v.size < 10:
        return None
    u = np.unique(v)
    if u.size < 3:
        return None
    d = np.diff(u)
    q = float(d.min())
    if not q > 0:
        return None
    k = (v - u[0]) / q
    if np.max(np.abs(k - np.rint(k))) > 1e-3:
        return None
    if abs(np.log10(q) - np.rint(np.log10(q))) < 1e-9:
        return None  # a power of ten: the export's decimal rounding, not an ADC's step
    return q


def _g_unit(m: float) -> str | None:
    if abs(m - 1.0) <= G_BAND:
        return "g"
    if abs(m - U.G_STANDARD) <= G_BAND * U.G_STANDARD:
        return "mps2"
    return None


def infer_unit(dimension: str, values, triad=None) -> tuple[str | None, str]:
    """``(unit or None, evidence)`` for a column of ``dimension`` without a unit.

    ``triad``: the (n, 3) accelerometer samples when the three axes are mapped together
    (their median norm decides); else the column's own median decides."""
    x = np.asarray(values, dtype=float)
    if dimension == "acceleration":
        if triad is not None:
            m = float(np.median(np.linalg.norm(np.asarray(triad, dtype=float), axis=1)))
            what = f"the accelerometer triad's median norm is {m:.4g}"
        else:
            m = float(abs(np.median(x)))
            what = f"its median is {m:.4g}"
        u = _g_unit(m)
        return u, what + (f", gravity in {u}" if u else ", neither about 1 (g) nor 9.8 (m/s^2)")
    if dimension == "angular_rate":
        q = quantisation_step(x)
        if q is None:
            return None, "its values sit on no quantisation grid"
        hits = [u for u, (lo, hi) in GYRO_STEP.items() if lo <= q <= hi]
        if len(hits) == 1:
            return hits[0], f"its quantisation step {q:.4g} is a gyro's step in {hits[0]}"
        return None, f"its quantisation step {q:.4g} is no gyro's step in one unit alone"
    return None, f"the unit of an {dimension} cannot be told from its values"


def check_accel_magnitude(df, units: dict, *, path) -> None:
    """Refuse an accelerometer triad (``ax ay az`` in g or m/s^2) whose median norm
    contradicts its declared unit (about 1 in m/s^2, about 9.8 in g)."""
    cols = []
    for base in ("ax", "ay", "az"):
        c = next((n for n in units if U.split_suffix(n)[0] == base), None)
        if c is None:
            return
        cols.append(c)
    sufs = {units[c] for c in cols}
    if len(sufs) != 1 or next(iter(sufs)) not in ("g", "mps2"):
        return
    declared = next(iter(sufs))
    a = np.column_stack([np.asarray(df[c], dtype=float) for c in cols])
    a = a[np.all(np.isfinite(a), axis=1)]
    if a.shape[0] == 0:
        return
    m = float(np.median(np.linalg.norm(a, axis=1)))
    looks = _g_unit(m)
    if looks is not None and looks != declared:
        shown = {"g": "g", "mps2": "m/s^2"}
        raise InputError(f"the accelerometer reads a median |a| of {m:.4g} {shown[declared]}, "
                         f"which is gravity in {shown[looks]}: the columns look like "
                         f"{looks}, not {declared} (declare {looks}: a suffix _{looks}, "
                         f"':{looks}' in the map or argument 'unit')", path=path,
                         column=", ".join(cols))
