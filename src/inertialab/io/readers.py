"""Readers: CSV / Parquet / memory-mapped ``.npy`` -> validated :class:`Record`.

``read_record(path, kind)`` loads a file, finds its sidecar or ``# key=value`` header,
maps column spellings to the canonical names of the kind's schema, resolves units,
checks types, finiteness, time order and size, and hashes the canonical columns.
Every failure is an :class:`~inertialab.errors.InputError` naming the file, column
and row (rows are counted from 1 = first data row, as a spreadsheet shows them below
the header).
"""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from inertialab.errors import DataQualityWarning, InputError
from inertialab.io import front_door
from inertialab.io.formats.npy import check_rate as _check_rate
from inertialab.io.formats.npy import open_npy as _open_npy
from inertialab.io.record import Record
from inertialab.io.schema import Column, Schema
from inertialab.io.schemas import SCHEMAS
from inertialab.io.sidecar import read_sidecar
from inertialab.units import SUFFIXES, split_suffix

_MAX_ROWS_LISTED = 5
#: Largest magnitude accepted in any numeric cell (1e100: squares and sums of larger
#: values overflow float64; no measurement or time stamp comes near it).
MAX_MAGNITUDE = 1e100


# ---------------------------------------------------------------------------- loading

def _load_table(path: Path, parse=None) -> tuple[pd.DataFrame, dict]:
    """Text or Parquet table -> (frame with the user's column names, header metadata).

    The header's units row (when there is one) is in ``frame.attrs["header_units"]``.
    """
    from inertialab.io.formats.dispatch import load_frame

    loaded = load_frame(path, parse=parse)
    loaded.frame.attrs["header_units"] = loaded.header_units
    return loaded.frame, loaded.meta


def read_record(path, kind: str, *, unit=None, rate_hz: float | None = None,
                column: str | None = None, g_local: float | None = None,
                column_map=None, parse=None, gaps: str | None = None,
                full_scale=None, options=None) -> Record:
    """Read and validate a record file of ``kind`` (the one front door).

    Parameters
    ----------
    path : str or Path
        By suffix: ``.csv``/``.txt``/``.tsv``/``.dat`` and other text (header rows,
        separator and decimal mark sniffed; optional ``# key=value`` lines),
        ``.parquet``, ``.npy`` (one column memory-mapped, or a 2-D/structured array),
        ``.mat`` (v5 via scipy, v7.3 via h5py; imu_tk's text ``.mat`` too),
        ``.h5``/``.hdf5``, ``.bag`` (ROS 1), ``.db3``/``.mcap`` or a ROS 2 bag folder,
        ``.ulg`` (PX4 ULog). See :mod:`inertialab.io.formats`.
    kind : str
        One of :data:`inertialab.io.schemas.SCHEMAS`.
    unit : str or dict, optional
        Unit override: a suffix applied to the measurement columns whose allowed
        dimensions include it, a comma list (``"g,dps"``, one per dimension), or
        ``{base: suffix}`` / ``"gx=dps,ax=g"``. Overrides column suffixes, which
        override the sidecar's ``units``.
    rate_hz : float, optional
        Sample rate for a log without time stamps (``.npy``, or a table without a time
        column: ``t_s`` is then built as ``i / rate_hz``); else the sidecar's ``fs_hz``.
    column : str, optional
        Canonical column name for a one-column ``.npy`` log (e.g. ``rate_dph``).
    g_local : float, optional
        Local gravity, m/s^2; stored in ``meta["g_local_mps2"]`` when given.
    column_map : ColumnMap or str, optional
        Canonical target <- source column and unit, applied before validation
        (:func:`inertialab.io.mapping.parse_map`; ``colN`` is the N-th column).
        Columns ``t_ms``/``t_us``/``t_ns`` become ``t_s`` with or without a map.
    parse : ParseOptions, optional
        Separator, decimal mark and preamble lines of a text file (default: sniffed).
    gaps : {None, "error", "split"}, default None
        Time-stamp policy for continuous logs (:mod:`inertialab.io.gaps`).
    full_scale : dict, float, "auto" or None
        Flag samples at full scale in a ``saturated`` column.
    options : ReadOptions, optional
        The reading options of the front door (:class:`inertialab.io.mapping.ReadOptions`);
        each of its fields is used where the matching argument above is not given, and it
        carries what only it has: time column and unit, topic, instance, dataset, joined
        files, resampling.

    The time stamps of a continuous log are audited (:mod:`inertialab.io.timestamps`):
    mean rate, jitter, gaps, dropped and repeated samples go to ``meta["timestamps"]``.

    Raises
    ------
    InputError
        Missing or empty file, unreadable format, missing column, non-numeric or
        non-finite value, bad time order, too few rows, unknown unit suffix.

    Examples
    --------
    A CSV with a unit-suffixed column and a sidecar giving the rate:

    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> import numpy as np
    >>> import pandas as pd
    >>> from inertialab.io import write_record
    >>> rate = np.random.default_rng(0).normal(0.0, 1.0, 200)
    >>> frame = pd.DataFrame({"t_s": np.arange(200) / 100.0, "rate_dph": rate})
    >>> path = write_record(frame, folder / "gyro.csv", {"fs_hz": 100.0})
    >>> rec = read_record(path, "gyro_log")
    >>> rec.n, rec.timebase.rate_hz, rec.timebase.source
    (200, 100.0, 'sidecar')
    >>> bool(np.array_equal(rec.column("rate_dph"), rate))
    True
    >>> tmp.cleanup()
    """
    if kind not in SCHEMAS:
        raise InputError(f"unknown record kind '{kind}' (known: {', '.join(SCHEMAS)})")
    front_door.note(path)
    try:
        return _read_record(path, kind, unit=unit, rate_hz=rate_hz, column=column,
                            g_local=g_local, column_map=column_map, parse=parse, gaps=gaps,
                            full_scale=full_scale, options=options)
    except InputError as exc:  # every message leaving the front door names its file
        exc.naming(path)
        raise


def _read_record(path, kind, *, unit, rate_hz, column, g_local, column_map, parse, gaps,
                 full_scale, options) -> Record:
    from inertialab.io.mapping import ReadOptions, parse_map, parse_unit_option

    opts = options if options is not None else ReadOptions()
    if column_map is None:
        column_map = opts.effective_map()
    elif isinstance(column_map, str):
        column_map = parse_map(column_map)
    parse = opts.parse if parse is None else parse
    unit = opts.unit if unit is None else parse_unit_option(unit)
    rate_hz = opts.rate_hz if rate_hz is None else rate_hz
    p = Path(path)
    if not p.exists():
        raise InputError("no such file", path=p)
    from inertialab.io.formats.dispatch import is_bag_folder

    if p.is_dir() and not is_bag_folder(p):
        raise InputError("is a directory, expected a file", path=p)
    if p.is_file() and p.stat().st_size == 0:
        raise InputError("empty file", path=p)
    meta = read_sidecar(p)
    if g_local is not None:
        meta["g_local_mps2"] = float(g_local)
    if p.suffix.lower() == ".npy":
        arr = _open_npy(p)
        if arr.dtype.names is None and (arr.ndim == 1 or (arr.ndim == 2 and arr.shape[1] == 1)):
            return _read_npy(p, kind, meta, arr, unit=unit, rate_hz=rate_hz, column=column)
    from inertialab.io.formats.dispatch import load_frame

    loaded = load_frame(p, parse=parse, options=opts)
    df, header_units = loaded.frame, dict(loaded.header_units)
    merged = dict(loaded.meta)
    merged.update(meta)
    if opts.join:
        from inertialab.io.formats.imu_tk import join_on_time

        df, jmeta = join_on_time(p, df, opts.join, parse=parse, options=opts)
        merged["join"] = jmeta
    return _finish(df, kind, p, merged, header_units=header_units, column_map=column_map,
                   parse=parse, unit=unit, rate_hz=rate_hz, gaps=gaps, full_scale=full_scale,
                   options=opts)


def peek_columns(path, options=None) -> list[str]:
    """Column names of a file as :func:`read_record` will see them before validation:
    lower-case, BOM dropped, the column map's targets in place of their sources, a time
    column given by the options as ``t_s``. Reads a few rows of a text file (after the
    size and content checks), so a CLI can choose a record kind (``t_s`` present: a raw
    log) without reading the file twice or sniffing headers itself.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> _ = (folder / "log.csv").write_text("Time_s,Rate_DPH\\n0,1\\n0.01,2\\n")
    >>> peek_columns(folder / "log.csv")
    ['time_s', 'rate_dph']
    >>> tmp.cleanup()
    """
    from inertialab.io.mapping import ReadOptions

    try:
        return _peek_columns(Path(path), options if options is not None else ReadOptions())
    except InputError as exc:
        exc.naming(path)
        raise


def _peek_columns(p: Path, opts) -> list[str]:
    from inertialab.io.formats.dispatch import format_of, load_frame
    from inertialab.io.formats.text import load_text

    if not p.exists():
        raise InputError("no such file", path=p)
    if p.is_file() and p.stat().st_size == 0:
        raise InputError("empty file", path=p)
    if format_of(p) == "text":
        names = list(load_text(p, opts.parse, nrows=5).frame.columns)
    elif p.suffix.lower() == ".npy" and _open_npy(p).dtype.names is None \
            and _open_npy(p).ndim == 1:
        names = []  # one unnamed column: its name comes from the column/unit arguments
    else:
        names = list(load_frame(p, parse=opts.parse, options=opts).frame.columns)
    cmap = opts.effective_map()
    sources = {e.source.strip().lower(): e.target for e in cmap.entries}
    out = []
    for j, n in enumerate(names):
        low = str(n).strip().lower()
        out.append(sources.get(low) or sources.get(f"col{j + 1}") or low)
    if opts.time_unit is not None and opts.time_column is None:
        out = ["t_s" if n in _TIME_NAMES else n for n in out]
    if any(n in ("t_ms", "t_us", "t_ns") for n in out) and "t_s" not in out:
        out = ["t_s" if n in ("t_ms", "t_us", "t_ns") else n for n in out]
    return out


def _finish(df, kind, p, merged, *, header_units, column_map, parse, unit, rate_hz, gaps,
            full_scale, options) -> Record:
    """Map, time base, audit, validate: the part every format shares."""
    from inertialab.io.mapping import apply_map

    schema = SCHEMAS[kind]
    if column_map:
        df = apply_map(df, column_map, path=p, g_local=merged.get("g_local_mps2"), meta=merged,
                       header_units=header_units, unit_option=unit)
    if options.time_unit is not None and options.time_column is None:
        df = _time_unit_only(df, options.time_unit, path=p, meta=merged)
    if schema.time_column == "t_s":
        df = _time_from_rate(df, rate_hz, path=p, meta=merged)
    if parse is not None and not parse.is_default:
        merged["parse"] = parse.to_dict()
    return validate_frame(df, kind, path=p, meta=merged, unit=unit, gaps=gaps,
                          full_scale=full_scale, header_units=header_units,
                          resample_hz=options.resample_hz, rate_hz=rate_hz)


_TIME_NAMES = ("t", "time", "timestamp", "stamp", "time_s", "timestamp_s")


def _time_unit_only(df: pd.DataFrame, time_unit: str, *, path, meta) -> pd.DataFrame:
    from inertialab.io.mapping import time_to_seconds

    low = {str(c).strip().lower(): c for c in df.columns}
    col = next((low[n] for n in _TIME_NAMES if n in low), None)
    if col is None:
        raise InputError("argument 'time_unit' given but no column named t, time or timestamp; "
                         "name the time column (argument 'time_column')", path=path)
    t, t0 = time_to_seconds(df[col], time_unit, path=path, column=str(col))
    meta["time_origin"] = {"column": str(col), "unit": time_unit, "value": t0}
    out = df.drop(columns=[col])
    out.insert(0, "t_s", t)
    return out


def _time_from_rate(df: pd.DataFrame, rate_hz, *, path, meta) -> pd.DataFrame:
    """A log without a time column gets ``t_s = i / rate`` (rate from the argument or the
    sidecar's ``fs_hz``); the rate goes to ``meta["fs_hz"]``."""
    low = {str(c).strip().lower() for c in df.columns}
    has_t = bool(low & {"t_s", "t_ms", "t_us", "t_ns"})
    fs = rate_hz if rate_hz is not None else (meta.get("fs_hz") if not has_t else None)
    if fs is None:
        return df
    fs = _check_rate(fs, path=path, where="argument 'rate_hz'" if rate_hz is not None
                     else "sidecar key 'fs_hz'")
    meta["fs_hz"] = fs
    if has_t:
        return df
    out = df.copy()
    out.insert(0, "t_s", np.arange(len(df), dtype=float) / fs)
    meta["time_from_rate"] = True
    return out


def _read_npy(p: Path, kind: str, meta: dict, arr, *, unit, rate_hz, column) -> Record:
    from inertialab.io.formats.npy import read_npy_column

    return read_npy_column(p, kind, meta, arr, unit=unit, rate_hz=rate_hz, column=column)


# ---------------------------------------------------------------------------- columns

def _normalise(name) -> str:
    return str(name).strip().lower()


def _override_unit(col: Column, unit) -> str | None:
    if unit is None:
        return None
    if isinstance(unit, dict):
        u = unit.get(col.name)
        return None if u is None else str(u).lower()
    for part in str(unit).lower().split(","):  # "g,dps": one unit per dimension
        u = SUFFIXES.get(part.strip())
        if u is None:
            raise InputError(f"unknown unit '{part.strip()}' (known suffixes: "
                             f"{', '.join(sorted(SUFFIXES))})")
        if u.dimension in col.dimensions:
            return part.strip()
    return None


def _meta_unit(col: Column, meta: dict) -> str | None:
    units = meta.get("units")
    if isinstance(units, dict):
        u = units.get(col.name)
        return None if u is None else str(u).lower()
    if isinstance(units, str):
        u = SUFFIXES.get(units.lower())
        if u is not None and u.dimension in col.dimensions:
            return units.lower()
    return None


def _suffix_against_sidecar(col: Column, orig: str, suf: str, meta: dict, path) -> None:
    """A column whose suffix names its unit while the sidecar's ``units`` gives it
    another is refused (neither silently wins); the same unit is fine."""
    units = meta.get("units")
    if meta.get("column_map"):  # a mapped column's sidecar unit is its source's
        from inertialab.io.mapping import parse_map

        if orig in {e.target for e in parse_map(str(meta["column_map"])).entries}:
            return
    said = None
    if isinstance(units, dict):
        said = units.get(orig, units.get(col.name))
        said = None if said is None else str(said).strip().lower()
    elif isinstance(units, str) and SUFFIXES.get(units.strip().lower()) is not None and \
            SUFFIXES[units.strip().lower()].dimension in col.dimensions:
        said = units.strip().lower()
    if said is None or said == suf or SUFFIXES.get(said) is SUFFIXES.get(suf):
        return
    raise InputError(f"the column suffix says '{suf}' but the header says units={said} "
                     "(sidecar or '# units=' line); fix one of them or give argument 'unit'",
                     path=path, column=orig)


def _resolve_columns(df: pd.DataFrame, schema: Schema, *, path, meta, unit):
    """Rename df columns to canonical names; return (df, units, present_bases)."""
    norm = [_normalise(c) for c in df.columns]
    seen: dict[str, int] = {}
    for i, n in enumerate(norm):
        if n in seen:
            raise InputError(f"duplicated column (also column {seen[n] + 1})", path=path,
                             column=df.columns[i])
        seen[n] = i
    rename: dict[str, str] = {}
    units: dict[str, str] = {}
    present: set[str] = set()
    flex = sorted((c for c in schema.columns if c.flexible), key=lambda c: -len(c.name))
    fixed = {c.name: c for c in schema.columns if not c.flexible}
    alias_to_fixed = {}
    for c in fixed.values():
        alias_to_fixed[c.name] = c.name
        for a in c.aliases:
            alias_to_fixed[_normalise(a)] = c.name
    for orig, n in zip(df.columns, norm):
        if n in alias_to_fixed:
            target = alias_to_fixed[n]
            if target in present:
                raise InputError(f"two columns give '{target}'", path=path, column=orig)
            rename[orig] = target
            present.add(target)
            continue
        base, suf = split_suffix(n)
        col = next((c for c in flex if c.name == base), None)
        if col is None and suf is None:
            col = next((c for c in flex if c.name == n), None)
            base = n if col is not None else base
        if col is None:
            # unknown suffix on a measurement base: 'rate_furlong'
            for c in flex:
                if n.startswith(c.name + "_"):
                    rest = n[len(c.name) + 1:]
                    if "_" not in rest and not any(x.name == n for x in flex):
                        raise InputError(f"unknown unit suffix '{rest}' (known: "
                                         f"{', '.join(sorted(SUFFIXES))})", path=path, column=orig)
            rename[orig] = n
            continue
        override = _override_unit(col, unit)
        if override is not None:
            suf = override
        elif suf is None:
            suf = _meta_unit(col, meta)
        else:
            _suffix_against_sidecar(col, orig, suf, meta, path)
        if suf is None:
            raise InputError(f"no unit: add a suffix (e.g. {col.name}_{_example_suffix(col)}) "
                             "or give argument 'unit'", path=path, column=orig)
        dim = SUFFIXES[suf].dimension
        if dim not in col.dimensions:
            raise InputError(f"unit '{suf}' is a {dim}, expected a {' or '.join(col.dimensions)}",
                             path=path, column=orig)
        target = f"{col.name}_{suf}"
        if col.name in present:
            raise InputError(f"two columns give '{col.name}'", path=path, column=orig)
        rename[orig] = target
        units[target] = suf
        present.add(col.name)
    return df.rename(columns=rename), units, present


_PREFERRED = {"acceleration": "mps2", "angular_rate": "dph", "angle": "arcsec", "counts": "lsb",
              "current": "ma", "time": "s", "ratio": "ppm"}


def _example_suffix(col: Column) -> str:
    if col.dimensions and col.dimensions[0] in _PREFERRED:
        return _PREFERRED[col.dimensions[0]]
    for s, u in SUFFIXES.items():
        if u.dimension == col.dimensions[0] and s not in ("g",):
            return s
    return "s"


# ---------------------------------------------------------------------------- values

def _bad_rows(mask: np.ndarray) -> list[int]:
    return (np.flatnonzero(mask)[:_MAX_ROWS_LISTED] + 1).tolist()


def _coerce_numeric(series: pd.Series, col: Column, *, path, name: str) -> pd.Series:
    if not pd.api.types.is_numeric_dtype(series) or pd.api.types.is_bool_dtype(series):
        conv = pd.to_numeric(series, errors="coerce")
        raw = series.astype("string")
        empty = series.isna() | raw.str.strip().isin(["", "nan", "NaN", "inf", "-inf", "Inf"])
        bad = conv.isna().to_numpy() & ~empty.fillna(True).to_numpy()
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise InputError(f"non-numeric value '{series.iloc[i]}'", path=path, column=name,
                             row=i + 1)
        series = conv.astype(float)
    if series.dtype == np.float64:
        values = series.to_numpy()  # a view: no copy of a long log
    else:
        values = series.to_numpy(dtype=float, na_value=np.nan)
    if col.finite or col.required:
        nonfinite = ~np.isfinite(values)
        if nonfinite.any():
            rows = _bad_rows(nonfinite)
            what = "empty cell or NaN" if np.isnan(values[rows[0] - 1]) else "infinite value"
            raise InputError(what, path=path, column=name, row=rows if len(rows) > 1 else rows[0])
    with np.errstate(invalid="ignore"):
        huge = np.abs(values) > MAX_MAGNITUDE
    if huge.any():  # sums of squares of such values overflow to inf/NaN
        i = int(np.flatnonzero(huge)[0])
        raise InputError(f"value {values[i]:.3g} is beyond {MAX_MAGNITUDE:g} in magnitude "
                         "(no sensor reads that; the arithmetic would overflow)",
                         path=path, column=name, row=i + 1)
    if col.kind == "int":
        finite = np.isfinite(values)
        frac = finite & (np.abs(values - np.round(values)) > 1e-9)
        if frac.any():
            i = int(np.flatnonzero(frac)[0])
            raise InputError(f"expected a whole number, got {values[i]!r}", path=path, column=name,
                             row=i + 1)
        if finite.all():
            return pd.Series(np.round(values).astype(np.int64), index=series.index, name=name)
    if series.dtype == np.float64 and series.name == name:
        return series  # unchanged: the caller keeps the frame without a copy
    return pd.Series(values, index=series.index, name=name)


_TRUE = {"true", "1", "yes", "y", "t"}
_FALSE = {"false", "0", "no", "n", "f"}


def _coerce(df: pd.DataFrame, schema: Schema, *, path) -> pd.DataFrame:
    out = {}
    for name in df.columns:
        base, _ = split_suffix(name)
        col = schema.column(name) or next(
            (c for c in schema.columns if c.flexible and c.name == base), None)
        s = df[name]
        if col is None:
            out[name] = s
            continue
        if col.kind in ("float", "int"):
            out[name] = _coerce_numeric(s, col, path=path, name=name)
        elif col.kind == "str":
            if col.required and s.isna().any():
                raise InputError("empty cell", path=path, column=name,
                                 row=_bad_rows(s.isna().to_numpy())[0])
            out[name] = s.astype("string").str.strip() if not s.isna().all() else s
        elif col.kind == "bool":
            low = s.astype("string").str.strip().str.lower()
            good = low.isin(_TRUE | _FALSE) | s.isna()
            if not good.all():
                i = int(np.flatnonzero(~good.to_numpy())[0])
                raise InputError(f"expected true/false, got '{s.iloc[i]}'", path=path, column=name,
                                 row=i + 1)
            out[name] = low.isin(_TRUE) | s.isna()
        elif col.kind == "datetime":
            conv = pd.to_datetime(s, errors="coerce", utc=True, format="mixed")
            bad = conv.isna().to_numpy() & s.notna().to_numpy()
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                raise InputError(f"not an ISO-8601 date/time: '{s.iloc[i]}'", path=path,
                                 column=name, row=i + 1)
            out[name] = conv
        else:  # pragma: no cover - schema error
            raise ValueError(f"unknown column kind {col.kind}")
    if all(out[n] is df[n] for n in df.columns) if df.columns.is_unique else False:
        return df
    return pd.DataFrame(out, index=df.index, copy=False)


def _check_time(df: pd.DataFrame, schema: Schema, *, path) -> pd.DataFrame:
    if schema.time_order == "strict" and schema.time_column in df.columns:
        t = df[schema.time_column].to_numpy(dtype=float)
        if t.size > 1:
            dt = np.diff(t)
            bad = dt <= 0
            if bad.any():
                rows = (np.flatnonzero(bad)[:_MAX_ROWS_LISTED] + 2).tolist()
                kind = "repeat" if np.any(dt[bad] == 0) and not np.any(dt[bad] < 0) else \
                    "decrease or repeat"
                raise InputError(f"time stamps {kind} (t must increase strictly)", path=path,
                                 column=schema.time_column, row=rows if len(rows) > 1 else rows[0])
    elif schema.time_order == "sort":
        keys = [k for k in schema.sort_by if k in df.columns]
        if keys:
            sorted_df = df.sort_values(keys, kind="stable")
            if not sorted_df.index.equals(df.index):
                warnings.warn(f"{path}: rows were not in {'/'.join(keys)} order; sorted them",
                              DataQualityWarning, stacklevel=4)
                df = sorted_df.reset_index(drop=True)
    return df


def _resample(df, rate_hz, schema, units, meta, *, path):
    from inertialab.io.timestamps import resample_uniform

    tcol = schema.time_column
    if "segment" in df.columns:
        raise InputError("cannot resample a log split into segments", path=path)
    num = [c for c in df.columns if c != tcol and pd.api.types.is_float_dtype(df[c])]
    grid, vals = resample_uniform(df[tcol].to_numpy(float), {c: df[c] for c in num},
                                  float(rate_hz), path=path)
    meta["resampled"] = {"rate_hz": float(rate_hz), "method": "linear", "n_before": len(df),
                         "n_after": int(grid.size), "columns": num}
    meta["fs_hz"] = float(rate_hz)
    return pd.DataFrame({tcol: grid, **vals})


def hash_frame(df: pd.DataFrame) -> str:
    """SHA-256 of a frame's columns in sorted-name order, values canonicalised (float64
    bytes for numbers, int64 ns for times, UTF-8 for text), so CSV and Parquet of the same
    data give the same hash.

    Examples
    --------
    Column order and the number's dtype do not change the hash; a value does:

    >>> import pandas as pd
    >>> a = pd.DataFrame({"t_s": [0.0, 0.1], "rate_dph": [1, 2]})
    >>> b = pd.DataFrame({"rate_dph": [1.0, 2.0], "t_s": [0.0, 0.1]})
    >>> hash_frame(a) == hash_frame(b), hash_frame(a) == hash_frame(b.assign(t_s=[0.0, 0.2]))
    (True, False)
    >>> len(hash_frame(a))
    64
    """
    h = hashlib.sha256()
    for name in sorted(df.columns):
        s = df[name]
        h.update(str(name).encode() + b"\0")
        if pd.api.types.is_datetime64_any_dtype(s):
            h.update(s.dt.tz_convert("UTC").astype("int64").to_numpy().tobytes()
                     if s.dt.tz is not None else s.astype("int64").to_numpy().tobytes())
        elif pd.api.types.is_numeric_dtype(s) and not pd.api.types.is_bool_dtype(s):
            h.update(np.ascontiguousarray(s.to_numpy(dtype=np.float64, na_value=np.nan)).tobytes())
        else:
            h.update("\x1f".join("" if pd.isna(v) else str(v) for v in s).encode())
        h.update(b"\x1e")
    return h.hexdigest()


def _missing(what: str, df_seen: pd.DataFrame, header_units, *, path, column=None,
             wanted=()) -> InputError:
    """The missing-column error: the columns found as the file shows them, and the map
    that would work when the match is obvious."""
    from inertialab.io.mapping import shown_columns
    from inertialab.io.suggest import suggest_map

    hint = suggest_map(list(df_seen.columns), header_units, set(wanted) or None)
    tail = f"; columns found: {shown_columns(df_seen, header_units)}"
    if hint:
        tail += f"; try argument 'column_map' {hint}"
    return InputError(what + tail, path=path, column=column)


def validate_frame(df: pd.DataFrame, kind: str, *, path="<frame>", meta: dict | None = None,
                   unit=None, gaps: str | None = None, full_scale=None,
                   header_units: dict | None = None, resample_hz: float | None = None,
                   rate_hz: float | None = None) -> Record:
    """Validate an in-memory DataFrame as a record of ``kind`` (see :func:`read_record`).

    ``header_units`` (column -> unit text from a units header row) only improves the
    missing-column message; ``resample_hz`` puts a continuous log on a uniform grid
    after the time-stamp audit (only when given; recorded in ``meta["resampled"]``).
    ``rate_hz`` is the caller's sample rate (first in the time base's precedence, see
    :func:`inertialab.io.timestamps.decide_timebase`); the record's
    :attr:`~Record.timebase` is decided here, once.

    Examples
    --------
    >>> import pandas as pd
    >>> frame = pd.DataFrame({"t_s": [0.0, 0.5, 1.0], "rate_dps": [0.1, 0.2, 0.3]})
    >>> validate_frame(frame, "gyro_log").timebase.rate_hz
    2.0
    """
    from inertialab.io.mapping import normalise_time_columns

    schema = SCHEMAS[kind]
    meta = dict(meta or {})
    path = str(path)
    if df.shape[1] == 0:
        raise InputError("no columns", path=path)
    if schema.time_column == "t_s":
        df = normalise_time_columns(df, path=path, meta=meta)
    seen = df
    df, units, present = _resolve_columns(df, schema, path=path, meta=meta, unit=unit)
    for c in schema.columns:
        if c.required and c.name not in present and c.name == schema.time_column == "t_s":
            raise _missing("needs a t_s column or argument 'rate_hz'", seen, header_units,
                           path=path, column="t_s",
                           wanted=[x.name for x in schema.columns])
        if c.required and c.name not in present:
            hint = f" (with a unit suffix, e.g. {c.name}_{_example_suffix(c)})" if c.flexible else ""
            raise _missing(f"missing required column{hint}", seen, header_units, path=path,
                           column=c.name,
                           wanted=[x.name for x in schema.columns])
    for group in schema.one_of:
        if not any(g in present for g in group):
            extra = ("t_s",) if schema.time_column == "t_s" and "t_s" not in present else ()
            raise _missing(f"needs at least one of the columns {', '.join(group)}", seen,
                           header_units, path=path, wanted=(*group, *extra))
    for key in schema.required_meta:
        if key not in meta:
            raise InputError(f"metadata key '{key}' missing (sidecar <stem>.meta.json)", path=path)
    if len(df) == 0:
        raise InputError("no data rows (header only)", path=path)
    if len(df) < schema.min_rows:
        raise InputError(f"too few samples: {len(df)} rows, need at least {schema.min_rows}",
                         path=path)
    ix = df.index
    if not (isinstance(ix, pd.RangeIndex) and ix.start == 0 and ix.step == 1):
        df = df.reset_index(drop=True)  # (a copy: only when the index is not 0..n-1)
    df = _coerce(df, schema, path=path).copy(deep=False)  # never alter the caller's frame
    from inertialab.io.unit_check import check_accel_magnitude, check_gyro_units

    check_accel_magnitude(df, units, path=path)
    check_gyro_units(df, units, path=path)
    if schema.time_order == "strict" and schema.time_column in df.columns:
        from inertialab.io.timestamps import audit

        meta["timestamps"] = audit(df[schema.time_column].to_numpy(dtype=float)).to_dict()
    if gaps is not None and schema.time_order == "strict" and schema.time_column in df.columns:
        from inertialab.io.gaps import apply_gap_policy

        df, rep = apply_gap_policy(df, gaps, time_column=schema.time_column, path=path)
        meta["gaps"] = rep.to_dict()
        if "segment" in df.columns and gaps == "split":
            meta["_derived"] = ["segment"]
    else:
        df = _check_time(df, schema, path=path)
    if resample_hz is not None and schema.time_column in df.columns \
            and schema.time_order == "strict":
        df = _resample(df, resample_hz, schema, units, meta, path=path)
    if full_scale is None:
        full_scale = meta.get("full_scale")
    if full_scale is not None:
        from inertialab.io.gaps import detect_saturation

        cols = [c for c in df.columns if c in units]
        sat = detect_saturation(df, cols, None if full_scale == "auto" else full_scale)
        df["saturated"] = sat.mask
        meta["_derived"] = [*meta.get("_derived", []), "saturated"]
        meta["saturation"] = sat.to_dict()
        if sat.n_flagged:
            warnings.warn(f"{path}: {sat.n_flagged} samples at full scale (rows "
                          f"{', '.join(str(r) for r in sat.rows)}{' ...' if sat.n_flagged > len(sat.rows) else ''}); "
                          "flagged in column 'saturated'", DataQualityWarning, stacklevel=3)
    derived = [c for c in ("segment", "saturated") if c in meta.get("_derived", ())]
    meta.pop("_derived", None)
    timebase = _timebase(df, schema, meta, rate_hz=rate_hz, resample_hz=resample_hz, path=path)
    if timebase is not None:
        meta["timebase"] = timebase.to_dict()
    return Record(kind=kind, data=df, meta=meta, path=path, units=units,
                  sha256=hash_frame(df.drop(columns=derived) if derived else df),
                  timebase=timebase)


def _timebase(df, schema: Schema, meta: dict, *, rate_hz, resample_hz, path):
    """The record's one time base (None for a kind that is not a continuous log)."""
    from inertialab.io.timestamps import Timebase, decide_timebase

    if schema.time_order != "strict" or schema.time_column != "t_s":
        return None
    if resample_hz is not None and "t_s" in df.columns:
        return Timebase(float(resample_hz), "resampled", len(df), jitter_rel=0.0,
                        jitter_max_rel=0.0)
    t = df["t_s"].to_numpy(dtype=float) if "t_s" in df.columns else None
    nominal = meta.get("fs_hz") if rate_hz is None else None
    return decide_timebase(t, n=len(df), rate_hz=rate_hz,
                           nominal_hz=None if nominal is None else float(nominal), path=path)
