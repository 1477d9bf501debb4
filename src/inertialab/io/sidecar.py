"""Record metadata: ``<stem>.meta.json`` sidecars, spec 002's ``# key=value`` header
lines and ``*.schedule.csv`` files (docs/records.md)."""

from __future__ import annotations

import json
import math
from pathlib import Path

from inertialab.errors import InputError
from inertialab.io.modelfile import unique_keys

_DATA_SUFFIXES = (".csv", ".txt", ".tsv", ".dat", ".parquet", ".pq", ".npy", ".mat", ".h5", ".hdf5",
                  ".bag", ".db3", ".mcap", ".ulg")


def data_stem(path: str | Path) -> Path:
    """``run1.csv`` -> ``run1``; ``lot.static.csv`` -> ``lot.static`` (directory kept)."""
    p = Path(path)
    if p.suffix.lower() in _DATA_SUFFIXES:
        return p.with_suffix("")
    return p


def sidecar_path(path: str | Path) -> Path:
    """Path of the JSON sidecar of a data file: ``<stem>.meta.json``.

    Examples
    --------
    >>> sidecar_path("runs/gyro.csv").as_posix()
    'runs/gyro.meta.json'
    >>> sidecar_path("runs/log.parquet").name
    'log.meta.json'
    """
    s = data_stem(path)
    return s.with_name(s.name + ".meta.json")


def schedule_path(path: str | Path) -> Path:
    """Path of a raw log's schedule (spec 002 §2.3): ``x.raw.csv`` -> ``x.schedule.csv``."""
    s = data_stem(path)
    name = s.name[: -len(".raw")] if s.name.endswith(".raw") else s.name
    return s.with_name(name + ".schedule.csv")


#: Largest sidecar read (bytes): metadata, not data.
MAX_SIDECAR_BYTES = 16 * 2**20

#: Sidecar / header keys that must be finite numbers, with their allowed range.
NUMERIC_KEYS = {
    "fs_hz": (1e-9, 1e9),
    "g_local_mps2": (1.0, 100.0),
    "lsb_per_g": (1e-12, 1e12),
    "gyro_lsb_per_rps": (1e-12, 1e12),
    "lat_deg": (-90.0, 90.0),
    "h_m": (-1e4, 1e5),
}


def check_numeric_keys(meta: dict, *, path) -> dict:
    """Refuse a known numeric key that is not a finite number in its range (a
    non-numeric ``fs_hz`` is an InputError naming the file and key)."""
    for key, (lo, hi) in NUMERIC_KEYS.items():
        if key not in meta or meta[key] is None:
            continue
        v = meta[key]
        ok = isinstance(v, (int, float)) and not isinstance(v, bool)
        if ok:
            try:
                f = float(v)
            except OverflowError:
                ok = False
            else:
                ok = math.isfinite(f) and lo <= f <= hi
        if not ok:
            shown = repr(v) if len(repr(v)) <= 40 else repr(v)[:37] + "..."
            raise InputError(f"key '{key}' must be a number between {lo:g} and {hi:g}, got "
                             f"{shown}", path=path)
    if "adc" in meta:
        check_adc(meta["adc"], path=path)
    return meta


#: Word sizes an ``adc`` declaration may give (bits).
ADC_BITS = (8, 10, 12, 14, 16, 18, 20, 22, 24, 32)


def check_adc(adc, *, path=None) -> dict:
    """A counts log's declared ADC range, ``{"bits": <int>, "signed": <true|false>}``:
    ``bits`` a JSON integer of :data:`ADC_BITS`, ``signed`` a JSON boolean. A string
    (``"16"``, ``"no"``), a number as ``signed`` or a non-object is refused naming the
    key: ``bool("no")`` is True, so a lenient reading would take an unsigned ADC for a
    signed one."""
    if not isinstance(adc, dict):
        raise InputError(f"key 'adc' must be an object {{\"bits\": 16, \"signed\": false}}, "
                         f"got {type(adc).__name__} {str(adc)[:40]!r}", path=path)
    bits, signed = adc.get("bits"), adc.get("signed")
    if isinstance(bits, bool) or not isinstance(bits, int) or bits not in ADC_BITS:
        raise InputError(f"key 'adc.bits' must be an integer of {', '.join(map(str, ADC_BITS))}"
                         f" (no quotes), got {bits!r:.40}", path=path)
    if not isinstance(signed, bool):
        raise InputError(f"key 'adc.signed' must be true or false (no quotes), got "
                         f"{signed!r:.40}", path=path)
    extra = sorted(set(adc) - {"bits", "signed"})
    if extra:
        raise InputError(f"key 'adc' has unknown entries {', '.join(map(str, extra))} (it "
                         "takes bits and signed)", path=path)
    return adc


def _reject_constant(name: str):
    raise ValueError(f"{name} is not a JSON number")


def read_sidecar(path: str | Path) -> dict:
    """The sidecar of ``path`` as a dict ({} when there is none).

    Raises InputError when it exists but is not a JSON object, is binary, UTF-16, too
    large (:data:`MAX_SIDECAR_BYTES`), nested too deep, holds ``NaN``/``Infinity`` or an
    integer too long to convert, or when a known numeric key (:data:`NUMERIC_KEYS`) is not
    a finite number in range.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> import pandas as pd
    >>> from inertialab.io import write_record
    >>> path = write_record(pd.DataFrame({"t_s": [0.0, 0.1]}), folder / "a.csv", {"fs_hz": 10.0})
    >>> sorted(read_sidecar(path).items())
    [('fs_hz', 10.0), ('schema_version', 1)]
    >>> read_sidecar(folder / "none.csv")
    {}
    >>> tmp.cleanup()
    """
    sp = sidecar_path(path)
    if not sp.exists():
        return {}
    if not sp.is_file():
        raise InputError("sidecar is not a regular file", path=sp)
    size = sp.stat().st_size
    if size > MAX_SIDECAR_BYTES:
        raise InputError(f"sidecar of {size} bytes is above the {MAX_SIDECAR_BYTES}-byte limit",
                         path=sp)
    raw = sp.read_bytes()
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise InputError("sidecar is UTF-16 text; save it as UTF-8", path=sp)
    nul = raw.find(b"\0")
    if nul >= 0:
        raise InputError(f"sidecar has binary content (NUL byte at byte {nul})", path=sp)
    try:
        meta = json.loads(raw.decode("utf-8-sig"), parse_constant=_reject_constant,
                          object_pairs_hook=unique_keys)
    except UnicodeDecodeError as exc:
        raise InputError(f"sidecar is not UTF-8 (byte {exc.start})", path=sp) from None
    except json.JSONDecodeError as exc:
        raise InputError(f"sidecar is not valid JSON ({exc.msg} at line {exc.lineno} column "
                         f"{exc.colno})", path=sp) from None
    except RecursionError:
        raise InputError("sidecar JSON is nested too deep", path=sp) from None
    except ValueError as exc:  # NaN/Infinity, a key twice, or a too-long integer
        raise InputError(f"sidecar is not valid JSON ({' '.join(str(exc).split())[:100]})",
                         path=sp) from None
    if not isinstance(meta, dict):
        raise InputError("sidecar must hold a JSON object", path=sp)
    return check_numeric_keys(meta, path=sp)


def _coerce(value: str):
    v = value.strip()
    for conv in (int, float):
        try:
            return conv(v)
        except ValueError:
            pass
    return v


def parse_header_lines(lines: list[str], *, path=None) -> dict:
    """Parse ``# key=value`` lines (spec 002 §2.3); values become int/float where they parse.

    Lines of only ``#`` or ``# text`` without ``=`` are comments and ignored.
    """
    meta: dict = {}
    for line in lines:
        body = line.lstrip()[1:].strip()
        if "=" not in body:
            continue
        key, _, value = body.partition("=")
        key = key.strip()
        if not key:
            raise InputError(f"header line without a key: {line.strip()!r}", path=path)
        meta[key] = _coerce(value)
    return check_numeric_keys(meta, path=path)


def read_schedule(path: str | Path):
    """A raw log's schedule (spec 002 §2.3: ``pos_id, pitch_deg, heading_deg`` or ``face``)
    as a DataFrame with lower-case column names, read through the text front door
    (size, NUL, UTF-16 and encoding checks first; ``#`` lines skipped).

    Raises InputError naming the file for a missing, empty, binary, UTF-16 or non-UTF-8
    file, one without data rows, or one with neither ``pitch_deg``/``heading_deg`` nor
    ``face``.
    """
    from inertialab.io.formats.text import load_text

    p = Path(path)
    if not p.exists():
        raise InputError("no such schedule file", path=p)
    if not p.is_file():
        raise InputError("schedule is not a regular file", path=p)
    if p.stat().st_size == 0:
        raise InputError("empty schedule file", path=p)
    df = load_text(p).frame
    df.columns = [str(c).strip().lower() for c in df.columns]
    if len(df) == 0:
        raise InputError("schedule has no rows", path=p)
    if not ({"pitch_deg", "heading_deg"} <= set(df.columns) or "face" in df.columns):
        raise InputError(f"schedule needs columns pitch_deg and heading_deg, or face "
                         f"(found: {', '.join(df.columns)})", path=p)
    return df
