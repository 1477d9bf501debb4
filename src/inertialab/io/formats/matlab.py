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


def _mat5(p: Path, dataset: str | None) -> Loaded:
    sio = need("scipy.io", "MATLAB files", path=p)
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
        if where not in fh:
            parent = "/".join(parts[:-1]) or "/"
            have = ", ".join(fh[parent].keys()) if parent in fh or parent == "/" else ""
            raise InputError(f"no dataset or group '{where}' (in {parent}: {have or 'nothing'})",
                             path=p)
        obj = fh[where]
        meta["dataset"] = where
        try:
            if isinstance(obj, h5py.Group):
                value = {k: obj[k][()] for k in obj if isinstance(obj[k], h5py.Dataset)}
            else:
                value = obj[()]
        except Exception as exc:
            text = " ".join(str(exc).split())[:160] or type(exc).__name__
            raise InputError(f"dataset '{where}' is unreadable ({text})", path=p) from None
    return Loaded(_from_value(value, p, where, meta), meta)


def read_matlab(path, kind: str, *, dataset: str | None = None) -> Loaded:
    """Read a ``.mat`` (``kind`` ``mat5``/``mat4``) or HDF5 / v7.3 file (``hdf5``)."""
    p = Path(path)
    if kind == "hdf5":
        return _hdf5(p, dataset)
    return _mat5(p, dataset)
