"""M4 decimation of long line series before plotting.

A line of 100 000 samples drawn into 800 pixel columns costs Agg a hundred segments per
column, and all but the first, last, lowest and highest sample of each column are hidden
under them. M4 (Jugel et al., "M4: a visualization-oriented time series data aggregation",
PVLDB 7(10), 2014) keeps exactly those four samples per column, so the drawn line keeps
every extreme and every column's entry and exit; with half-pixel columns the rendered
picture differs from the full line only in antialiasing at a few pixels (tested).
"""

from __future__ import annotations

import numpy as np

__all__ = ["columns_for", "m4", "m4_even_indices", "m4_indices", "plot_m4", "plot_m4_even"]


def m4_indices(x, y, n_columns: int) -> np.ndarray:
    """Indices of the first, last, minimum and maximum sample of ``y`` in each of
    ``n_columns`` equal columns of ``x`` (``x`` non-decreasing), ascending.

    Series of at most ``4 * n_columns`` samples, and series with non-finite values (whose
    gaps a plot shows as breaks), keep every index.
    """
    x = np.asarray(x)
    y = np.asarray(y)
    n = y.size
    if x.shape != y.shape or y.ndim != 1:
        raise ValueError(f"x and y must be 1-D of one length, got {x.shape} and {y.shape}")
    n_columns = int(n_columns)
    if n_columns < 1:
        raise ValueError(f"n_columns must be >= 1, got {n_columns}")
    every = np.arange(n)
    if n <= 4 * n_columns or not np.isfinite(y).all():
        return every
    dx = np.diff(x)
    x0, x1 = float(x[0]), float(x[-1])
    step = (x1 - x0) / (n - 1)
    if step > 0 and np.isfinite(step) and float(np.abs(dx - step).max()) <= 1e-9 * step:
        return m4_even_indices(y, n_columns)
    if not np.isfinite(x).all():
        return every
    if np.any(dx < 0):
        raise ValueError("x must be non-decreasing")
    if not x1 > x0:
        return every
    col = np.minimum(((x - x0) * (n_columns / (x1 - x0))).astype(np.int64), n_columns - 1)
    starts = np.flatnonzero(np.r_[True, col[1:] != col[:-1]])
    ends = np.r_[starts[1:], n] - 1
    seg = np.repeat(np.arange(starts.size), np.diff(np.r_[starts, n]))
    lo = np.minimum.reduceat(y, starts)
    hi = np.maximum.reduceat(y, starts)
    i_lo = np.minimum.reduceat(np.where(y == lo[seg], every, n), starts)
    i_hi = np.minimum.reduceat(np.where(y == hi[seg], every, n), starts)
    return np.unique(np.concatenate([starts, ends, i_lo, i_hi]))


def m4_even_indices(y, n_columns: int) -> np.ndarray:
    """M4 indices for evenly spaced samples: the columns are blocks of ``n // n_columns``
    samples (at least ``n_columns`` columns, each no wider than asked), first, last,
    argmin and argmax per block from one reshape (two passes over ``y``). Short series
    and series with non-finite values keep every index."""
    y = np.asarray(y)
    n = y.size
    if n <= 4 * n_columns or not np.isfinite(y).all():
        return np.arange(n)
    k = max(1, n // n_columns)
    m = n // k
    blocks = y[:m * k].reshape(m, k)
    base = np.arange(m) * k
    rows = np.stack([base, base + k - 1, base + blocks.argmin(axis=1),
                     base + blocks.argmax(axis=1)], axis=1)
    if m * k < n:  # the short last block
        tail = y[m * k:]
        rows = np.vstack([rows, m * k + np.array([0, tail.size - 1, tail.argmin(),
                                                  tail.argmax()])])
    idx = np.sort(rows, axis=1).ravel()  # blocks in order: sorted rows are sorted overall
    return idx[np.r_[True, idx[1:] != idx[:-1]]]


def m4(x, y, n_columns: int) -> tuple[np.ndarray, np.ndarray]:
    """The samples :func:`m4_indices` keeps, as ``(x, y)``."""
    keep = m4_indices(x, y, n_columns)
    return np.asarray(x)[keep], np.asarray(y)[keep]


def columns_for(ax, *, per_pixel: float = 4.0) -> int:
    """Columns for :func:`m4` on ``ax``: ``per_pixel`` per pixel of the widest the axes
    can become (its grid cell with no margins; the figure's width for an axes outside a
    grid), so quarter-pixel columns or finer whatever the layout does later. Agg's time
    for a dense trace depends on the pixels it covers, not on the 4 or 16 samples per
    pixel (measured: 17 ms either way for 1e6 samples), while four columns per pixel
    halve the visible difference to the full trace against two."""
    fig = ax.get_figure(root=True)
    frac = 1.0
    ss = ax.get_subplotspec()
    if ss is not None:
        top = ss.get_topmost_subplotspec()
        ratios = np.asarray(top.get_gridspec().get_width_ratios() or
                            [1.0] * top.get_gridspec().ncols, dtype=float)
        frac = float(ratios[top.colspan].sum() / ratios.sum())
    return max(1, int(np.ceil(per_pixel * frac * fig.get_figwidth() * fig.dpi)))


def plot_m4(ax, x, y, *args, **kwargs):
    """``ax.plot(x, y, ...)`` of the :func:`m4` decimation of a series on quarter-pixel
    columns of the x axis's scale (a log axis is decimated in log x); returns the line.
    Set the x scale before calling."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    tx = x if ax.get_xscale() == "linear" else ax.xaxis.get_transform().transform(x)
    keep = m4_indices(tx, y, columns_for(ax))
    line, = ax.plot(x[keep], y[keep], *args, **kwargs)
    return line


def plot_m4_even(ax, y, dt: float, *args, t0: float = 0.0, **kwargs):
    """``ax.plot(t0 + dt * arange(n), y, ...)`` of the :func:`m4_even_indices` decimation
    on quarter-pixel columns (linear x); the time axis is built for the kept samples only.
    Returns the line."""
    keep = m4_even_indices(y, columns_for(ax))
    line, = ax.plot(t0 + dt * keep, np.asarray(y)[keep], *args, **kwargs)
    return line
