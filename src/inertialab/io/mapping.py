"""Column mapping and parse options for files not written to a spec (issue 10 item 1).

Real rigs write Xsens, VectorNav, PX4 or ROS exports: other column names, units in
the header text instead of the name, integer time stamps in ms/us/ns, ``;`` as the
separator and ``,`` as the decimal mark (European locales), and preamble lines before
the header. This module turns such a table into the canonical columns of
:mod:`inertialab.io.schemas` before the normal validation runs:

* :func:`parse_map` reads ``--map ax_mps2=AccX:g,gx_rps=GyrX:dps,t_s=SampleTimeFine:us``
  into a :class:`ColumnMap`: target canonical column = source column ``:`` source unit.
  The source unit must have the target's dimension (``ax_mps2=AccX:dps`` is an
  :class:`~inertialab.errors.InputError`); without ``:unit`` the values are taken in
  the target's unit.
* :func:`load_map_file` reads the same from a JSON or TOML file (``--map-file``), with
  the parse options: ``{"columns": {"ax_mps2": "AccX:g", ...}, "sep": ";",
  "decimal": ",", "skip_rows": 3}``; a column entry may also be
  ``{"column": "AccX", "unit": "g"}``.
* :func:`apply_map` renames and converts (through :mod:`inertialab.units` only).
  Time targets (``t_s``) taken from integer stamps are converted relative to the
  first stamp in integer arithmetic, so ns since the epoch keep their resolution.
* :func:`normalise_time_columns` does the same for a file whose time column is already
  called ``t_ms``, ``t_us`` or ``t_ns`` (no map needed).
* :class:`ParseOptions` and :func:`sniff` decide separator, decimal mark and the
  preamble lines to skip (explicit options win over sniffing).

Written by hand because it is glue: pandas does the parsing; what is added is the
grammar of the option and the unit checks.
"""

from __future__ import annotations

import json
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from inertialab import units as U
from inertialab.errors import InputError

__all__ = [
    "ColumnMap",
    "MapEntry",
    "ParseOptions",
    "apply_map",
    "load_map_file",
    "normalise_time_columns",
    "parse_map",
    "sniff",
]

_TIME_TARGETS = ("t_s",)
_TIME_SUFFIXES = ("ms", "us", "ns")


@dataclass(frozen=True)
class MapEntry:
    """One mapped column: ``target`` (canonical, with unit suffix) <- ``source`` in ``unit``.

    ``unit`` is None when the source is already in the target's unit.
    """

    target: str
    source: str
    unit: str | None = None
    scale: float = 1.0

    def to_text(self) -> str:
        if not self.unit:
            return f"{self.target}={self.source}"
        pre = "" if self.scale == 1.0 else f"{self.scale!r}"
        return f"{self.target}={self.source}:{pre}{self.unit}"


@dataclass(frozen=True)
class ColumnMap:
    """An ordered set of :class:`MapEntry` (one per target column)."""

    entries: tuple[MapEntry, ...] = ()

    def __bool__(self) -> bool:
        return bool(self.entries)

    def to_text(self) -> str:
        """The ``--map`` spelling (round-trips through :func:`parse_map`)."""
        return ",".join(e.to_text() for e in self.entries)

    def merged(self, other: ColumnMap | None) -> ColumnMap:
        """This map with ``other``'s entries replacing those of the same target."""
        if not other:
            return self
        targets = {e.target for e in other.entries}
        return ColumnMap(tuple(e for e in self.entries if e.target not in targets)
                         + other.entries)


@dataclass(frozen=True)
class ParseOptions:
    """How to read a delimited text file.

    Parameters
    ----------
    sep : str or None, default None
        Field separator (``","``, ``";"``, ``"\\t"``, ``" "`` for runs of blanks);
        None sniffs it from the header line.
    decimal : str or None, default None
        Decimal mark, ``"."`` or ``","``; None sniffs (``","`` only when the separator
        is not a comma and numbers like ``0,25`` appear).
    skip_rows : int or None, default None
        Preamble lines before the header. None skips ``#`` lines (parsed as
        ``# key=value`` metadata), ``//`` lines (Xsens) and blank lines.
    """

    sep: str | None = None
    decimal: str | None = None
    skip_rows: int | None = None

    def __post_init__(self):
        if self.decimal not in (None, ".", ","):
            raise InputError(f"decimal mark must be '.' or ',', got {self.decimal!r}")
        if self.sep is not None and (len(self.sep) == 0 or self.sep == self.decimal):
            raise InputError(f"separator {self.sep!r} cannot be empty or equal the decimal mark")
        if self.skip_rows is not None and int(self.skip_rows) < 0:
            raise InputError(f"skip_rows must be >= 0, got {self.skip_rows}")

    @property
    def is_default(self) -> bool:
        return self.sep is None and self.decimal is None and self.skip_rows is None

    def to_dict(self) -> dict:
        return {"sep": self.sep, "decimal": self.decimal, "skip_rows": self.skip_rows}


# ----------------------------------------------------------------------------- parsing

_ENTRY = re.compile(r"^\s*([^=\s]+)\s*=\s*(.+?)\s*$")
#: a unit with a numeric factor in front: ``100us`` (Xsens SampleTimeFine ticks),
#: ``0.000598mps2`` (an LSB size), ``1e-4*s``
_SCALED = re.compile(r"^([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*\*?\s*([A-Za-z].*)$")


def _check_entry(target: str, source: str, unit: str | None, *, where: str) -> MapEntry:
    target = target.strip().lower()
    source = source.strip()
    if not target or not source:
        raise InputError(f"{where}: empty target or source column in map entry")
    if target in _TIME_TARGETS:
        tdim = "time"
    else:
        base, suf = U.split_suffix(target)
        tdim = U.SUFFIXES[suf].dimension if suf is not None else None
    scale = 1.0
    if unit is not None:
        unit = unit.strip()
        m = _SCALED.match(unit)
        if m is not None:
            scale = float(m.group(1))
            unit = m.group(2)
            if not np.isfinite(scale) or scale == 0:
                raise InputError(f"{where}: unit factor must be finite and non-zero: '{unit}'")
        try:
            u = U.lookup(unit)
        except InputError:
            raise InputError(f"{where}: unknown unit '{unit}' for column '{source}' (known "
                             f"suffixes: {', '.join(sorted(U.SUFFIXES))})") from None
        if tdim is None:
            raise InputError(f"{where}: target '{target}' has no unit suffix, so the source "
                             f"unit '{unit}' cannot be converted; name the target with its "
                             "unit (e.g. ax_mps2)")
        if u.dimension != tdim:
            raise InputError(f"{where}: unit '{unit}' of column '{source}' is a {u.dimension}, "
                             f"but target '{target}' is a {tdim}")
        unit = u.name
    return MapEntry(target=target, source=source, unit=unit, scale=scale)


def parse_map(text: str | None, *, where: str = "--map") -> ColumnMap:
    """Parse ``target=source[:unit],...`` into a :class:`ColumnMap`.

    The last ``:`` of an entry separates the unit, so source names may contain ``:``
    only when a unit follows. Raises :class:`InputError` for a malformed entry, an
    unknown unit, a unit of the wrong dimension or a target given twice.
    """
    if text is None or not str(text).strip():
        return ColumnMap()
    entries = []
    seen = set()
    for raw in str(text).split(","):
        if not raw.strip():
            continue
        m = _ENTRY.match(raw)
        if m is None:
            raise InputError(f"{where}: entry {raw.strip()!r} is not target=source[:unit]")
        target, rhs = m.group(1), m.group(2)
        if ":" in rhs:
            source, unit = rhs.rsplit(":", 1)
        else:
            source, unit = rhs, None
        e = _check_entry(target, source, unit, where=where)
        if e.target in seen:
            raise InputError(f"{where}: target '{e.target}' is mapped twice")
        seen.add(e.target)
        entries.append(e)
    return ColumnMap(tuple(entries))


def load_map_file(path) -> tuple[ColumnMap, ParseOptions]:
    """Read a mapping file (``.json`` or ``.toml``): ``columns`` plus the parse options
    ``sep``, ``decimal``, ``skip_rows`` (all optional)."""
    p = Path(path)
    if not p.is_file():
        raise InputError("no such mapping file", path=p)
    try:
        if p.suffix.lower() == ".toml":
            with open(p, "rb") as fh:
                doc = tomllib.load(fh)
        else:
            doc = json.loads(p.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"mapping file is not valid {p.suffix.lstrip('.').upper() or 'JSON'} "
                         f"({' '.join(str(exc).split())})", path=p) from None
    if not isinstance(doc, dict):
        raise InputError("mapping file must hold an object/table", path=p)
    unknown = set(doc) - {"columns", "sep", "decimal", "skip_rows", "description", "vendor"}
    if unknown:
        raise InputError(f"unknown keys {sorted(unknown)} (known: columns, sep, decimal, "
                         "skip_rows, description, vendor)", path=p)
    cols = doc.get("columns", {})
    if not isinstance(cols, dict):
        raise InputError("'columns' must map target -> 'source[:unit]'", path=p)
    entries, where = [], str(p)
    for target, spec in cols.items():
        if isinstance(spec, dict):
            if "column" not in spec:
                raise InputError(f"columns.{target} needs 'column'", path=p)
            entries.append(_check_entry(target, str(spec["column"]), spec.get("unit"),
                                        where=where))
        elif isinstance(spec, str):
            entries.extend(parse_map(f"{target}={spec}", where=where).entries)
        else:
            raise InputError(f"columns.{target} must be 'source[:unit]' or a table", path=p)
    try:
        opts = ParseOptions(sep=doc.get("sep"), decimal=doc.get("decimal"),
                            skip_rows=doc.get("skip_rows"))
    except InputError as exc:
        raise InputError(str(exc), path=p) from None
    return ColumnMap(tuple(entries)), opts


# ----------------------------------------------------------------------------- sniffing

_PREAMBLE = ("#", "//")


def sniff(lines: list[str], opts: ParseOptions | None = None) -> tuple[int, str, str, list[str]]:
    """Decide ``(skip, sep, decimal, hash_lines)`` from the first lines of a text file.

    ``skip`` counts preamble lines before the header; ``hash_lines`` are the ``#``
    lines among them (for ``# key=value`` metadata).
    """
    opts = opts or ParseOptions()
    hash_lines: list[str] = []
    if opts.skip_rows is not None:
        skip = int(opts.skip_rows)
        hash_lines = [ln for ln in lines[:skip] if ln.lstrip().startswith("#")]
    else:
        skip = 0
        for ln in lines:
            s = ln.strip()
            if s.startswith(_PREAMBLE) or not s:
                if s.startswith("#"):
                    hash_lines.append(ln)
                skip += 1
            else:
                break
    header = lines[skip] if skip < len(lines) else ""
    body = [ln for ln in lines[skip + 1:skip + 21] if ln.strip()]
    sep = opts.sep
    if sep is None:
        counts = {c: header.count(c) for c in (",", ";", "\t")}
        best = max(counts, key=lambda c: counts[c])
        sep = best if counts[best] > 0 else (r"\s+" if len(header.split()) > 1 else ",")
    elif sep == " ":
        sep = r"\s+"
    dec = opts.decimal
    if dec is None:
        dec = "."
        if sep != "," and any(re.search(r"(?<![\d.])-?\d+,\d+(?![\d,]*\.)", ln) for ln in body):
            dec = ","
    return skip, sep, dec, hash_lines


# ----------------------------------------------------------------------------- applying

def _find_source(df: pd.DataFrame, name: str, *, path) -> str:
    if name in df.columns:
        return name
    low = name.strip().lower()
    hits = [c for c in df.columns if str(c).strip().lower() == low]
    if len(hits) == 1:
        return hits[0]
    shown = ", ".join(str(c) for c in list(df.columns)[:12])
    more = " ..." if df.shape[1] > 12 else ""
    raise InputError(f"mapped source column not in the file (columns: {shown}{more})",
                     path=path, column=name)


def _numeric(s: pd.Series, *, path, column: str) -> pd.Series:
    if pd.api.types.is_numeric_dtype(s) and not pd.api.types.is_bool_dtype(s):
        return s
    conv = pd.to_numeric(s, errors="coerce")
    bad = conv.isna().to_numpy() & s.notna().to_numpy()
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"non-numeric value '{s.iloc[i]}'", path=path, column=column, row=i + 1)
    return conv


def time_to_seconds(values: pd.Series, unit: str, *, path=None, column: str = "",
                    scale: float = 1.0) -> tuple[np.ndarray, float | int]:
    """Seconds since the first stamp, and the first stamp in ``unit``.

    Integer stamps (any integer dtype, or floats holding whole numbers below 2**53)
    are differenced in int64 before scaling, so ns since the epoch keep full resolution.
    """
    u = U.lookup(unit)
    if u.dimension != "time":
        raise InputError(f"unit '{unit}' is a {u.dimension}, expected a time", path=path,
                         column=column)
    s = _numeric(values, path=path, column=column)
    arr = s.to_numpy()
    if arr.size == 0:
        return np.zeros(0), 0
    if np.issubdtype(arr.dtype, np.integer):
        iv = arr.astype(np.int64)
    else:
        f = arr.astype(float)
        if np.all(np.isfinite(f)) and np.all(f == np.round(f)) and np.all(np.abs(f) < 2.0**53):
            iv = f.astype(np.int64)
        else:
            iv = None
    if iv is not None:
        t0 = int(iv[0])
        return U.convert((iv - t0).astype(np.float64) * scale, u.name, "s"), t0
    f = arr.astype(float)
    return U.convert((f - f[0]) * scale, u.name, "s"), float(f[0])


def apply_map(df: pd.DataFrame, cmap: ColumnMap, *, path=None, g_local: float | None = None,
              meta: dict | None = None) -> pd.DataFrame:
    """Return ``df`` with each mapped source column replaced by its converted target.

    Unmapped columns pass through unchanged. Time targets are made relative to the first
    stamp; the stamp itself goes to ``meta["time_origin"]`` (when ``meta`` is given).
    g-based units convert with ``g_local`` (default 9.80665 m/s^2).
    """
    if not cmap:
        return df
    g = U.G_STANDARD if g_local is None else float(g_local)
    out = {}
    used = set()
    for e in cmap.entries:
        src = _find_source(df, e.source, path=path)
        if src in used:
            raise InputError(f"source column mapped to two targets (second: {e.target})",
                             path=path, column=e.source)
        used.add(src)
        if e.target in _TIME_TARGETS:
            unit = e.unit or "s"
            t, t0 = time_to_seconds(df[src], unit, path=path, column=str(src), scale=e.scale)
            out[e.target] = t
            if meta is not None:
                meta["time_origin"] = {"column": str(src), "unit": unit, "value": t0}
            continue
        vals = _numeric(df[src], path=path, column=str(src))
        _, suf = U.split_suffix(e.target)
        if e.unit is not None and suf is not None:
            v = vals.to_numpy(dtype=float)
            v = v * e.scale if e.scale != 1.0 else v
            out[e.target] = np.asarray(U.convert(v, e.unit, suf, g_local=g), dtype=float)
        else:
            out[e.target] = vals.to_numpy()
    rest = {c: df[c] for c in df.columns if c not in used
            and str(c).strip().lower() not in out}
    res = pd.DataFrame({**out, **rest}, index=df.index)
    if meta is not None:
        meta["column_map"] = cmap.to_text()
    return res


def normalise_time_columns(df: pd.DataFrame, *, path=None, meta: dict | None = None
                           ) -> pd.DataFrame:
    """Turn a ``t_ms`` / ``t_us`` / ``t_ns`` column (integer stamps) into ``t_s`` seconds
    since the first stamp; a file that already has ``t_s`` is returned unchanged."""
    low = {str(c).strip().lower(): c for c in df.columns}
    if "t_s" in low:
        return df
    found = [(s, low[f"t_{s}"]) for s in _TIME_SUFFIXES if f"t_{s}" in low]
    if not found:
        return df
    if len(found) > 1:
        raise InputError("two time columns; keep one of "
                         + ", ".join(str(c) for _, c in found), path=path)
    unit, col = found[0]
    t, t0 = time_to_seconds(df[col], unit, path=path, column=str(col))
    if meta is not None:
        meta["time_origin"] = {"column": str(col), "unit": unit, "value": t0}
    pos = list(df.columns).index(col)
    out = df.drop(columns=[col])
    out.insert(pos, "t_s", t)
    return out


@dataclass
class ReadOptions:
    """Everything :func:`inertialab.io.read_record` takes for non-spec files, as one
    settings object (what ``--map``, ``--map-file``, ``--sep``, ``--decimal``,
    ``--skip-rows`` build)."""

    column_map: ColumnMap = field(default_factory=ColumnMap)
    parse: ParseOptions = field(default_factory=ParseOptions)

    @classmethod
    def from_cli(cls, map_text: str | None = None, map_file=None, *, sep: str | None = None,
                 decimal: str | None = None, skip_rows: int | None = None) -> ReadOptions:
        cmap, opts = (load_map_file(map_file) if map_file else (ColumnMap(), ParseOptions()))
        cmap = cmap.merged(parse_map(map_text))
        opts = ParseOptions(sep=sep if sep is not None else opts.sep,
                            decimal=decimal if decimal is not None else opts.decimal,
                            skip_rows=skip_rows if skip_rows is not None else opts.skip_rows)
        return cls(cmap, opts)
