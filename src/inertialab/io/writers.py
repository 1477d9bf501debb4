"""Atomic writers: data records (CSV/Parquet + sidecar) and text/bytes files.

Every write goes to a temporary file in the target's directory and is renamed into
place with ``os.replace``, so a reader never sees a half-written file and a failed
write leaves the old file (or nothing) behind. Targets that are not regular files are
refused, and writes join the current output transaction
(:mod:`inertialab.io.outputs`).
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

from inertialab.errors import InputError
from inertialab.io import outputs
from inertialab.io.sidecar import sidecar_path

if TYPE_CHECKING:
    import pandas as pd


@contextlib.contextmanager
def atomic_path(path: str | Path):
    """Yield a temporary path beside ``path``; on success rename it to ``path``.

    The target must be a regular file or absent (a directory, device node, FIFO or socket
    is refused with :class:`~inertialab.io.outputs.OutputError`; a link to a regular
    file replaces the file it points to). Inside a
    :func:`~inertialab.io.outputs.transaction` the rename waits for the transaction's
    commit, and a path inside a staged directory output is written into its staging
    directory. On an exception the temporary file is removed and the exception
    propagates; an ``OSError`` (disk full, read-only, permission) becomes an
    ``OutputError`` naming ``path``.
    """
    tx = outputs.current()
    if tx is not None:
        tx.check_inside(path)
    routed = tx.route(path) if tx is not None else None
    if routed is not None:  # inside a directory output: its staging directory is the temp
        try:
            routed.parent.mkdir(parents=True, exist_ok=True)
            outputs.file_target(routed)
        except OSError as exc:
            raise outputs.output_error(exc, path) from None
        try:
            yield routed
        except OSError as exc:
            raise outputs.output_error(exc, path) from None
        return
    target = outputs.file_target(path)
    if tx is not None:
        tx.makedirs(target.parent)
    elif not target.parent.exists():
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise outputs.output_error(exc, target.parent) from None
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except OSError as exc:
        raise outputs.output_error(exc, path) from None
    os.close(fd)
    try:
        yield Path(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        if tx is not None:
            tx.stage_file(Path(tmp), target)
        else:
            outputs.file_target(target)  # still a regular file or absent
            os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise outputs.output_error(exc, path) from None
        raise


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically (a temporary file beside it, renamed
    into place once complete).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = atomic_write_text(pathlib.Path(tempfile.mkdtemp()) / "note.txt", "ok")
    >>> p.read_text()
    'ok'
    """
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically.

    Examples
    --------
    The file appears whole or not at all; no temporary file is left beside it:

    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> list(atomic_write_bytes(folder / "blob.bin", bytes(range(4))).read_bytes())
    [0, 1, 2, 3]
    >>> sorted(p.name for p in folder.iterdir())
    ['blob.bin']
    >>> tmp.cleanup()
    """
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_record(df: pd.DataFrame, path: str | Path, meta: dict | None = None) -> Path:
    """Write a record as CSV (or Parquet for ``.parquet``) plus its JSON sidecar.

    Floats are written with full round-trip precision. ``meta`` gets
    ``schema_version`` = 1 unless given. Both files are written atomically and together
    (one transaction): a failure leaves neither.

    Examples
    --------
    A written record reads back with the same values and its sidecar:

    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> import numpy as np
    >>> import pandas as pd
    >>> from inertialab.io import read_record
    >>> rate = np.random.default_rng(0).normal(0.0, 1.0, 100)
    >>> frame = pd.DataFrame({"t_s": np.arange(100) / 100.0, "rate_dph": rate})
    >>> path = write_record(frame, folder / "gyro.csv", {"fs_hz": 100.0})
    >>> sorted(p.name for p in folder.iterdir())
    ['gyro.csv', 'gyro.meta.json']
    >>> rec = read_record(path, "gyro_log")
    >>> bool(np.array_equal(rec.column("rate_dph"), rate)), rec.meta["schema_version"]
    (True, 1)
    >>> tmp.cleanup()
    """
    p = Path(path)
    suffix = p.suffix.lower()
    with outputs.transaction():
        _write_data(df, p, suffix)
        m = {"schema_version": 1}
        m.update(meta or {})
        write_sidecar(p, m)
    return p


def _write_data(df: pd.DataFrame, p: Path, suffix: str) -> None:
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


def write_sidecar(path: str | Path, meta: dict) -> Path:
    """Write ``meta`` as the JSON sidecar of data file ``path`` (atomically)."""
    sp = sidecar_path(path)
    from inertialab.jsonable import to_jsonable  # numpy: loaded when a record is written

    text = json.dumps(to_jsonable(meta), indent=2, sort_keys=True, allow_nan=False)
    atomic_write_text(sp, text + "\n")
    return sp
