"""What every format reader shares: the :class:`Loaded` result, the import of an extra
(:func:`need`) and :func:`columns_frame` (split from ``dispatch`` so that the readers do
not import the dispatcher that imports them: no circle)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from inertialab.errors import InputError


@dataclass
class Loaded:
    frame: pd.DataFrame
    meta: dict = field(default_factory=dict)
    header_units: dict = field(default_factory=dict)


def need(module: str, what: str, *, path=None):
    """Import ``module`` of the ``[formats]`` extra, or a one-line InputError naming it."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise InputError(f"reading {what} needs the '{module.split('.')[0]}' package: "
                         "pip install 'inertialab[formats]'", path=path) from None


def columns_frame(arr: np.ndarray, *, meta: dict | None, names=None) -> pd.DataFrame:
    """A 2-D array as a frame ``col1..colN``; a short wide array (3 x n, MATLAB's row per
    axis) is transposed and ``meta["transposed"]`` set."""
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.shape[0] < arr.shape[1] and arr.shape[0] <= 16:
        arr = arr.T
        if meta is not None:
            meta["transposed"] = True
    names = names or [f"col{j + 1}" for j in range(arr.shape[1])]
    return pd.DataFrame({n: arr[:, j] for j, n in enumerate(names)})
