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
  between the distinct values, every value a whole number of steps from the first).
  Real gyros step by 5e-6 to 1.5e-3 rad/s (0.0003 to 0.086 deg/s), 3e-3 to 0.1 deg/s
  (MEMS data sheets: an ADIS16405 steps 0.05 deg/s, a BMI088 0.061 deg/s at 2000 deg/s
  full scale, an MPU-6000 0.0076 deg/s at 250 deg/s), and 1e-4 to 400 deg/h (fibre-optic
  gyros print down to 1e-4 deg/h). These bands overlap: a step that fits one unit alone
  decides; a step that fits two decides nothing, and the error names both. A float log
  without such a grid, a step that is a power of ten (the decimal rounding of an
  export, 1e-6 for six decimals), or a step outside every band decides nothing.

An inferred unit converts the column like a declared one, is printed as a
``DataQualityWarning`` and recorded in ``meta["inferred_units"]``.

Declared units are checked against the data too, for gyros as for accelerometers; the
error names the column and the unit it looks like:

* :func:`check_accel_magnitude` (every record): an accelerometer triad whose median norm
  is gravity in another acceleration unit (about 1 in m/s^2 is g; 1000 in m/s^2 is mg),
  or beyond :data:`MAX_ACCEL_G` g in its declared unit (raw ADC counts declared as m/s^2);
* :func:`check_gyro_units` (every record): a gyro whose quantisation step is no gyro's
  step in its declared unit but is one in another unit (a 0.05 grid declared in rad/s),
  or whose median magnitude exceeds :data:`MAX_RATE_RPS` (no MEMS range reaches it);
* :func:`check_static_units` (the logs a noise analysis reads, ``validate --kind imu``
  alike): a static accelerometer's median |a| must lie within :data:`STATIC_G` g
  (0.5-1.5 g) in its declared unit, and a static gyro's median |w| under
  :data:`STATIC_RATE_RPS` (Earth's rate plus the largest MEMS bias).
"""

from __future__ import annotations

import numpy as np

from inertialab import units as U
from inertialab.errors import InputError

__all__ = ["check_accel_magnitude", "check_gyro_units", "check_static_units", "infer_unit",
           "quantisation_step"]

#: candidate units of the dimensions whose unit can be inferred
CANDIDATES = {"acceleration": ("g", "mps2"), "angular_rate": ("rps", "dps", "dph"),
              "angle": ("arcsec", "deg", "rad")}
#: quantisation steps of real gyros per unit (see the module text); the bands overlap
GYRO_STEP = {"rps": (5e-6, 1.5e-3), "dps": (3e-3, 0.1), "dph": (1e-4, 400.0)}
#: no accelerometer's median norm reaches this, in g (raw counts declared as m/s^2 do)
MAX_ACCEL_G = 50.0
#: no gyro's median magnitude reaches this, rad/s (2000 deg/s: the largest MEMS range)
MAX_RATE_RPS = 35.0
#: a static accelerometer's median norm lies in this band, g
STATIC_G = (0.5, 1.5)
#: a static gyro reads Earth's rate plus its bias: under 0.6 rad/s (34 deg/s; the
#: largest zero-rate offsets of consumer MEMS gyros are 20-30 deg/s)
STATIC_RATE_RPS = 0.6
_SHOWN = {"g": "g", "mps2": "m/s^2", "mg": "mg", "ug": "ug", "rps": "rad/s", "dps": "deg/s",
          "dph": "deg/h"}
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


def step_units(q: float) -> list[str]:
    """The gyro units whose quantisation-step band (:data:`GYRO_STEP`) holds ``q``."""
    return [u for u, (lo, hi) in GYRO_STEP.items() if lo <= q <= hi]


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
        hits = step_units(q)
        if len(hits) == 1:
            return hits[0], f"its quantisation step {q:.4g} is a gyro's step in {hits[0]}"
        if hits:
            return None, (f"its quantisation step {q:.4g} is a gyro's step in "
                          f"{' and in '.join(_SHOWN[u] for u in hits)} alike: the data "
                          "cannot tell which")
        return None, f"its quantisation step {q:.4g} is no gyro's step in any unit"
    return None, f"the unit of an {dimension} cannot be told from its values"


def _triad(units: dict, bases=("ax", "ay", "az")):
    """The columns of a triad (or None when one is missing) and their one unit (None
    when they differ)."""
    cols = []
    for base in bases:
        c = next((n for n in units if U.split_suffix(n)[0] == base), None)
        if c is None:
            return None, None
        cols.append(c)
    sufs = {units[c] for c in cols}
    return cols, (next(iter(sufs)) if len(sufs) == 1 else None)


def _median_norm(df, cols) -> float | None:
    a = np.column_stack([np.asarray(df[c], dtype=float)[:_SAMPLE * 5] for c in cols])
    a = a[np.all(np.isfinite(a), axis=1)]
    return float(np.median(np.linalg.norm(a, axis=1))) if a.shape[0] else None


def _accel_look_alike(m: float, declared: str) -> str | None:
    """The acceleration unit in which a median norm ``m`` (in the declared unit's
    numbers) is gravity, other than ``declared``; None when none is."""
    for u in ("g", "mps2", "mg", "ug"):
        if u != declared and abs(float(U.convert(m, u, "g")) - 1.0) <= G_BAND:
            return u
    return None


def _integral(v) -> bool:
    v = np.asarray(v, dtype=float)[:_SAMPLE]
    v = v[np.isfinite(v)]
    return bool(v.size) and bool(np.all(v == np.rint(v)))


def check_accel_magnitude(df, units: dict, *, path) -> None:
    """Refuse an accelerometer triad (``ax ay az`` in one acceleration unit) whose median
    norm is gravity in another unit (about 1 in m/s^2: g; about 9.8 in g: m/s^2; 1000
    in g: mg), or beyond :data:`MAX_ACCEL_G` g (no accelerometer's median)."""
    cols, declared = _triad(units)
    if cols is None or declared is None or U.lookup(declared).dimension != "acceleration":
        return
    m = _median_norm(df, cols)
    if m is None:
        return
    in_g = float(U.convert(m, declared, "g"))
    if abs(in_g - 1.0) <= G_BAND:
        return
    looks = _accel_look_alike(m, declared)
    shown = _SHOWN.get(declared, declared)
    if looks is not None:
        raise InputError(f"the accelerometer reads a median |a| of {m:.4g} {shown}, "
                         f"which is gravity in {_SHOWN[looks]}: the columns look like "
                         f"{looks}, not {declared} (declare {looks}: a suffix _{looks}, "
                         f"':{looks}' in the map or argument 'unit')", path=path,
                         column=", ".join(cols))
    if in_g > MAX_ACCEL_G:
        raise InputError(f"the accelerometer reads a median |a| of {m:.4g} {shown} "
                         f"({in_g:.4g} g): no accelerometer reads that"
                         + ("; the values are whole numbers, like raw ADC counts (declare "
                            "them lsb: argument 'unit' lsb, with the sensitivity in the sidecar)"
                            if _integral(df[cols[0]]) else "; check the declared unit"),
                         path=path, column=", ".join(cols))


def check_gyro_units(df, units: dict, *, path) -> None:
    """Refuse a gyro column (``gx gy gz rate``) whose quantisation step is no gyro's
    step in its declared unit but is one in another unit, or whose median magnitude
    exceeds :data:`MAX_RATE_RPS`."""
    for col, suf in units.items():
        if U.split_suffix(col)[0] not in ("gx", "gy", "gz", "rate") or suf not in GYRO_STEP:
            continue
        v = np.asarray(df[col], dtype=float)
        shown = _SHOWN[suf]
        med = float(abs(np.nanmedian(v[:_SAMPLE]))) if v.size else 0.0
        if float(U.convert(med, suf, "rps")) > MAX_RATE_RPS:
            raise InputError(f"the gyro reads a median |w| of {med:.4g} {shown}, beyond "
                             f"{MAX_RATE_RPS:g} rad/s (no gyro's range)"
                             + ("; the values are whole numbers, like raw ADC counts "
                                "(declare them lsb: argument 'unit' lsb)" if _integral(v) else
                                "; check the declared unit"), path=path, column=col)
        q = quantisation_step(v)
        hits = step_units(q) if q is not None else []
        if hits and suf not in hits:
            lo, hi = GYRO_STEP[suf]
            alt = " or ".join(_SHOWN[u] for u in hits)
            raise InputError(f"its values step by {q:.4g} {shown}, no gyro's quantisation "
                             f"step in {shown} ({lo:g} to {hi:g}): it looks like {alt} "
                             f"(declare it: a suffix _{hits[0]}, ':{hits[0]}' in the map or "
                             "argument 'unit')", path=path, column=col)


def check_static_units(record) -> None:
    """The magnitudes a static log must have in its declared units (the checks of a
    noise analysis and of ``validate --kind imu``): the accelerometer triad's median
    |a| within :data:`STATIC_G` g (a single axis: at most its upper end), each gyro's
    median |w| under :data:`STATIC_RATE_RPS`. One-line :class:`InputError` naming the
    columns and the unit they look like."""
    df, units, path = record.data, dict(record.units or {}), record.path
    units = {c: u for c, u in units.items() if c in df.columns}
    cols, declared = _triad(units)
    lo, hi = STATIC_G
    if cols is not None and declared is not None \
            and U.lookup(declared).dimension == "acceleration":
        m = _median_norm(df, cols)
        in_g = float(U.convert(m, declared, "g")) if m is not None else 1.0
        if not lo <= in_g <= hi:
            looks = _accel_look_alike(m, declared)
            raise InputError(f"a static accelerometer reads gravity, {lo:g} to {hi:g} g; "
                             f"this one reads a median |a| of {m:.4g} "
                             f"{_SHOWN.get(declared, declared)} ({in_g:.3g} g)"
                             + (f": the columns look like {looks}, not {declared}"
                                if looks else ": check the declared unit (or the record is "
                                "not of a sensor at rest)"), path=path, column=", ".join(cols))
    for col, suf in units.items():
        base = U.split_suffix(col)[0]
        v = np.asarray(df[col], dtype=float)[:_SAMPLE * 5]
        med = float(abs(np.nanmedian(v))) if v.size else 0.0
        if base in ("ax", "ay", "az") and U.lookup(suf).dimension == "acceleration" \
                and float(U.convert(med, suf, "g")) > hi:
            raise InputError(f"a static accelerometer axis reads at most {hi:g} g; this one "
                             f"a median of {med:.4g} {_SHOWN.get(suf, suf)}", path=path,
                             column=col)
        if base in ("gx", "gy", "gz") and suf in GYRO_STEP \
                and float(U.convert(med, suf, "rps")) > STATIC_RATE_RPS:
            dps = suf == "rps" and med * 180.0 / np.pi > 0 and med <= STATIC_RATE_RPS * 57.3
            raise InputError(f"a static gyro reads Earth's rate plus its bias, under "
                             f"{STATIC_RATE_RPS:g} rad/s; this one a median |w| of {med:.4g} "
                             f"{_SHOWN[suf]}" + (": it looks like deg/s, not rad/s" if dps
                                                 else ": check the declared unit (or the "
                                                 "record is not of a sensor at rest)"),
                             path=path, column=col)
