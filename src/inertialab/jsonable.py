"""The one JSON sanitiser: numpy scalars/arrays, tuples, paths and objects with
``to_dict`` to plain JSON values ("one of each").

JSON has no NaN or infinity: a non-finite float becomes ``None`` and, when a list is
passed as ``nulls``, the key path of every such value is appended to it so that the
CLI can flag it (``non_estimable``, docs/cli.md). Used by model files,
sidecars, the ``--json`` envelope, the report's ``results.json`` and every ``to_dict``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def to_jsonable(obj, *, nulls: list[str] | None = None, path: str = ""):
    """Plain-JSON copy of ``obj`` (dicts, lists, str, int, float, bool, None).

    Parameters
    ----------
    obj : any
        Dicts (keys become ``str``), lists/tuples, numpy arrays and scalars, ``Path``,
        objects with a ``to_dict()`` method, and plain JSON values.
    nulls : list of str, optional
        Receives the dotted key path (``a.b[2]``) of every non-finite float replaced by
        ``None``.
    path : str
        Key path of ``obj`` itself (used in recursion).
    """
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v, nulls=nulls, path=f"{path}.{k}" if path else str(k))
                for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v, nulls=nulls, path=f"{path}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist(), nulls=nulls, path=path)
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        f = float(obj)
        if math.isfinite(f):
            return f
        if nulls is not None:
            nulls.append(path)
        return None
    if isinstance(obj, Path):
        return str(obj)
    if hasattr(obj, "to_dict") and not isinstance(obj, type):
        return to_jsonable(obj.to_dict(), nulls=nulls, path=path)
    return obj
