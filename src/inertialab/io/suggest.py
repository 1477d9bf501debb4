"""Suggest a column map when a record's columns are missing but the match is obvious.

A vendor CSV names its gyro columns ``Gyro X``, ``GyrX``, ``gyro_x (deg/s)`` or
``angular_velocity.x``; the record schema wants ``gx_<unit>``. :func:`suggest_map`
proposes ``gx_rps=Gyro X:dps`` (the unit from the header's units row or the name's
bracket when there is one, else a ``<unit>`` placeholder), so the error a user sees
names the option value that would work.
"""

from __future__ import annotations

import re

__all__ = ["canonical_guess", "name_unit", "suggest_map"]

#: an axis: a letter (``gyr_x``, ``Gyro X``, ``angular_velocity.x``) or an index in
#: brackets (PX4 ulog2csv: ``gyro_rad[0]``)
_AXIS = r"[_\s.\-]*(?:([xyz])|\[([012])\])"
#: a unit spelled inside a name (PX4: ``gyro_rad``, ``accelerometer_m_s2``)
_NAME_UNIT = r"(?:[_\s]*(rad|deg|dps|rps|m_s2|mps2|g))?"
_PATTERNS = (
    ("g", re.compile(r"^(?:imu[_\s.]*|field[_\s.]*)?(?:gyro(?:scope)?|gyr|angular[_\s.]*"
                     r"(?:velocity|rate)|ang[_\s.]*vel|omega|rot(?:ation)?[_\s.]*rate|w|g)"
                     + _NAME_UNIT + _AXIS + r"$")),
    ("a", re.compile(r"^(?:imu[_\s.]*|field[_\s.]*)?(?:acc(?:el(?:erometer|eration)?)?|"
                     r"linear[_\s.]*acceleration|specific[_\s.]*force|f|a)"
                     + _NAME_UNIT + _AXIS + r"$")),
)
#: units spelled inside names, per family, as a header would write them
_NAME_UNITS = {("g", "rad"): "rad/s", ("g", "rps"): "rad/s", ("g", "deg"): "deg/s",
               ("g", "dps"): "deg/s", ("a", "m_s2"): "m/s^2", ("a", "mps2"): "m/s^2",
               ("a", "g"): "g"}
_TIME = re.compile(r"^(?:t|time|timestamp|time[_\s]?stamp|sample[_\s]?time(?:fine)?|stamp|"
                   r"secs?|seconds|%time|field\.header\.stamp)$")
_TEMP = re.compile(r"^(?:temp|temperature|t[_\s]?imu|imu[_\s]?temp(?:erature)?)$")
_BRACKET = re.compile(r"\s*[\[(]([^\])]+)[\])]\s*$")

#: canonical target unit per family, and the dimension it needs
_TARGET = {"g": "rps", "a": "mps2", "t": "s", "temp": "c"}


def name_unit(name: str) -> str | None:
    """The unit text in a column name's trailing bracket (``Gyro X (deg/s)`` -> ``deg/s``)."""
    m = _BRACKET.search(str(name))
    return m.group(1).strip() if m and not m.group(1).strip().isdigit() else None


def canonical_guess(name: str) -> tuple[str, str | None] | None:
    """``(base, unit text or None)`` for an obvious vendor column name, else None:
    ``"Gyro X [deg/s]"`` -> ``("gx", "deg/s")``; ``"AccZ"`` -> ``("az", None)``;
    imucal's ``gyr_x`` -> ``("gx", None)``; PX4's ``gyro_rad[1]`` -> ``("gy", "rad/s")``."""
    text = str(name).strip()
    unit = None
    m = _BRACKET.search(text)
    if m and not m.group(1).strip().isdigit():  # "[0]" is an index (PX4), not a unit
        unit = m.group(1).strip()
        text = text[:m.start()].strip()
    low = text.lower()
    for fam, pat in _PATTERNS:
        mm = pat.match(low)
        if mm:
            axis = mm.group(2) or "xyz"[int(mm.group(3))]
            if unit is None and mm.group(1):
                unit = _NAME_UNITS.get((fam, mm.group(1)))
            return f"{fam}{axis}", unit
    if _TIME.match(low):
        return "t", unit
    if _TEMP.match(low):
        return "temp", unit
    return None


def suggest_map(columns, header_units: dict | None = None, wanted=None) -> str | None:
    """A ``target=source[:unit]`` map for the obvious columns among ``columns`` whose base
    is in ``wanted`` (default: any), or None when nothing matches."""
    from inertialab.io.formats.text import unit_suffix

    hu = header_units or {}
    entries, seen = [], set()
    for col in columns:
        g = canonical_guess(f"{col} [{hu[col]}]" if col in hu else col)
        if g is None:
            continue
        base, unit = g
        if base in seen or (wanted is not None and base not in wanted
                            and not (base == "t" and "t_s" in wanted)
                            and not (base == "temp" and "temp_c" in wanted)):
            continue
        if str(col).strip().lower() in ("t_s", "temp_c"):
            continue
        seen.add(base)
        suf = unit_suffix(unit) if unit else None
        fam = base if base in ("t", "temp") else base[0]
        target = {"t": "t_s", "temp": "temp_c"}.get(base, f"{base}_{_TARGET[fam]}")
        source = str(col)
        if suf is not None and (suf != _TARGET[fam] or fam in ("g", "a")):
            entries.append(f"{target}={source}:{suf}")  # a measurement's unit always shown
        elif suf is not None or fam == "temp":
            entries.append(f"{target}={source}")
        else:
            entries.append(f"{target}={source}:<unit>")
    return ",".join(entries) if entries else None
