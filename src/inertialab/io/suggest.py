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

_AXIS = r"[_\s.\-]*([xyz])"
_PATTERNS = (
    ("g", re.compile(r"^(?:imu[_\s.]*)?(?:gyro(?:scope)?|gyr|angular[_\s.]*(?:velocity|rate)|"
                     r"ang[_\s.]*vel|omega|rot(?:ation)?[_\s.]*rate|w|g)" + _AXIS + r"$")),
    ("a", re.compile(r"^(?:imu[_\s.]*)?(?:acc(?:el(?:erometer|eration)?)?|linear[_\s.]*"
                     r"acceleration|specific[_\s.]*force|f|a)" + _AXIS + r"$")),
)
_TIME = re.compile(r"^(?:t|time|timestamp|time[_\s]?stamp|sample[_\s]?time(?:fine)?|stamp|"
                   r"secs?|seconds)$")
_TEMP = re.compile(r"^(?:temp|temperature|t[_\s]?imu|imu[_\s]?temp(?:erature)?)$")
_BRACKET = re.compile(r"\s*[\[(]([^\])]+)[\])]\s*$")

#: canonical target unit per family, and the dimension it needs
_TARGET = {"g": "rps", "a": "mps2", "t": "s", "temp": "c"}


def name_unit(name: str) -> str | None:
    """The unit text in a column name's trailing bracket (``Gyro X (deg/s)`` -> ``deg/s``)."""
    m = _BRACKET.search(str(name))
    return m.group(1).strip() if m else None


def canonical_guess(name: str) -> tuple[str, str | None] | None:
    """``(base, unit text or None)`` for an obvious vendor column name, else None:
    ``"Gyro X [deg/s]"`` -> ``("gx", "deg/s")``; ``"AccZ"`` -> ``("az", None)``."""
    text = str(name).strip()
    unit = None
    m = _BRACKET.search(text)
    if m:
        unit = m.group(1).strip()
        text = text[:m.start()].strip()
    low = text.lower()
    for fam, pat in _PATTERNS:
        mm = pat.match(low)
        if mm:
            return f"{fam}{mm.group(1)}", unit
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
        if suf is not None and suf != _TARGET[fam]:
            entries.append(f"{target}={source}:{suf}")
        elif suf is not None or fam == "temp":
            entries.append(f"{target}={source}")
        else:
            entries.append(f"{target}={source}:<unit>")
    return ",".join(entries) if entries else None
