"""Unit conversions: the only module of inertialab that converts units.

Units travel in column-name suffixes (docs/records.md) and in model files.
This module knows every suffix, its physical dimension and its factor to the SI
unit of that dimension, plus the composite units in which noise terms are reported
(deg/sqrt(h), deg/h/sqrt(h), ug/sqrt(Hz) ...).

g-based units (``g``, ``mg``, ``ug``) convert with a *local* gravity ``g_local``
(m/s^2, default :data:`G_STANDARD` = 9.80665); pass the value of the rig's site
(``normal_gravity`` helps when only latitude and height are known).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from inertialab.errors import InputError

G_STANDARD = 9.80665
"""Standard gravity g_n in m/s^2 (CGPM 1901)."""

DEG = math.pi / 180.0
ARCSEC = DEG / 3600.0
HOUR = 3600.0
DAY = 86400.0


@dataclass(frozen=True)
class Unit:
    """A unit: its dimension name and the factor that takes a value to SI.

    ``offset`` is added after scaling (only for temperature units; SI here is deg C,
    the unit every record uses). ``g_power`` is the power of local gravity in the
    factor (1 for g/mg/ug): the SI value is ``x * scale * g_local**g_power``.
    """

    name: str
    dimension: str
    scale: float
    g_power: int = 0

    def factor(self, g_local: float = G_STANDARD) -> float:
        return self.scale * (g_local ** self.g_power)


def _u(name, dim, scale, g_power=0):
    return Unit(name, dim, float(scale), g_power)


# Column-name suffixes, one spelling per unit (docs/records.md).
SUFFIXES: dict[str, Unit] = {
    "s": _u("s", "time", 1.0),
    "ms": _u("ms", "time", 1e-3),
    "us": _u("us", "time", 1e-6),
    "ns": _u("ns", "time", 1e-9),
    "h": _u("h", "time", HOUR),
    "day": _u("day", "time", DAY),
    "hz": _u("hz", "frequency", 1.0),
    "deg": _u("deg", "angle", DEG),
    "rad": _u("rad", "angle", 1.0),
    "arcsec": _u("arcsec", "angle", ARCSEC),
    "g": _u("g", "acceleration", 1.0, 1),
    "mg": _u("mg", "acceleration", 1e-3, 1),
    "ug": _u("ug", "acceleration", 1e-6, 1),
    "mps2": _u("mps2", "acceleration", 1.0),
    "dph": _u("dph", "angular_rate", DEG / HOUR),
    "dps": _u("dps", "angular_rate", DEG),
    "rps": _u("rps", "angular_rate", 1.0),
    "c": _u("c", "temperature", 1.0),
    "v": _u("v", "voltage", 1.0),
    "mv": _u("mv", "voltage", 1e-3),
    "ma": _u("ma", "current", 1e-3),
    "ma_per_g": _u("ma_per_g", "current_per_acceleration", 1e-3),
    "v_per_g": _u("v_per_g", "voltage_per_acceleration", 1.0),
    "ppm": _u("ppm", "ratio", 1e-6),
    "pct": _u("pct", "ratio", 1e-2),
    # dimensionless fractional frequency (a clock's y), the same as "1"
    "ratio": _u("ratio", "ratio", 1.0),
    "frac": _u("frac", "ratio", 1.0),
    "lsb": _u("lsb", "counts", 1.0),
    "ohm": _u("ohm", "resistance", 1.0),
    "per_c": _u("per_c", "per_temperature", 1.0),
}

# Display spellings used in reports and JSON (noise terms and friends).
DISPLAY: dict[str, Unit] = {
    "m/s^2": _u("m/s^2", "acceleration", 1.0),
    "deg/h": _u("deg/h", "angular_rate", DEG / HOUR),
    "deg/s": _u("deg/s", "angular_rate", DEG),
    "rad/s": _u("rad/s", "angular_rate", 1.0),
    # angle random walk / velocity random walk: [rate]*sqrt(time) = [rate]/sqrt(Hz)
    "deg/sqrt(h)": _u("deg/sqrt(h)", "arw", DEG / math.sqrt(HOUR)),
    "rad/sqrt(s)": _u("rad/sqrt(s)", "arw", 1.0),
    "rad/s/sqrt(Hz)": _u("rad/s/sqrt(Hz)", "arw", 1.0),
    "deg/s/sqrt(Hz)": _u("deg/s/sqrt(Hz)", "arw", DEG),
    "deg/h/sqrt(Hz)": _u("deg/h/sqrt(Hz)", "arw", DEG / HOUR),
    "m/s/sqrt(h)": _u("m/s/sqrt(h)", "vrw", 1.0 / math.sqrt(HOUR)),
    "m/s/sqrt(s)": _u("m/s/sqrt(s)", "vrw", 1.0),
    "m/s^2/sqrt(Hz)": _u("m/s^2/sqrt(Hz)", "vrw", 1.0),
    "ug/sqrt(Hz)": _u("ug/sqrt(Hz)", "vrw", 1e-6, 1),
    "mg/sqrt(Hz)": _u("mg/sqrt(Hz)", "vrw", 1e-3, 1),
    # rate random walk: [rate]/sqrt(time)
    "deg/h/sqrt(h)": _u("deg/h/sqrt(h)", "rrw", DEG / HOUR / math.sqrt(HOUR)),
    "rad/s/sqrt(s)": _u("rad/s/sqrt(s)", "rrw", 1.0),
    "rad/s^2/sqrt(Hz)": _u("rad/s^2/sqrt(Hz)", "rrw", 1.0),
    "m/s^2/sqrt(h)": _u("m/s^2/sqrt(h)", "arw_acc", 1.0 / math.sqrt(HOUR)),
    "m/s^2/sqrt(s)": _u("m/s^2/sqrt(s)", "arw_acc", 1.0),
    "m/s^3/sqrt(Hz)": _u("m/s^3/sqrt(Hz)", "arw_acc", 1.0),
    # rate ramp
    "deg/h^2": _u("deg/h^2", "rate_ramp", DEG / HOUR**2),
    "rad/s^2": _u("rad/s^2", "rate_ramp", 1.0),
    "m/s^3": _u("m/s^3", "jerk", 1.0),
    # quantisation: angle (gyro) or velocity (accelerometer)
    "m/s": _u("m/s", "velocity", 1.0),
}
for _k in ("s", "ms", "us", "ns", "h", "day", "deg", "rad", "arcsec", "g", "mg", "ug",
           "ppm", "pct", "lsb", "ohm", "v", "mv", "ma"):
    DISPLAY.setdefault(_k, SUFFIXES[_k])
DISPLAY.setdefault("Hz", SUFFIXES["hz"])
DISPLAY.setdefault("C", SUFFIXES["c"])
DISPLAY.setdefault("1", _u("1", "ratio", 1.0))


def lookup(unit: str) -> Unit:
    """Return the :class:`Unit` for a suffix (case-insensitive) or display spelling.

    Raises
    ------
    InputError
        For a unit inertialab does not know.
    """
    if isinstance(unit, Unit):
        return unit
    if unit in DISPLAY:
        return DISPLAY[unit]
    key = str(unit).strip().lower()
    if key in SUFFIXES:
        return SUFFIXES[key]
    for k, v in DISPLAY.items():
        if k.lower() == key:
            return v
    known = ", ".join(sorted(SUFFIXES))
    raise InputError(f"unknown unit '{unit}' (known suffixes: {known})")


def dimension(unit: str) -> str:
    """Dimension name of a unit (``"acceleration"``, ``"angular_rate"`` ...)."""
    return lookup(unit).dimension


def convert(x, from_unit: str, to_unit: str, *, g_local: float = G_STANDARD):
    """Convert ``x`` (scalar or array) from ``from_unit`` to ``to_unit``.

    Both units must have the same dimension. g-based units use ``g_local`` (m/s^2).
    Temperatures are all deg C (the only temperature unit), so they pass unchanged.

    Raises
    ------
    InputError
        Unknown unit, or units of different dimensions.
    """
    import numpy as np

    a, b = lookup(from_unit), lookup(to_unit)
    if a.dimension != b.dimension:
        raise InputError(
            f"cannot convert '{a.name}' ({a.dimension}) to '{b.name}' ({b.dimension})"
        )
    f = a.factor(g_local) / b.factor(g_local)
    if isinstance(x, (list, tuple)):
        x = np.asarray(x, dtype=float)
    return x * f if f != 1.0 else x


def to_si(x, unit: str, *, g_local: float = G_STANDARD):
    """Convert ``x`` from ``unit`` to the SI unit of its dimension (rad, rad/s, m/s^2 ...)."""
    import numpy as np

    u = lookup(unit)
    f = u.factor(g_local)
    if isinstance(x, (list, tuple)):
        x = np.asarray(x, dtype=float)
    return x * f if f != 1.0 else x


def from_si(x, unit: str, *, g_local: float = G_STANDARD):
    """Convert ``x`` from the SI unit of ``unit``'s dimension to ``unit``."""
    import numpy as np

    u = lookup(unit)
    f = u.factor(g_local)
    if isinstance(x, (list, tuple)):
        x = np.asarray(x, dtype=float)
    return x / f if f != 1.0 else x


def lsb_to(x, lsb_per_unit: float, *, offset_lsb: float = 0.0):
    """Convert raw counts to the unit whose sensitivity is ``lsb_per_unit`` counts per unit.

    ``offset_lsb`` is subtracted first (e.g. 32768 for an unsigned 16-bit ADC).
    """
    import numpy as np

    if not np.isfinite(lsb_per_unit) or lsb_per_unit == 0:
        raise InputError(f"LSB sensitivity must be finite and non-zero, got {lsb_per_unit}")
    return (np.asarray(x, dtype=float) - offset_lsb) / lsb_per_unit


def to_lsb(x, lsb_per_unit: float, *, offset_lsb: float = 0.0):
    """Inverse of :func:`lsb_to`."""
    import numpy as np

    return np.asarray(x, dtype=float) * lsb_per_unit + offset_lsb


# Convenience names used across the studies -----------------------------------------

def dph_to_rps(x):
    """deg/h -> rad/s."""
    return convert(x, "dph", "rps")


def rps_to_dph(x):
    """rad/s -> deg/h."""
    return convert(x, "rps", "dph")


def g_to_mps2(x, g_local: float = G_STANDARD):
    """g (of local gravity ``g_local``) -> m/s^2."""
    return convert(x, "g", "mps2", g_local=g_local)


def mps2_to_g(x, g_local: float = G_STANDARD):
    """m/s^2 -> g (of local gravity ``g_local``)."""
    return convert(x, "mps2", "g", g_local=g_local)


def normal_gravity(lat_deg: float, h_m: float = 0.0) -> float:
    """Normal gravity in m/s^2 on the WGS-84 ellipsoid (Somigliana) with a free-air
    height correction (the second-order formula of NIMA TR8350.2 eq. 4-3).

    Parameters
    ----------
    lat_deg : float
        Geodetic latitude in degrees.
    h_m : float, default 0
        Ellipsoidal height in metres.
    """
    a = 6378137.0
    b = 6356752.3142
    ge = 9.7803253359
    gp = 9.8321849378
    e2 = 0.00669437999013
    k = (b * gp) / (a * ge) - 1.0
    s2 = math.sin(math.radians(lat_deg)) ** 2
    g0 = ge * (1.0 + k * s2) / math.sqrt(1.0 - e2 * s2)
    f = 1.0 / 298.257223563
    m = 0.00344978650684
    return g0 * (1.0 - 2.0 / a * (1.0 + f + m - 2.0 * f * s2) * h_m + 3.0 / a**2 * h_m**2)


def split_suffix(column: str) -> tuple[str, str | None]:
    """Split a column name into ``(base, unit_suffix)``.

    The longest known suffix wins (``sf_ma_per_g`` -> ``("sf", "ma_per_g")``). A
    name without a known suffix returns ``(name, None)``; :func:`unit_suffix_or_error`
    is the strict version.
    """
    name = column.strip().lower()
    best = None
    for suf in SUFFIXES:
        if name.endswith("_" + suf) and len(name) > len(suf) + 1:
            if best is None or len(suf) > len(best):
                best = suf
    if best is None:
        return name, None
    return name[: -(len(best) + 1)], best


def unit_suffix_or_error(column: str, *, dimension_: str | None = None, path=None) -> str:
    """The unit suffix of ``column``, checked against an expected dimension.

    Raises
    ------
    InputError
        No known suffix, or a suffix of another dimension.
    """
    base, suf = split_suffix(column)
    if suf is None:
        tail = column.rsplit("_", 1)[-1] if "_" in column else ""
        hint = f" (unknown unit suffix '{tail}')" if tail else ""
        raise InputError(
            f"no known unit suffix{hint}; use one of {', '.join(sorted(SUFFIXES))} "
            "or give argument 'unit'", path=path, column=column)
    if dimension_ is not None and SUFFIXES[suf].dimension != dimension_:
        raise InputError(
            f"unit '{suf}' is a {SUFFIXES[suf].dimension}, expected a {dimension_}",
            path=path, column=column)
    return suf


# --------------------------------------------------------------------- clock units
#: Fractional-frequency units of a clock record (dimensionless) and their factor to the
#: ratio (NIST SP 1065 section 2: y = (f - f0) / f0).
CLOCK_RATIO = {"1": 1.0, "ratio": 1.0, "frac": 1.0, "pct": 1e-2, "ppm": 1e-6, "ppb": 1e-9,
               "ppt": 1e-12}
#: Phase (time-error) units of a clock record and their factor to seconds.
CLOCK_TIME = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "ps": 1e-12}

# ------------------------------------------------------- thermal study, reported units
#: Units of the thermal study's reported settings and coefficients (spec 000: the
#: accelerometer output in mV, its model coefficients K0 .. Kp, the optimiser's unit-cube
#: parameters and counts).
THERMAL_UNITS = {"temp": "degC", "output": "mV", "k0": "mV", "k1": "mV/g", "k2": "mV/g^2",
                 "kip": "mV/g^2", "kp": "mV/g", "wall_s": "s", "fun": "mg", "f_default": "mg",
                 "radius": "1 (scaled)", "squash": "1", "accept": "1", "reject": "1",
                 "visual": "1 (unit cube)", "step": "1 (unit cube)",
                 "visual_min": "1 (unit cube)", "step_min": "1 (unit cube)", "crowd": "1",
                 "try_number": "1", "n_fish": "1", "max_generations": "1",
                 "adaptive_exponent": "1", "r_max": "1", "search_epochs": "1"}
