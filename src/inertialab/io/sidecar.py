"""Record metadata: ``<stem>.meta.json`` sidecars, spec 002's ``# key=value`` header
lines and ``*.schedule.csv`` files (DESIGN.md "Sidecars")."""

from __future__ import annotations

import json
from pathlib import Path

from inertialab.errors import InputError

_DATA_SUFFIXES = (".csv", ".txt", ".tsv", ".parquet", ".pq", ".npy")


def data_stem(path: str | Path) -> Path:
    """``run1.csv`` -> ``run1``; ``lot.static.csv`` -> ``lot.static`` (directory kept)."""
    p = Path(path)
    if p.suffix.lower() in _DATA_SUFFIXES:
        return p.with_suffix("")
    return p


def sidecar_path(path: str | Path) -> Path:
    """Path of the JSON sidecar of a data file: ``<stem>.meta.json``."""
    s = data_stem(path)
    return s.with_name(s.name + ".meta.json")


def schedule_path(path: str | Path) -> Path:
    """Path of a raw log's schedule (spec 002 §2.3): ``x.raw.csv`` -> ``x.schedule.csv``."""
    s = data_stem(path)
    name = s.name[: -len(".raw")] if s.name.endswith(".raw") else s.name
    return s.with_name(name + ".schedule.csv")


def read_sidecar(path: str | Path) -> dict:
    """The sidecar of ``path`` as a dict ({} when there is none).

    Raises InputError when it exists but is not a JSON object.
    """
    sp = sidecar_path(path)
    if not sp.exists():
        return {}
    try:
        meta = json.loads(sp.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"sidecar is not valid JSON ({exc})", path=sp) from None
    if not isinstance(meta, dict):
        raise InputError("sidecar must hold a JSON object", path=sp)
    return meta


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
    return meta
