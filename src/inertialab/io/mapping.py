"""Column mapping and parse options for files not written to a spec.

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
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from inertialab import units as U
from inertialab.errors import InputError
from inertialab.io.formats.text import ParseOptions
from inertialab.io.modelfile import unique_keys

if TYPE_CHECKING:  # numpy and pandas load when a table is mapped, not when a command starts
    import numpy as np
    import pandas as pd

__all__ = [
    "ColumnMap",
    "MapEntry",
    "ParseOptions",
    "apply_map",
    "load_map_file",
    "normalise_time_columns",
    "parse_map",
    "parse_unit_option",
    "shown_columns",
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


# ----------------------------------------------------------------------------- parsing

_ENTRY = re.compile(r"^\s*([^=\s]+)\s*=\s*(.+?)\s*$")
#: a unit with a numeric factor in front: ``100us`` (Xsens SampleTimeFine ticks),
#: ``0.000598mps2`` (an LSB size), ``1e-4*s``
_SCALED = re.compile(r"^([0-9]*\.?[0-9]+(?:[eE][+-]?[0-9]+)?)\s*\*?\s*([A-Za-z].*)$")


def _check_entry(target: str, source: str, unit: str | None, *, where: str) -> MapEntry:
    import numpy as np

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


def parse_map(text: str | None, *, where: str = "argument 'column_map'") -> ColumnMap:
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
            doc = json.loads(p.read_text(encoding="utf-8"), object_pairs_hook=unique_keys)
    except (tomllib.TOMLDecodeError, ValueError, UnicodeDecodeError) as exc:
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

def sniff(lines: list[str], opts: ParseOptions | None = None) -> tuple[int, str, str, list[str]]:
    """Decide ``(skip, sep, decimal, hash_lines)`` from the first lines of a text file.

    ``skip`` counts the lines before the (last) header row; ``hash_lines`` are the ``#``
    lines among them (for ``# key=value`` metadata). The full layout (header rows, units
    row, headerless files) is :func:`inertialab.io.formats.text.layout_of`.
    """
    from inertialab.io.formats.text import sniff_compat

    return sniff_compat(lines, opts)


# ----------------------------------------------------------------------------- applying

_POSITIONAL = re.compile(r"^col(\d+)$", re.IGNORECASE)


def shown_columns(df: pd.DataFrame, header_units: dict | None = None, limit: int = 16) -> str:
    """The frame's columns as the user sees them in the file (``Gyro X [deg/s]``)."""
    hu = header_units or {}
    names = [f"{c} [{hu[c]}]" if c in hu else str(c) for c in list(df.columns)[:limit]]
    more = f" ... ({df.shape[1]} in all)" if df.shape[1] > limit else ""
    return ", ".join(names) + more


def _find_source(df: pd.DataFrame, name: str, *, path, header_units=None) -> str:
    if name in df.columns:
        return name
    low = name.strip().lower()
    hits = [c for c in df.columns if str(c).strip().lower() == low]
    if len(hits) == 1:
        return hits[0]
    hu = header_units or {}
    hits = [c for c in df.columns if c in hu and f"{c} [{hu[c]}]".lower() == low]
    if len(hits) == 1:
        return hits[0]
    m = _POSITIONAL.match(name.strip())
    if m is not None and 1 <= int(m.group(1)) <= df.shape[1]:
        return df.columns[int(m.group(1)) - 1]
    raise InputError(f"mapped source column not in the file (columns: "
                     f"{shown_columns(df, header_units)}; colN picks the N-th)",
                     path=path, column=name)


def _numeric(s: pd.Series, *, path, column: str) -> pd.Series:
    import numpy as np
    import pandas as pd

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
    import numpy as np

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
              meta: dict | None = None, header_units: dict | None = None,
              unit_option=None) -> pd.DataFrame:
    """Return ``df`` with each mapped source column replaced by its converted target.

    Unmapped columns pass through unchanged. Time targets are made relative to the first
    stamp; the stamp itself goes to ``meta["time_origin"]`` (when ``meta`` is given).
    g-based units convert with ``g_local`` (default 9.80665 m/s^2). An entry without a
    unit takes the unit of the file's units header row, or of a bracket in the source's
    name (``Gyro X (deg/s)``); else an acceleration or angular-rate target takes the unit
    the data decide (:mod:`inertialab.io.unit_check`: a warning, recorded in
    ``meta["inferred_units"]``), unless the sidecar's ``units`` (``{base: unit}``, the
    source's unit, converted) or the reading option ``unit`` (``unit_option``, the
    values relabelled) declares it; a column whose unit nothing declares or decides is an
    :class:`InputError` naming it and the units it could be.
    """
    import numpy as np
    import pandas as pd

    from inertialab.io.formats.text import unit_suffix

    if not cmap:
        return df
    g = U.G_STANDARD if g_local is None else float(g_local)
    entries = [_with_source_unit(e, _find_source(df, e.source, path=path,
                                                 header_units=header_units),
                                 header_units, unit_suffix) for e in cmap.entries]
    entries = _infer_units(df, entries, path=path, meta=meta, header_units=header_units,
                           unit_option=unit_option)
    out = {}
    used = set()
    for e in entries:
        src = _find_source(df, e.source, path=path, header_units=header_units)
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


def _with_source_unit(e: MapEntry, src, header_units, unit_suffix) -> MapEntry:
    """The entry with the unit of the source's units-header cell or name bracket."""
    if e.unit is not None:
        return e
    text = (header_units or {}).get(src)
    if text is None:
        from inertialab.io.suggest import canonical_guess, name_unit

        guess = canonical_guess(str(src))
        text = guess[1] if guess and guess[1] else name_unit(str(src))
    suf = unit_suffix(text) if text else None
    return e if suf is None else MapEntry(e.target, e.source, suf, e.scale)


def _declared_by_option(dim: str, base: str, unit_option) -> bool:
    if unit_option is None:
        return False
    if isinstance(unit_option, dict):
        return base in unit_option
    return any(U.SUFFIXES.get(p.strip()) is not None
               and U.SUFFIXES[p.strip()].dimension == dim for p in str(unit_option).split(","))


def _infer_units(df, entries, *, path, meta, header_units, unit_option) -> list[MapEntry]:
    """Entries whose measurement target has no source unit get the unit the data decide
    (:mod:`inertialab.io.unit_check`), or an error naming the column."""
    import warnings

    import numpy as np

    from inertialab.errors import DataQualityWarning
    from inertialab.io.unit_check import CANDIDATES, infer_unit

    todo = []
    side = (meta or {}).get("units")
    for i, e in enumerate(entries):
        if e.unit is not None or e.target in _TIME_TARGETS:
            continue
        base, suf = U.split_suffix(e.target)
        dim = U.SUFFIXES[suf].dimension if suf is not None else None
        declared = side.get(base) if isinstance(side, dict) else None
        if dim in CANDIDATES and declared is not None and declared in U.SUFFIXES \
                and U.SUFFIXES[declared].dimension == dim:
            entries[i] = MapEntry(e.target, e.source, declared, e.scale)  # the sidecar's unit
        elif dim in CANDIDATES and not _declared_by_option(dim, base, unit_option):
            todo.append((i, e, base, dim))
    if not todo:
        return entries
    col = {i: _numeric(df[_find_source(df, e.source, path=path, header_units=header_units)],
                       path=path, column=e.source).to_numpy(dtype=float) * e.scale
           for i, e, _, _ in todo}
    acc = {b: i for i, _, b, d in todo if d == "acceleration" and b in ("ax", "ay", "az")}
    triad = np.column_stack([col[acc[b]] for b in ("ax", "ay", "az")]) if len(acc) == 3 else None
    out = list(entries)
    for i, e, base, dim in todo:
        unit, why = infer_unit(dim, col[i], triad if base in acc else None)
        cands = CANDIDATES[dim]
        if unit is None:
            raise InputError(f"mapped to '{e.target}' without a unit, and {why}: declare the "
                             f"source's unit ({e.target}={e.source}:{'|'.join(cands)}) or give "
                             "argument 'unit'", path=path, column=e.source)
        out[i] = MapEntry(e.target, e.source, unit, e.scale)
        where = f"{path}: " if path else ""
        warnings.warn(f"{where}column '{e.source}' mapped to '{e.target}' without a unit: "
                      f"{why}, so it is read in {unit} (declare it: "
                      f"{e.target}={e.source}:{unit})", DataQualityWarning, stacklevel=5)
        if meta is not None:
            meta.setdefault("inferred_units", {})[e.target] = {
                "source": str(e.source), "unit": unit, "evidence": why}
    return out


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


def parse_unit_option(value):
    """The ``unit`` reading option: None, one suffix (``dps``), a list of suffixes, one per
    dimension (``g,dps``: accelerometer columns in g, gyro columns in deg/s), or a unit
    per column (``gx=dps,ax=g``; keys are column bases). Header spellings (``deg/s``)
    are accepted. Returns None, a suffix string (``"g,dps"`` kept as text) or a dict."""
    from inertialab.io.formats.text import unit_suffix

    if value is None or isinstance(value, dict):
        return None if not value else {str(k).strip().lower(): _suffix_or_error(v, unit_suffix)
                                       for k, v in value.items()}
    text = str(value).strip()
    if not text:
        return None
    if any(not part.strip() for part in text.split(",")):
        raise InputError(f"argument 'unit' has an empty entry in {text[:60]!r}: give one "
                         "suffix (dps), one per dimension (g,dps) or column=unit pairs")
    if "=" not in text:
        return ",".join(_suffix_or_error(u, unit_suffix) for u in text.split(",") if u.strip())
    out = {}
    for part in text.split(","):
        if not part.strip():
            continue
        key, sep, unit = part.partition("=")
        if not sep or not key.strip():
            raise InputError(f"argument 'unit': entry {part.strip()!r} is not column=unit")
        out[key.strip().lower()] = _suffix_or_error(unit, unit_suffix)
    return out


def _suffix_or_error(unit, unit_suffix) -> str:
    u = str(unit).strip()
    if u.lower() in U.SUFFIXES:
        return u.lower()
    suf = unit_suffix(u)
    if suf is None:
        raise InputError(f"argument 'unit': unknown unit '{u}' (known suffixes: "
                         f"{', '.join(sorted(U.SUFFIXES))})")
    return suf


@dataclass
class ReadOptions:
    """Everything :func:`inertialab.io.read_record` takes for files not written to a
    spec, as one settings object: what the command line's reading options build
    (``--map``, ``--map-file``, ``--sep``, ``--decimal``, ``--skip-rows``,
    ``--time-col``, ``--time-unit``, ``--rate``, ``--unit``, ``--topic``,
    ``--instance``, ``--dataset``, ``--join``, ``--resample``).

    Attributes
    ----------
    column_map : ColumnMap
        Canonical target <- source column (and unit); ``colN`` names the N-th column.
    parse : ParseOptions
        Separator, decimal mark, preamble lines of a text file.
    rate_hz : float or None
        Sample rate, Hz, for a record without a time column (a ``t_s`` column is then
        built as ``i / rate_hz`` and ``meta["fs_hz"]`` set).
    unit : str, dict or None
        See :func:`parse_unit_option`.
    time_column, time_unit : str or None
        The column holding time stamps and their unit (``s ms us ns``); becomes ``t_s``
        in seconds since the first stamp.
    topic : str or None
        ROS bag topic (``/imu/data``) or PX4 ULog message (``sensor_combined``,
        ``sensor_gyro``, ``sensor_accel``); default: the only IMU topic.
    instance : int or None
        ULog multi-instance id (``sensor_gyro`` 0, 1, 2 ...); default 0.
    dataset : str or None
        MATLAB variable or HDF5 dataset path (``imu/gyro`` or ``imu.gyro``).
    join : tuple of paths
        Further files (imu_tk-style ``time x y z`` text) joined to the first on time.
    resample_hz : float or None
        Resample a jittery log onto a uniform grid at this rate (linear interpolation);
        only when asked, recorded in ``meta["resampled"]``.

    Examples
    --------
    A headerless one-column file in deg/s, logged at 200 Hz: the map names the column and
    its unit (converted to the canonical deg/h), the rate builds the time column:

    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> _ = (folder / "raw.csv").write_text("0.5\\n0.7\\n0.6\\n")
    >>> from inertialab.io import read_record
    >>> opts = ReadOptions.from_cli("rate_dph=col1:dps", rate=200.0)
    >>> rec = read_record(folder / "raw.csv", "gyro_log", options=opts)
    >>> rec.column("rate_dph").tolist(), rec.column("t_s").tolist()
    ([1800.0, 2520.0, 2160.0], [0.0, 0.005, 0.01])
    >>> tmp.cleanup()
    """

    column_map: ColumnMap = field(default_factory=ColumnMap)
    parse: ParseOptions = field(default_factory=ParseOptions)
    rate_hz: float | None = None
    unit: str | dict | None = None
    time_column: str | None = None
    time_unit: str | None = None
    topic: str | None = None
    instance: int | None = None
    dataset: str | None = None
    join: tuple = ()
    resample_hz: float | None = None

    def __post_init__(self):
        import numpy as np

        for name in ("rate_hz", "resample_hz"):
            v = getattr(self, name)
            if v is not None:
                try:
                    v = float(v)
                except (TypeError, ValueError):
                    raise InputError(f"argument '{name}' must be a number, got {v!r}") from None
                if not np.isfinite(v) or not 1e-9 <= v <= 1e9:
                    raise InputError(f"argument '{name}' must be a rate between 1e-9 and 1e9 "
                                     f"Hz, got {v!r}")
                setattr(self, name, v)
        if self.time_unit is not None:
            try:
                u = U.lookup(self.time_unit)
            except InputError:
                u = None
            if u is None or u.dimension != "time":
                raise InputError(f"argument 'time_unit' must be a time unit (s, ms, us, ns), "
                                 f"got {self.time_unit!r}")
            self.time_unit = u.name
        if self.instance is not None and int(self.instance) < 0:
            raise InputError(f"argument 'instance' must be >= 0, got {self.instance}")
        self.unit = parse_unit_option(self.unit)
        self.join = tuple(self.join or ())

    def effective_map(self) -> ColumnMap:
        """The column map with the time column option folded in as a ``t_s`` entry."""
        if self.time_column is None or any(e.target == "t_s" for e in self.column_map.entries):
            return self.column_map
        return self.column_map.merged(ColumnMap((MapEntry(
            "t_s", self.time_column, self.time_unit or "s"),)))

    def settings(self) -> dict:
        """The non-default options, for a result's ``settings`` (JSON-ready)."""
        out = {}
        if self.column_map:
            out["column_map"] = self.column_map.to_text()
        if not self.parse.is_default:
            out["parse"] = self.parse.to_dict()
        for k in ("rate_hz", "unit", "time_column", "time_unit", "topic", "instance",
                  "dataset", "resample_hz"):
            v = getattr(self, k)
            if v is not None:
                out[k] = v
        if self.join:
            out["join"] = [str(j) for j in self.join]
        return out

    def reusable(self) -> dict:
        """The options a model keeps to read the next file as its training file was
        read (JSON-ready, non-default only): the map (its content, also when it came
        from a map file), units, rate, separators, time column, topic ... never the
        paths of joined files."""
        return {k: v for k, v in self.settings().items() if k != "join"}

    def over(self, stored: dict | None) -> ReadOptions:
        """These options, each one left at its default taken from ``stored`` (a
        :meth:`reusable` dict; None or empty: these unchanged): what the user gives
        now wins, option by option."""
        if not stored:
            return self
        kw = {}
        if not self.column_map and stored.get("column_map"):
            kw["column_map"] = parse_map(stored["column_map"])
        if self.parse.is_default and stored.get("parse"):
            from inertialab.io.formats.text import ParseOptions

            kw["parse"] = ParseOptions(**{k: stored["parse"].get(k)
                                          for k in ("sep", "decimal", "skip_rows")})
        for k in ("rate_hz", "unit", "time_column", "time_unit", "topic", "instance",
                  "dataset", "resample_hz"):
            if getattr(self, k) is None and stored.get(k) is not None:
                kw[k] = stored[k]
        return replace(self, **kw) if kw else self

    @classmethod
    def from_cli(cls, map_text: str | None = None, map_file=None, *, sep: str | None = None,
                 decimal: str | None = None, skip_rows: int | None = None,
                 time_col: str | None = None, time_unit: str | None = None,
                 rate: float | None = None, unit=None, topic: str | None = None,
                 instance: int | None = None, dataset: str | None = None,
                 join=None, resample: float | None = None) -> ReadOptions:
        cmap, opts = (load_map_file(map_file) if map_file else (ColumnMap(), ParseOptions()))
        cmap = cmap.merged(parse_map(map_text))
        opts = ParseOptions(sep=sep if sep is not None else opts.sep,
                            decimal=decimal if decimal is not None else opts.decimal,
                            skip_rows=skip_rows if skip_rows is not None else opts.skip_rows)
        return cls(cmap, opts, rate_hz=rate, unit=unit, time_column=time_col,
                   time_unit=time_unit, topic=topic, instance=instance, dataset=dataset,
                   join=tuple(join or ()), resample_hz=resample)
