"""MATLAB ``.mat`` (v4/v5 via :func:`scipy.io.loadmat`, v7.3 via ``h5py``) and HDF5
datasets, chosen by path (``dataset``: ``imu/gyro`` or ``imu.gyro``).

What a dataset path may name:

* a numeric matrix: columns ``col1 .. colN`` (a short wide matrix, MATLAB's row per
  axis or v7.3's transposed storage, is turned so that rows are samples;
  ``meta["transposed"]``); a vector: one column named after the variable;
* a struct (v5) or group (HDF5) of equal-length numeric fields: one column per field,
  an ``n x k`` field giving ``field_1 .. field_k``;
* an HDF5 compound dataset: one column per member.

Without ``dataset`` the file must hold exactly one such variable; otherwise the
:class:`~inertialab.errors.InputError` lists them. The columns are then mapped by the
column map like any table (``t_s=col1,gx_rps=col2:dps``).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.io.formats.base import Loaded, columns_frame, need
from inertialab.limits import check_budget, memory_budget

__all__ = ["read_matlab"]

_SPLIT = re.compile(r"[/.]")


def _parts(dataset: str | None) -> list[str]:
    return [x for x in _SPLIT.split(dataset or "") if x]


def _frame_from_fields(fields: dict, p: Path, where: str) -> pd.DataFrame:
    cols = {}
    n = None
    for name, v in fields.items():
        a = np.asarray(v)
        if a.dtype.kind not in "biuf" or a.ndim == 0 or a.size == 0:
            continue
        if a.ndim == 2 and min(a.shape) == 1:
            a = a.reshape(-1)
        if a.ndim == 2 and a.shape[0] < a.shape[1] and a.shape[0] <= 16:
            a = a.T
        length = a.shape[0]
        if n is None:
            n = length
        if length != n:
            raise InputError(f"fields of '{where}' differ in length ({name}: {length}, "
                             f"others: {n})", path=p)
        if a.ndim == 1:
            cols[name] = a.astype(float)
        elif a.ndim == 2:
            for j in range(a.shape[1]):
                cols[f"{name}_{j + 1}"] = a[:, j].astype(float)
    if not cols:
        raise InputError(f"'{where}' holds no numeric fields", path=p)
    return pd.DataFrame(cols)


def _from_value(v, p: Path, where: str, meta: dict) -> pd.DataFrame:
    if isinstance(v, dict):
        return _frame_from_fields(v, p, where)
    a = np.asarray(v)
    if a.dtype.names:
        return pd.DataFrame({n: np.asarray(a[n]).reshape(-1) for n in a.dtype.names})
    if a.dtype.kind not in "biuf":
        raise InputError(f"'{where}' is not numeric (MATLAB class {a.dtype})", path=p)
    if a.ndim == 1 or (a.ndim == 2 and min(a.shape) == 1):
        return pd.DataFrame({where.split("/")[-1]: a.reshape(-1).astype(float)})
    if a.ndim != 2:
        raise InputError(f"'{where}' has {a.ndim} dimensions, expected a matrix", path=p)
    return columns_frame(a, meta=meta)


_MI_MATRIX, _MI_COMPRESSED = 14, 15
_SCAN_CHUNK = 1 << 20


def _mat5_decompressed_bytes(p: Path) -> int:
    """Bytes a MATLAB v5 file holds once its compressed variables are inflated, counted
    by streaming each ``miCOMPRESSED`` element through zlib without keeping the output
    and stopping as soon as the total passes the memory budget (a 4 MB file may declare
    4 GiB of zeros)."""
    import struct
    import zlib

    budget = memory_budget()
    total = 0
    with open(p, "rb") as fh:
        head = fh.read(128)
        if len(head) < 128:
            return 0
        order = "<" if head[126:128] == b"IM" else ">"
        while total <= budget:
            tag = fh.read(8)
            if len(tag) < 8:
                break
            mtype, nbytes = struct.unpack(order + "II", tag)
            if mtype not in (_MI_MATRIX, _MI_COMPRESSED):
                break  # not a top-level variable: damaged, loadmat says so
            if mtype == _MI_MATRIX:
                total += nbytes
                fh.seek(nbytes + (-nbytes % 8), 1)
                continue
            inflate = zlib.decompressobj()
            left = nbytes
            while left > 0 and total <= budget:
                chunk = fh.read(min(left, _SCAN_CHUNK))
                if not chunk:
                    break
                left -= len(chunk)
                try:
                    while chunk and total <= budget:  # bounded output per call
                        total += len(inflate.decompress(chunk, 16 * _SCAN_CHUNK))
                        chunk = inflate.unconsumed_tail
                except zlib.error:
                    return total  # corrupt: loadmat says so
            if left > 0 and total <= budget:
                fh.seek(left, 1)
    return total


def _mat5(p: Path, dataset: str | None) -> Loaded:
    sio = need("scipy.io", "MATLAB files", path=p)
    check_budget(_mat5_decompressed_bytes(p), "the variables of this MATLAB file", p,
                 scanned=True)
    try:
        doc = sio.loadmat(str(p), simplify_cells=True)
    except NotImplementedError:  # v7.3 without the HDF5 signature where we looked
        return _hdf5(p, dataset)
    except Exception as exc:  # scipy raises ValueError, TypeError, MatReadError ...
        text = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise InputError(f"not a readable MATLAB file ({type(exc).__name__}: {text})",
                         path=p) from None
    names = [k for k in doc if not k.startswith("__")]
    parts = _parts(dataset)
    meta: dict = {"format": "matlab v5"}
    if not parts:
        usable = [k for k in names if isinstance(doc[k], dict)
                  or (isinstance(doc[k], np.ndarray) and doc[k].dtype.kind in "biuf")]
        if len(usable) != 1:
            listing = ", ".join(f"{k} {np.shape(doc[k]) if not isinstance(doc[k], dict) else '(struct)'}"
                                for k in names)
            raise InputError(f"{len(usable)} numeric variables ({listing}); choose one "
                             "(argument 'dataset')", path=p)
        parts = [usable[0]]
    v = doc
    for k, part in enumerate(parts):
        if not isinstance(v, dict) or part not in v:
            here = "/".join(parts[:k]) or "the file"
            have = ", ".join(x for x in (v if isinstance(v, dict) else {}) if not x.startswith("__"))
            raise InputError(f"no variable or field '{part}' in {here} (has: {have or 'nothing'})",
                             path=p)
        v = v[part]
    where = "/".join(parts)
    meta["dataset"] = where
    return Loaded(_from_value(v, p, where, meta), meta)


def _hdf5(p: Path, dataset: str | None) -> Loaded:
    h5py = need("h5py", "MATLAB v7.3 / HDF5 files", path=p)
    meta: dict = {"format": "hdf5"}
    try:
        fh = h5py.File(str(p), "r")
    except Exception as exc:  # OSError with HDF5's reason (truncated file: eof = ...)
        text = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise InputError(f"not a readable HDF5 / MATLAB v7.3 file ({text})", path=p) from None
    with fh:
        parts = _parts(dataset)
        if not parts:
            found = []
            fh.visititems(lambda n, o: found.append(n) if isinstance(o, h5py.Dataset)
                          and o.dtype.kind in "biufV" and not n.startswith("#") else None)
            if len(found) != 1:
                listing = ", ".join(f"{n} {fh[n].shape}" for n in found[:20])
                raise InputError(f"{len(found)} numeric datasets ({listing or 'none'}); choose "
                                 "one (argument 'dataset')", path=p)
            parts = _parts(found[0])
        where = "/".join(parts)
        obj = _resolve(h5py, fh, parts, p)
        meta["dataset"] = where
        if isinstance(obj, h5py.Group):
            members = {k: _inside(h5py, obj, k, f"{where}/{k}", p) for k in obj}
            members = {k: v for k, v in members.items() if isinstance(v, h5py.Dataset)}
        else:
            members = {where: obj}
        for name, ds in members.items():
            _check_dataset(ds, name, p)
        check_budget(sum(ds.size * ds.dtype.itemsize for ds in members.values()),
                     f"dataset '{where}' ({' + '.join(str(ds.shape) for ds in members.values())}"
                     " values)", p)
        try:
            if isinstance(obj, h5py.Group):
                value = {k: ds[()] for k, ds in members.items()}
            else:
                value = obj[()]
        except Exception as exc:
            text = " ".join(str(exc).split())[:160] or type(exc).__name__
            raise InputError(f"dataset '{where}' is unreadable ({text})", path=p) from None
    return Loaded(_from_value(value, p, where, meta), meta)


def _inside(h5py, group, name: str, where: str, p: Path):
    """``group[name]`` after checking its link: an external link (data in another file)
    is refused; a soft-link loop or a dangling link is one error line."""
    link = group.get(name, getlink=True)
    if isinstance(link, h5py.ExternalLink):
        raise InputError(f"'{where}' is an external link to '{link.filename}'; inertialab "
                         "reads only data stored inside the file", path=p)
    try:
        return group[name]
    except Exception as exc:  # KeyError / RuntimeError: dangling link or soft-link loop
        text = " ".join(str(exc).split())[:120] or type(exc).__name__
        raise InputError(f"'{where}' cannot be resolved (a dangling or looping soft link: "
                         f"{text})", path=p) from None


def _resolve(h5py, fh, parts: list[str], p: Path):
    """The object at ``parts``, one link at a time (see :func:`_inside`)."""
    obj = fh
    for k, part in enumerate(parts):
        here = "/".join(parts[:k + 1])
        if not isinstance(obj, h5py.Group) or part not in _names(obj):
            parent = "/".join(parts[:k]) or "/"
            have = ", ".join(_names(obj)) if isinstance(obj, h5py.Group) else ""
            raise InputError(f"no dataset or group '{'/'.join(parts)}' (in {parent}: "
                             f"{have or 'nothing'})", path=p)
        obj = _inside(h5py, obj, part, here, p)
    return obj


def _names(group) -> list[str]:
    try:
        return list(group.keys())
    except Exception:  # pragma: no cover - a corrupt group
        return []


def _check_dataset(ds, where: str, p: Path) -> None:
    """Refuse a dataset whose data live outside the file (external raw storage, a
    virtual dataset) before reading it."""
    if ds.external:
        files = ", ".join(str(e[0]) for e in ds.external[:3])
        raise InputError(f"dataset '{where}' stores its data in external file(s) ({files}); "
                         "inertialab reads only data stored inside the file", path=p)
    if getattr(ds, "is_virtual", False):
        raise InputError(f"dataset '{where}' is a virtual dataset (its data live in other "
                         "files); inertialab reads only data stored inside the file", path=p)


def read_matlab(path, kind: str, *, dataset: str | None = None) -> Loaded:
    """Read a ``.mat`` (``kind`` ``mat5``/``mat4``) or HDF5 / v7.3 file (``hdf5``)."""
    p = Path(path)
    if kind == "hdf5":
        return _hdf5(p, dataset)
    return _mat5(p, dataset)
