"""Delimited text tables as rigs write them: the text half of the front door.

What a vendor CSV throws at a reader, handled before pandas sees the file:

* **size and content checks first** (docs/robustness.md): a file above
  :data:`MAX_TEXT_BYTES`, a NUL byte in its first or last MiB (a sparse or binary
  file), UTF-16 text or bytes that are not UTF-8 are a one-line
  :class:`~inertialab.errors.InputError` before any parsing, so a 2 GB sparse file
  fails in milliseconds instead of filling memory;
* a UTF-8 byte-order mark is dropped (it is not part of the first column's name);
* **preamble** lines (``#`` metadata, ``//`` comments, blank lines, and free-text
  lines whose field count differs from the table's) are skipped;
* the **separator** is sniffed: tab, ``;``, ``,`` or runs of blanks, the first that
  splits the data lines into one consistent number of fields (> 1);
* **header rows** are the rows between the preamble and the first data row; a second
  header row of units (``s``, ``[deg/s]``, ``(g)``) is joined to the names: the unit
  goes to :attr:`TextTable.header_units` and, for a bare canonical name (``gx``), into
  the name's suffix (``gx_dps``);
* a file **without a header** gets the positional names ``col1 .. colN`` (1-based, as a
  spreadsheet counts), so ``gx_rps=col7`` maps its seventh column;
* a row of **group names** above the names (``Gyro,,,Accel,,`` over
  ``X,Y,Z,X,Y,Z``: a spreadsheet's merged cells) is carried over its empty cells and
  joined to the names below (``Gyro X``, ``Accel X``);
* an exactly **duplicated header name** is refused (pandas would silently rename it
  ``x.1``);
* the data are read in chunks (bounded memory: about twice the parsed numbers).

Written by hand because it is glue around :func:`pandas.read_csv` (which does the
parsing): the sniffing rules are what a user's file needs and pandas does not do.
"""

from __future__ import annotations

import csv
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from inertialab import units as U
from inertialab.errors import InputError
from inertialab.limits import MAX_COLUMNS, regular_input

if TYPE_CHECKING:  # pandas loads when a table is read, not when a command starts
    import pandas as pd

__all__ = ["MAX_TEXT_BYTES", "TextLayout", "TextTable", "layout_of", "load_text", "unit_suffix"]

#: Largest text file the reader parses (bytes); above it, convert to Parquet or .npy.
#: ``INERTIALAB_MAX_TEXT_BYTES`` in the environment overrides it.
MAX_TEXT_BYTES = 4 * 2**30
_HEAD_BYTES = 1 << 20
_CHUNK_ROWS = 1 << 18
_PREAMBLE = ("#", "//")
_CANDIDATE_SEPS = ("\t", ";", ",", r"\s+")
_NUM = re.compile(r"^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?$|^[+-]?(?:nan|inf|infinity)$",
                  re.IGNORECASE)


def _max_bytes() -> int:
    env = os.environ.get("INERTIALAB_MAX_TEXT_BYTES")
    try:
        return int(env) if env else MAX_TEXT_BYTES
    except ValueError:
        return MAX_TEXT_BYTES


@dataclass
class TextLayout:
    """What sniffing decided about a text file (all counts in lines of the file)."""

    skip: int                      # preamble lines before the first header row
    n_header: int                  # header rows (0: headerless)
    sep: str                       # separator ("\\s+" for runs of blanks)
    decimal: str
    names: list[str]               # column names as the user sees them (BOM dropped)
    header_units: dict[str, str] = field(default_factory=dict)  # name -> unit text
    hash_lines: list[str] = field(default_factory=list)          # '# key=value' lines
    bom: bool = False


@dataclass
class TextTable:
    """A parsed text table with its layout."""

    frame: pd.DataFrame
    layout: TextLayout

    @property
    def header_units(self) -> dict[str, str]:
        return self.layout.header_units


def unit_suffix(text: str) -> str | None:
    """The canonical suffix (``dps``) of a unit as written in a header (``deg/s``,
    ``[deg/s]``, ``(g)``, ``m/s^2``), or None when it is not a unit inertialab knows."""
    t = str(text).strip().strip("[]()").strip()
    if not t:
        return None
    t = {"°/s": "deg/s", "deg/sec": "deg/s", "m/s2": "m/s^2", "m/s²": "m/s^2", "rad/sec": "rad/s",
         "sec": "s", "°c": "c", "degc": "c", "°": "deg", "us": "us", "µs": "us",
         "µg": "ug"}.get(t.lower(), t)
    try:
        u = U.lookup(t)
    except InputError:
        return None
    for name, v in U.SUFFIXES.items():
        if v.dimension == u.dimension and math.isclose(v.scale, u.scale, rel_tol=1e-12) \
                and v.g_power == u.g_power:
            return name
    return None


# ----------------------------------------------------------------------------- checks

def _check_bytes(path: Path) -> tuple[bytes, bool]:
    """Regular file, size, NUL and encoding checks; return (head bytes, truncated)."""
    regular_input(path)
    size = path.stat().st_size
    limit = _max_bytes()
    if size > limit:
        raise InputError(f"text file of {size / 2**30:.2f} GiB is above the reader's limit of "
                         f"{limit / 2**30:.2f} GiB; convert it to Parquet or .npy", path=path)
    with open(path, "rb") as fh:
        head = fh.read(_HEAD_BYTES)
        tail = b""
        if size > _HEAD_BYTES:
            fh.seek(max(_HEAD_BYTES, size - _HEAD_BYTES))
            tail = fh.read(_HEAD_BYTES)
    if head[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise InputError("UTF-16 text; save the file as UTF-8", path=path)
    for block, offset in ((head, 0), (tail, size - len(tail))):
        i = block.find(b"\0")
        if i >= 0:
            raise InputError(f"binary content (NUL byte at byte {offset + i}), not a text "
                             "table", path=path)
    return head, size > len(head)


def _decode(head: bytes, truncated: bool, path: Path) -> str:
    if truncated:  # cut at the last full line so a multi-byte character is not split
        cut = head.rfind(b"\n")
        head = head[:cut + 1] if cut >= 0 else head
    try:
        return head.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text (byte {exc.start}); save the file as UTF-8 CSV",
                         path=path) from None


# ----------------------------------------------------------------------------- sniffing

def _split(line: str, sep: str) -> list[str]:
    if sep == r"\s+":
        cells = line.split()
    else:
        try:
            row = next(csv.reader([line.rstrip("\r\n")], delimiter=sep,
                                  skipinitialspace=True), [])
        except csv.Error as exc:  # a field above the csv module's size limit
            raise InputError(f"a line has a field the text reader cannot take ({exc}); not a "
                             "table inertialab reads") from None
        cells = [c.strip() for c in row]
    if len(cells) > MAX_COLUMNS:
        raise InputError(f"a line has {len(cells)} fields, more than the {MAX_COLUMNS} "
                         "columns a table may have")
    return cells


def _is_number(cell: str, decimal: str) -> bool:
    c = cell.strip()
    if decimal == ",":
        c = c.replace(",", ".")
    return bool(_NUM.match(c))


#: Cells that are values although not numbers: ISO dates and times, booleans (a header
#: name is neither). A table of unit ids, dates, one number and a validity flag has data
#: rows with one number in four cells.
_VALUE = re.compile(r"^\d{4}-\d{2}-\d{2}(?:[T ]\d{2}:\d{2}(?::\d{2}(?:\.\d+)?)?"
                    r"(?:Z|[+-]\d{2}:?\d{2})?)?$|^(?:true|false)$", re.I)


def _is_data_row(cells: list[str], decimal: str) -> bool:
    """A row of values: at least one number, and numbers, dates, times and booleans make
    at least a third of its filled cells."""
    filled = [c.strip() for c in cells if c.strip()]
    if not filled:
        return False
    num = sum(_is_number(c, decimal) for c in filled)
    values = num + sum(bool(_VALUE.match(c)) for c in filled)
    return num >= 1 and 3 * values >= len(filled)


_QUOTED = re.compile(r'"(?:[^"]|"")*"')
#: Most physical lines one quoted cell may span (a stray quote must not swallow a file).
_MAX_CELL_LINES = 50


def _records(lines: list[str]) -> tuple[list[str], list[int]]:
    """Physical lines joined into records where a quoted cell holds a line break;
    returns (records, physical lines per record)."""
    recs, sizes = [], []
    i = 0
    while i < len(lines):
        rec, k = lines[i], 1
        while rec.count('"') % 2 and i + k < len(lines) and k < _MAX_CELL_LINES:
            rec += lines[i + k]
            k += 1
        if rec.count('"') % 2:  # unbalanced to the end: a stray quote, not a cell
            rec, k = lines[i], 1
        recs.append(rec)
        sizes.append(k)
        i += k
    return recs, sizes


def _unquoted(line: str) -> str:
    """``line`` with every quoted cell replaced by ``Q``: a separator, blank or line break
    inside quotes says nothing about the table's separator."""
    return _QUOTED.sub("Q", line) if '"' in line else line


def _guess_sep(lines: list[str], seps=_CANDIDATE_SEPS) -> tuple[str, int]:
    """First candidate separator that splits the last lines (the data, past any header)
    into one consistent count of fields above one; returns (separator, field count).
    Quoted cells are blanked first (a ``;`` inside quotes is text)."""
    lines = [_unquoted(ln) for ln in lines]
    n = len(lines)
    sample = lines[-min(40, max(2, math.ceil(n / 2))):] if n > 2 else lines
    for sep in seps:
        try:
            split = [_split(ln, sep) for ln in sample]
        except InputError:  # a field or field count out of bounds: not this separator
            if sep == seps[-1]:
                raise
            continue
        counts = [len(r) for r in split]
        if not counts:
            continue
        if sep != r"\s+" and any(len(f.split()) > 1 and all(_is_number(x, ".") or
                                                            _is_number(x, ",") for x in f.split())
                                  for r in split for f in r):
            continue  # numbers separated by blanks inside a field: not this separator
        mode = max(set(counts), key=counts.count)
        if mode > 1 and counts.count(mode) >= 0.9 * len(counts):
            return sep, mode
    sep = seps[0] if len(seps) == 1 else ","
    counts = [len(_split(ln, sep)) for ln in sample] or [1]
    return sep, max(set(counts), key=counts.count)


def _is_unit_row(cells: list[str]) -> bool:
    filled = [c for c in cells if c.strip()]
    return bool(filled) and all(unit_suffix(c) is not None for c in filled)


def _guess_decimal(lines: list[str], sep: str) -> str:
    if sep == ",":
        return "."
    if any(re.search(r"(?<![\d.])-?\d+,\d+(?![\d,]*\.)", ln) for ln in lines):
        return ","
    return "."


def _is_group_row(row: list[str], ncol: int) -> bool:
    """A row of group names with gaps (``Gyro,,,Accel,,``: merged cells above the
    names), as wide as the table."""
    cells = [c.strip() for c in row]
    filled = [c for c in cells if c]
    return (len(cells) == ncol and 2 <= len(filled) < ncol and bool(cells[0])
            and not any(unit_suffix(c) is not None for c in filled))


def _merged_groups(row: list[str]) -> list[str]:
    """A group row above the names (``Gyro,,,Accel,,`` over ``X,Y,Z,X,Y,Z``: a
    spreadsheet's merged cells) with each group carried over the empty cells to its
    right, so that the names below read ``Gyro X, Gyro Y ...``; a row with a unit cell
    or fewer than two groups is kept as it is."""
    cells = [c.strip() for c in row]
    filled = [c for c in cells if c]
    if len(filled) < 2 or not cells[0] or any(unit_suffix(c) is not None for c in filled):
        return row
    out, last = [], ""
    for c in cells:
        last = c or last
        out.append(last)
    return out


def _header_names(rows: list[list[str]], ncol: int, *, path) -> tuple[list[str], dict[str, str]]:
    """Names (one per column) and units from one or more header rows."""
    from inertialab.io.schemas import flexible_bases

    rows = [r + [""] * (ncol - len(r)) for r in rows]
    rows = [_merged_groups(r) if k < len(rows) - 1 else r for k, r in enumerate(rows)]
    names, units = [], {}
    bases = flexible_bases()
    for j in range(ncol):
        parts, unit = [], None
        for k, r in enumerate(rows):
            cell = r[j].strip()
            if not cell:
                continue
            if k > 0 and unit is None and unit_suffix(cell) is not None:
                unit = cell.strip().strip("[]()").strip()
                continue
            parts.append(cell)
        name = " ".join(parts) if parts else f"col{j + 1}"
        if unit is not None:
            suf = unit_suffix(unit)
            if name.strip().lower() in bases and suf is not None:
                name = f"{name}_{suf}"
            else:
                units[name] = unit
        names.append(name)
    seen: dict[str, int] = {}
    for j, n in enumerate(names):
        key = n.strip().lower()
        if key in seen:
            raise InputError(f"duplicated column header '{n}' (columns {seen[key] + 1} and "
                             f"{j + 1}); rename one", path=path)
        seen[key] = j
    return names, units


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


def layout_of(lines: list[str], parse=None, *, path=None) -> TextLayout:
    """Sniff the layout of a text file from its first lines (BOM already removed)."""
    opts = parse or ParseOptions()
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
    rest, sizes = _records(lines[skip:])
    if not any(ln.strip() for ln in rest):
        raise InputError("no header and no data (empty table)", path=path)
    sep = opts.sep
    if sep == " ":
        sep = r"\s+"
    sep, ncol = _guess_sep([ln for ln in rest if ln.strip()],
                           _CANDIDATE_SEPS if sep is None else (sep,))
    dec = opts.decimal or _guess_decimal(rest[1:21], sep)
    rows = [_split(ln, sep) for ln in rest]
    # first data row; the rows before it are header rows (or free-text preamble)
    first = next((i for i, r in enumerate(rows) if len(r) == ncol and _is_data_row(r, dec)),
                 None)
    if first is None:  # header only, no data
        first = len(rows)
        while first > 0 and not rest[first - 1].strip():
            first -= 1
    head = [i for i in range(first) if rest[i].strip()]
    if opts.skip_rows is None:
        # free-text lines above the header have another number of fields than the table;
        # the row just above the data is always the header
        while len(head) > 1 and len(rows[head[0]]) != ncol:
            head.pop(0)
        # name row = the last row that is not all units; rows above it are preamble
        name_at = max((k for k, i in enumerate(head) if not _is_unit_row(rows[i])), default=0)
        if name_at > 0 and _is_group_row(rows[head[name_at - 1]], ncol):
            name_at -= 1  # group names over the names (merged cells): joined to them
        head = head[name_at:]
    start = head[0] if head else first
    head_rows = [rows[i] for i in head]
    if len(head_rows) > 3:
        raise InputError(f"{len(head_rows)} lines before the first row of numbers; give the "
                         "number of preamble lines (argument 'skip_rows')", path=path)
    for r in head_rows:
        if len([c for c in r if c.strip()]) > ncol > 0:
            raise InputError(f"header line has {len(r)} names but the data rows have {ncol} "
                             "fields", path=path)
    if head_rows and 1 < len(head_rows[-1]) < ncol:
        # more fields than names: most often decimal commas in a comma-separated file
        # (0,25 read as two fields), which would invent columns and shift every value
        hint = " (decimal commas in a comma-separated file? save it with '.' decimals or " \
               "another separator)" if sep == "," else ""
        raise InputError(f"the header names {len(head_rows[-1])} columns but the data rows "
                         f"have {ncol} fields{hint}", path=path)
    if head_rows:
        names, units = _header_names(head_rows, ncol, path=path)
    else:
        names, units = [f"col{j + 1}" for j in range(ncol)], {}
    return TextLayout(skip=skip + sum(sizes[:start]), n_header=sum(sizes[start:first]),
                      sep=sep, decimal=dec, names=names,
                      header_units=units, hash_lines=hash_lines)


def _head_lines(path: Path, parse) -> tuple[list[str], bool]:
    head, truncated = _check_bytes(path)
    text = _decode(head, truncated, path)
    bom = text.startswith("\ufeff")
    if bom:
        text = text[1:]
    lines = text.splitlines(keepends=True)
    extra = parse.skip_rows if parse is not None and parse.skip_rows else 0
    return lines[:400 + extra], bom


def load_text(path, parse=None, *, nrows: int | None = None) -> TextTable:
    """Read a delimited text file into a frame with the user's column names.

    ``nrows`` limits the data rows (for a peek). Raises :class:`InputError` naming the
    file (and row/column where pandas reports one).
    """
    p = Path(path)
    lines, bom = _head_lines(p, parse)
    try:
        lay = layout_of(lines, parse, path=p)
    except InputError as exc:
        if exc.path is None:  # raised below without the file: name it
            raise InputError(str(exc), path=p) from None
        raise
    lay.bom = bom
    lead = lay.skip + lay.n_header
    ncol = len(lay.names)
    kw = dict(sep=lay.sep, decimal=lay.decimal, header=None, names=lay.names,
              skiprows=lead, encoding="utf-8-sig", skip_blank_lines=True,
              comment=None, index_col=False)
    if lay.sep != r"\s+":
        kw["skipinitialspace"] = True
    chunks = None
    import pandas as pd

    try:
        if nrows is not None:
            df = pd.read_csv(p, nrows=nrows, **kw)
        else:
            chunks = list(pd.read_csv(p, chunksize=_CHUNK_ROWS, **kw))
    except UnicodeDecodeError as exc:
        raise InputError(f"not UTF-8 text (byte {exc.start}); save the file as UTF-8 CSV",
                         path=p) from None
    except pd.errors.EmptyDataError:
        df = pd.DataFrame(columns=lay.names)
    except (pd.errors.ParserError, ValueError) as exc:
        msg = " ".join(str(exc).split()) or type(exc).__name__
        raise InputError(f"not a readable text table ({msg[:160]}); expected {ncol} "
                         "fields per line", path=p) from None
    if chunks is not None:
        _refuse_stray_text(chunks, path=p)
        df = (pd.concat(chunks, ignore_index=True) if len(chunks) > 1 else chunks[0]) \
            if chunks else pd.DataFrame(columns=lay.names)
    return TextTable(df, lay)


#: A column read as numbers in some chunks and text in others is a numeric column with
#: bad cells when at most this share of its cells are text (else a text column).
STRAY_TEXT_SHARE = 0.01
_EMPTY_WORDS = ("", "nan", "NaN", "inf", "-inf", "Inf", "-Inf")


def _refuse_stray_text(chunks: list, *, path) -> None:
    """Refuse a numeric column holding a stray text cell before the chunks are joined.

    ``pd.concat`` of float chunks with one chunk that read as text (``abc`` in the last
    row of 10^7) makes the whole column Python objects, about five times the numbers'
    memory, only for the reader to refuse the cell afterwards: the error path used to
    peak at twice the good path. A column that reads as numbers in some chunks and as
    text in others, with text in at most :data:`STRAY_TEXT_SHARE` of its cells, is
    refused here (one line naming the column, the data row and the value); a real text
    column (unit ids, dates) has far more text and is joined as before."""
    if len(chunks) < 2:
        return
    import numpy as np
    import pandas as pd

    for name in chunks[0].columns:
        kinds = [pd.api.types.is_numeric_dtype(c[name]) for c in chunks]
        if all(kinds) or not any(kinds):
            continue
        first, n_text, n_rows, row0 = None, 0, 0, 0
        for c, numeric in zip(chunks, kinds):
            col = c[name]
            n_rows += len(col)
            if not numeric:
                conv = pd.to_numeric(col, errors="coerce")
                raw = col.astype("string").str.strip()
                text = (conv.isna() & col.notna() & ~raw.isin(_EMPTY_WORDS).fillna(True)
                        ).to_numpy()
                n_text += int(text.sum())
                if first is None and text.any():
                    i = int(np.flatnonzero(text)[0])
                    first = (row0 + i + 1, col.iloc[i])
            row0 += len(col)
        if first is not None and n_text <= STRAY_TEXT_SHARE * n_rows:
            raise InputError(f"non-numeric value '{str(first[1])[:40]}' in a column of numbers",
                             path=path, column=str(name), row=first[0])


def peek_names(path, parse=None) -> list[str]:
    """Column names of a text file as :func:`load_text` gives them (reads a few rows)."""
    return list(load_text(path, parse, nrows=5).frame.columns)


def sniff_compat(lines: list[str], parse=None) -> tuple[int, str, str, list[str]]:
    """``(skip, sep, decimal, hash_lines)`` — the old :func:`inertialab.io.mapping.sniff`
    answer, where ``skip`` counts the lines before the (last) header row."""
    lay = layout_of(lines, parse)
    return lay.skip + max(lay.n_header - 1, 0), lay.sep, lay.decimal, lay.hash_lines
