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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from inertialab.errors import DataQualityWarning, InputError
from inertialab.io.schema import Column, Schema
from inertialab.io.schemas import SCHEMAS
from inertialab.io.sidecar import parse_header_lines, read_sidecar
from inertialab.units import SUFFIXES, split_suffix

_MAX_ROWS_LISTED = 5


@dataclass
class Record:
    """A validated record.

    Attributes
    ----------
    kind : schema kind
    data : DataFrame with canonical lower-case column names (units as suffixes)
    meta : sidecar / header metadata
    path : source file (or ``"<frame>"``)
    units : canonical column -> unit suffix, for unit-flexible columns
    sha256 : hash of the validated canonical columns (format-independent)
    arrays : for ``.npy`` logs, the memory-mapped column (not copied into ``data``)
    """

    kind: str
    data: pd.DataFrame
    meta: dict
    path: str
    units: dict[str, str]
    sha256: str
    arrays: dict[str, np.ndarray] = field(default_factory=dict)

    def column(self, name: str) -> np.ndarray:
        """Values of a canonical column as a float ndarray (memmap for .npy logs)."""
        if name in self.arrays:
            return self.arrays[name]
        if name not in self.data.columns:
            raise InputError("no such column", path=self.path, column=name)
        return self.data[name].to_numpy()

    def find(self, base: str) -> str | None:
        """Canonical name of the unit-flexible column with ``base`` (e.g. ``rate`` ->
        ``rate_dph``), or None."""
        for col in list(self.arrays) + list(self.data.columns):
            b, suf = split_suffix(col)
            if b == base and suf is not None:
                return col
        return None

    @property
    def n(self) -> int:
        if self.arrays:
            return int(next(iter(self.arrays.values())).shape[0])
        return len(self.data)


# ---------------------------------------------------------------------------- loading

def _load_table(path: Path, parse=None) -> tuple[pd.DataFrame, dict]:
    suffix = path.suffix.lower()
    if suffix in (".parquet", ".pq"):
        try:
            df = pd.read_parquet(path)
        except ImportError:
            raise InputError("reading Parquet needs pyarrow: pip install 'inertialab[parquet]'",
                             path=path) from None
        except Exception as exc:  # pyarrow raises many types for corrupt files
            raise InputError(f"not a readable Parquet file ({type(exc).__name__})", path=path) from None
        return df, {}
    # text: preamble, separator and decimal mark from the first lines (io.mapping.sniff)
    from inertialab.io.mapping import sniff

    try:
        with open(path, encoding="utf-8") as fh:
            first = []
            limit = 200 + (parse.skip_rows if parse is not None and parse.skip_rows else 0)
            for i, line in enumerate(fh):
                first.append(line)
                if i >= limit:
                    break
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text (byte {exc.start}); save the file as UTF-8 CSV",
                         path=path) from None
    skip, sep, dec, header_lines = sniff(first, parse)
    meta = parse_header_lines(header_lines, path=path)
    try:
        df = pd.read_csv(path, skiprows=skip, encoding="utf-8", skipinitialspace=True,
                         low_memory=False, sep=sep, decimal=dec)
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text (byte {exc.start}); save the file as UTF-8 CSV",
                         path=path) from None
    except pd.errors.EmptyDataError:
        raise InputError("no header and no data (empty file)", path=path) from None
    except (pd.errors.ParserError, ValueError) as exc:
        msg = str(exc).strip().splitlines()[-1] if str(exc).strip() else type(exc).__name__
        raise InputError(f"not a readable CSV file ({msg})", path=path) from None
    return df, meta


def read_record(path, kind: str, *, unit=None, rate_hz: float | None = None,
                column: str | None = None, g_local: float | None = None,
                column_map=None, parse=None, gaps: str | None = None,
                full_scale=None, options=None) -> Record:
    """Read and validate a record file of ``kind``.

    Parameters
    ----------
    path : str or Path
        ``.csv``/``.txt`` (with optional ``# key=value`` header lines), ``.parquet``,
        or ``.npy`` (one column, memory-mapped; needs ``column`` and ``rate_hz`` or a
        sidecar with ``column`` and ``fs_hz``).
    kind : str
        One of :data:`inertialab.io.schemas.SCHEMAS`.
    unit : str or dict, optional
        Unit override (``--unit``): a suffix applied to the measurement columns whose
        allowed dimensions include it, or ``{base: suffix}``. Overrides column
        suffixes, which override the sidecar's ``units``.
    rate_hz : float, optional
        Sample rate for a ``.npy`` log (else the sidecar's ``fs_hz``).
    column : str, optional
        Canonical column name for a ``.npy`` log (e.g. ``rate_dph``).
    g_local : float, optional
        Local gravity, m/s^2; stored in ``meta["g_local_mps2"]`` when given.
    column_map : ColumnMap or str, optional
        ``--map`` (:func:`inertialab.io.mapping.parse_map`): canonical target <- source
        column and unit, applied before validation. Columns ``t_ms``/``t_us``/``t_ns``
        become ``t_s`` (seconds since the first stamp) with or without a map.
    parse : ParseOptions, optional
        Separator, decimal mark and preamble lines of a text file (default: sniffed).
    gaps : {None, "error", "split"}, default None
        Time-stamp policy for continuous logs (:mod:`inertialab.io.gaps`): None keeps
        the order check only; ``"error"`` also stops at dropouts with their rows and
        durations; ``"split"`` adds a ``segment`` column instead of stopping.
    full_scale : dict, float, "auto" or None
        Flag samples at full scale in a ``saturated`` column (dict: column -> value in
        the column's unit; "auto": flat runs at a column's extreme). None uses the
        sidecar's ``full_scale`` when there is one.
    options : ReadOptions, optional
        The reading options of the command line's front door
        (:class:`inertialab.io.mapping.ReadOptions`); its column map and parse options
        are used where ``column_map``/``parse`` are not given.

    Raises
    ------
    InputError
        Missing or empty file, unreadable format, missing column, non-numeric or
        non-finite value, bad time order, too few rows, unknown unit suffix.
    """
    if kind not in SCHEMAS:
        raise InputError(f"unknown record kind '{kind}' (known: {', '.join(SCHEMAS)})")
    if options is not None:
        column_map = options.column_map if column_map is None else column_map
        parse = options.parse if parse is None else parse
    p = Path(path)
    if not p.exists():
        raise InputError("no such file", path=p)
    if p.is_dir():
        raise InputError("is a directory, expected a file", path=p)
    if p.stat().st_size == 0:
        raise InputError("empty file", path=p)
    meta = read_sidecar(p)
    if g_local is not None:
        meta["g_local_mps2"] = float(g_local)
    if p.suffix.lower() == ".npy":
        return _read_npy(p, kind, meta, unit=unit, rate_hz=rate_hz, column=column)
    df, header_meta = _load_table(p, parse)
    merged = dict(header_meta)
    merged.update(meta)
    if column_map:
        from inertialab.io.mapping import apply_map, parse_map

        cmap = parse_map(column_map) if isinstance(column_map, str) else column_map
        df = apply_map(df, cmap, path=p, g_local=merged.get("g_local_mps2"), meta=merged)
    if parse is not None and not parse.is_default:
        merged["parse"] = parse.to_dict()
    return validate_frame(df, kind, path=p, meta=merged, unit=unit, gaps=gaps,
                          full_scale=full_scale)


def _read_npy(p: Path, kind: str, meta: dict, *, unit, rate_hz, column) -> Record:
    try:
        arr = np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError) as exc:
        raise InputError(f"not a readable .npy file ({exc})", path=p) from None
    if arr.ndim == 2 and arr.shape[1] == 1:
        arr = arr[:, 0]
    if arr.ndim != 1:
        raise InputError(f".npy log must be one column, got shape {arr.shape}", path=p)
    if not np.issubdtype(arr.dtype, np.number):
        raise InputError(f".npy log must be numeric, got dtype {arr.dtype}", path=p)
    name = column or meta.get("column")
    if name is None and isinstance(unit, str):
        dim = SUFFIXES.get(unit.lower())
        base = {"angular_rate": "rate", "acceleration": "accel", "angle": "dtheta"}.get(
            dim.dimension if dim else "", None)
        if base:
            name = f"{base}_{unit.lower()}"
    if name is None:
        raise InputError("a .npy log needs --unit (or --column) and --rate, or a sidecar "
                         "with 'column' and 'fs_hz'", path=p)
    fs = rate_hz if rate_hz is not None else meta.get("fs_hz")
    if fs is None:
        raise InputError("a .npy log needs --rate (Hz) or a sidecar with 'fs_hz'", path=p)
    fs = float(fs)
    if not np.isfinite(fs) or fs <= 0:
        raise InputError(f"sample rate must be positive, got {fs}", path=p)
    base, suf = split_suffix(name)
    if suf is None:
        raise InputError("column name has no unit suffix", path=p, column=name)
    if arr.shape[0] < SCHEMAS[kind].min_rows:
        raise InputError(f"too few samples: {arr.shape[0]}", path=p, column=name)
    # finiteness and hash in chunks: one pass over the memory map
    h = hashlib.sha256()
    h.update(name.encode() + b"\0")
    chunk = 1 << 22
    for start in range(0, arr.shape[0], chunk):
        block = np.ascontiguousarray(arr[start:start + chunk], dtype=np.float64)
        bad = ~np.isfinite(block)
        if bad.any():
            rows = (np.flatnonzero(bad)[:_MAX_ROWS_LISTED] + start + 1).tolist()
            raise InputError("NaN or infinite value", path=p, column=name, row=rows)
        h.update(block.tobytes())
    meta = dict(meta)
    meta["fs_hz"] = fs
    meta["column"] = name
    data = pd.DataFrame(index=pd.RangeIndex(0))
    return Record(kind=kind, data=data, meta=meta, path=str(p), units={name: suf},
                  sha256=h.hexdigest(), arrays={name: arr})


# ---------------------------------------------------------------------------- columns

def _normalise(name) -> str:
    return str(name).strip().lower()


def _override_unit(col: Column, unit) -> str | None:
    if unit is None:
        return None
    if isinstance(unit, dict):
        u = unit.get(col.name)
        return None if u is None else str(u).lower()
    u = SUFFIXES.get(str(unit).lower())
    if u is None:
        raise InputError(f"unknown unit '{unit}' (known suffixes: {', '.join(sorted(SUFFIXES))})")
    return str(unit).lower() if u.dimension in col.dimensions else None


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
        if suf is None:
            raise InputError(f"no unit: add a suffix (e.g. {col.name}_{_example_suffix(col)}) "
                             "or give --unit", path=path, column=orig)
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
    values = series.to_numpy(dtype=float, na_value=np.nan)
    if col.finite or col.required:
        nonfinite = ~np.isfinite(values)
        if nonfinite.any():
            rows = _bad_rows(nonfinite)
            what = "empty cell or NaN" if np.isnan(values[rows[0] - 1]) else "infinite value"
            raise InputError(what, path=path, column=name, row=rows if len(rows) > 1 else rows[0])
    if col.kind == "int":
        finite = np.isfinite(values)
        frac = finite & (np.abs(values - np.round(values)) > 1e-9)
        if frac.any():
            i = int(np.flatnonzero(frac)[0])
            raise InputError(f"expected a whole number, got {values[i]!r}", path=path, column=name,
                             row=i + 1)
        if finite.all():
            return pd.Series(np.round(values).astype(np.int64), index=series.index, name=name)
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
    return pd.DataFrame(out, index=df.index)


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


def hash_frame(df: pd.DataFrame) -> str:
    """SHA-256 of a frame's columns in sorted-name order, values canonicalised (float64
    bytes for numbers, int64 ns for times, UTF-8 for text), so CSV and Parquet of the same
    data give the same hash."""
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


def validate_frame(df: pd.DataFrame, kind: str, *, path="<frame>", meta: dict | None = None,
                   unit=None, gaps: str | None = None, full_scale=None) -> Record:
    """Validate an in-memory DataFrame as a record of ``kind`` (see :func:`read_record`)."""
    from inertialab.io.mapping import normalise_time_columns

    schema = SCHEMAS[kind]
    meta = dict(meta or {})
    path = str(path)
    if df.shape[1] == 0:
        raise InputError("no columns", path=path)
    if schema.time_column == "t_s":
        df = normalise_time_columns(df, path=path, meta=meta)
    df, units, present = _resolve_columns(df, schema, path=path, meta=meta, unit=unit)
    for c in schema.columns:
        if c.required and c.name not in present:
            hint = f" (with a unit suffix, e.g. {c.name}_{_example_suffix(c)})" if c.flexible else ""
            raise InputError(f"missing required column{hint}", path=path, column=c.name)
    for group in schema.one_of:
        if not any(g in present for g in group):
            raise InputError(f"needs at least one of the columns {', '.join(group)}", path=path)
    for key in schema.required_meta:
        if key not in meta:
            raise InputError(f"metadata key '{key}' missing (sidecar <stem>.meta.json)", path=path)
    if len(df) == 0:
        raise InputError("no data rows (header only)", path=path)
    if len(df) < schema.min_rows:
        raise InputError(f"too few samples: {len(df)} rows, need at least {schema.min_rows}",
                         path=path)
    df = df.reset_index(drop=True)
    df = _coerce(df, schema, path=path)
    if gaps is not None and schema.time_order == "strict" and schema.time_column in df.columns:
        from inertialab.io.gaps import apply_gap_policy

        df, rep = apply_gap_policy(df, gaps, time_column=schema.time_column, path=path)
        meta["gaps"] = rep.to_dict()
        if "segment" in df.columns and gaps == "split":
            meta["_derived"] = ["segment"]
    else:
        df = _check_time(df, schema, path=path)
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
    return Record(kind=kind, data=df, meta=meta, path=path, units=units,
                  sha256=hash_frame(df.drop(columns=derived) if derived else df))
