"""One-column ``.npy`` logs: memory-mapped, never loaded whole (needs a column name
with its unit and a rate, from the arguments or a sidecar with ``column`` and ``fs_hz``);
finiteness is checked and the hash computed in chunks of 4 Mi samples."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.io.record import Record
from inertialab.io.schemas import SCHEMAS
from inertialab.limits import regular_input
from inertialab.units import SUFFIXES, split_suffix

_MAX_ROWS_LISTED = 5


def check_rate(value, *, path, where: str) -> float:
    try:
        fs = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{where} must be a number in Hz, got {value!r}", path=path) from None
    if not np.isfinite(fs) or not 1e-9 <= fs <= 1e9:
        raise InputError(f"{where} must be a rate between 1e-9 and 1e9 Hz, got {value!r}",
                         path=path)
    return fs


def open_npy(p: Path) -> np.ndarray:
    regular_input(p)
    try:
        return np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise InputError(f"not a readable .npy file ({' '.join(str(exc).split())[:120]})",
                         path=p) from None


def read_npy_column(p: Path, kind: str, meta: dict, arr, *, unit, rate_hz, column):
    """A one-column ``.npy`` log as a Record (memory-mapped, hashed in chunks)."""
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
        raise InputError("a .npy log needs argument 'unit' (or argument 'column') and argument 'rate_hz', "
                         "or a sidecar "
                         "with 'column' and 'fs_hz'", path=p)
    fs = rate_hz if rate_hz is not None else meta.get("fs_hz")
    if fs is None:
        raise InputError("a .npy log needs argument 'rate_hz' (Hz) or a sidecar with 'fs_hz'", path=p)
    fs = check_rate(fs, path=p, where="argument 'rate_hz'" if rate_hz is not None
                     else "sidecar key 'fs_hz'")
    base, suf = split_suffix(name)
    if suf is None:
        raise InputError("column name has no unit suffix", path=p, column=name)
    if arr.shape[0] < SCHEMAS[kind].min_rows:
        raise InputError(f"too few samples: {arr.shape[0]}", path=p, column=name)
    # finiteness and hash in chunks: one pass over the memory map
    h = hashlib.sha256()
    h.update(name.encode() + b"\0")
    chunk = 1 << 22
    # a contiguous map is read through the file, not the mapping: a pass over a file
    # larger than memory then leaves nothing of it resident in the process
    fh = open(p, "rb") if isinstance(arr, np.memmap) and arr.flags.c_contiguous else None
    for start in range(0, arr.shape[0], chunk):
        if fh is not None:
            fh.seek(arr.offset + start * arr.itemsize)
            block = np.fromfile(fh, dtype=arr.dtype, count=min(chunk, arr.shape[0] - start))
            block = block.astype(np.float64, copy=False)
        else:
            block = np.ascontiguousarray(arr[start:start + chunk], dtype=np.float64)
        bad = ~np.isfinite(block)
        if bad.any():
            if fh is not None:
                fh.close()
            rows = (np.flatnonzero(bad)[:_MAX_ROWS_LISTED] + start + 1).tolist()
            raise InputError("NaN or infinite value", path=p, column=name, row=rows)
        h.update(block)  # (its buffer: the bytes tobytes() would copy)
    if fh is not None:
        fh.close()
    meta = dict(meta)
    meta["fs_hz"] = fs
    meta["column"] = name
    data = pd.DataFrame(index=pd.RangeIndex(0))
    from inertialab.io.timestamps import Timebase

    tb = Timebase(fs, "argument" if rate_hz is not None else "sidecar", int(arr.shape[0]))
    meta["timebase"] = tb.to_dict()
    return Record(kind=kind, data=data, meta=meta, path=str(p), units={name: suf},
                  sha256=h.hexdigest(), arrays={name: arr}, timebase=tb)
