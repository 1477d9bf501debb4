"""Atomic writers: data records (CSV/Parquet + sidecar) and text/bytes files.

Every write goes to a temporary file in the target's directory and is renamed into
place with ``os.replace``, so a reader never sees a half-written file and a failed
write leaves the old file (or nothing) behind.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path

import pandas as pd

from inertialab.errors import InputError
from inertialab.io.sidecar import sidecar_path
from inertialab.jsonable import to_jsonable


@contextlib.contextmanager
def atomic_path(path: str | Path):
    """Yield a temporary path beside ``path``; on success rename it to ``path``.

    On an exception the temporary file is removed and the exception propagates.
    """
    target = Path(path)
    if target.parent and not target.parent.exists():
        target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent or ".")
    os.close(fd)
    try:
        yield Path(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_record(df: pd.DataFrame, path: str | Path, meta: dict | None = None) -> Path:
    """Write a record as CSV (or Parquet for ``.parquet``) plus its JSON sidecar.

    Floats are written with full round-trip precision. ``meta`` gets
    ``schema_version`` = 1 unless given. Both files are written atomically; the
    sidecar is written only after the data file succeeded.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    with atomic_path(p) as tmp:
        if suffix in (".parquet", ".pq"):
            try:
                df.to_parquet(tmp, index=False)
            except ImportError:
                raise InputError("writing Parquet needs pyarrow: pip install 'inertialab[parquet]'",
                                 path=p) from None
        elif suffix in (".csv", ".txt", ""):
            df.to_csv(tmp, index=False, float_format=None, lineterminator="\n")
        else:
            raise InputError(f"unknown record file type '{suffix}' (use .csv or .parquet)", path=p)
    m = {"schema_version": 1}
    m.update(meta or {})
    write_sidecar(p, m)
    return p


def write_sidecar(path: str | Path, meta: dict) -> Path:
    """Write ``meta`` as the JSON sidecar of data file ``path`` (atomically)."""
    sp = sidecar_path(path)
    text = json.dumps(to_jsonable(meta), indent=2, sort_keys=True, allow_nan=False)
    atomic_write_text(sp, text + "\n")
    return sp
