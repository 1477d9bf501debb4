"""M4 decimation: every column keeps its first, last, lowest and highest
sample (checked against a brute-force scan), and the drawn line looks like the full one."""

import matplotlib.pyplot as plt
import numpy as np
import pytest

from inertialab.report.decimate import (
    columns_for,
    m4,
    m4_even_indices,
    m4_indices,
    plot_m4,
    plot_m4_even,
)


def _series(kind: str, n: int = 200_000, seed: int = 0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 200.0
    if kind == "random walk + white":
        y = np.cumsum(rng.normal(size=n)) * 0.01 + rng.normal(size=n)
    elif kind == "sine + noise":
        y = np.sin(t / 30) + 0.05 * rng.normal(size=n)
    else:  # steps with rare spikes
        y = np.where(rng.random(n) < 1e-4, 8.0, 0.0) + np.floor(t / 300) + 0.1 * rng.normal(size=n)
    return t, y


@pytest.mark.parametrize("n_columns", [1, 7, 640])
def test_each_column_keeps_first_last_min_max(n_columns):
    rng = np.random.default_rng(7)
    x = np.sort(rng.uniform(0, 50, 20_000))
    y = rng.standard_t(2, x.size)
    keep = m4_indices(x, y, n_columns)
    assert np.all(np.diff(keep) > 0)
    edges = np.linspace(x[0], x[-1], n_columns + 1)
    col = np.minimum(np.searchsorted(edges, x, side="right") - 1, n_columns - 1)
    kept = set(keep.tolist())
    for c in np.unique(col):
        idx = np.flatnonzero(col == c)
        must = {idx[0], idx[-1], idx[np.argmin(y[idx])], idx[np.argmax(y[idx])]}
        assert must <= kept
        assert len(kept & set(idx.tolist())) <= 4
    assert len(keep) <= 4 * n_columns
    xs, ys = m4(x, y, n_columns)
    assert ys.max() == y.max() and ys.min() == y.min()
    assert xs[0] == x[0] and xs[-1] == x[-1]


@pytest.mark.parametrize("n", [10_007, 40_000])
def test_even_samples_keep_each_blocks_first_last_min_max(n):
    """Evenly spaced samples: the columns are blocks of n // n_columns samples; the fast
    path must keep each block's extremes (brute force), also through m4_indices."""
    y = np.random.default_rng(11).standard_t(2, n)
    n_columns = 300
    keep = m4_even_indices(y, n_columns)
    k = n // n_columns
    kept = set(keep.tolist())
    for s in range(0, n, k):
        idx = np.arange(s, min(s + k, n))
        must = {idx[0], idx[-1], idx[np.argmin(y[idx])], idx[np.argmax(y[idx])]}
        assert must <= kept
    assert np.array_equal(m4_indices(np.arange(n) * 0.005 + 3.0, y, n_columns), keep)
    assert len(keep) <= 4 * (n // k + 1)


def test_short_or_non_finite_series_are_kept_whole():
    x = np.arange(100.0)
    assert m4_indices(x, np.sin(x), 25).size == 100  # 100 <= 4 * 25
    y = np.sin(np.arange(10_000.0))
    y[500] = np.nan  # a gap the plot must show
    assert m4_indices(np.arange(10_000.0), y, 10).size == 10_000
    with pytest.raises(ValueError, match="non-decreasing"):
        m4_indices(np.arange(1000.0)[::-1], np.zeros(1000), 10)


def _render(x, y, lw, xlim):
    fig, ax = plt.subplots(figsize=(9, 3), dpi=100)
    ax.plot(x, y, lw=lw)
    ax.set_xlim(*xlim)
    fig.canvas.draw()
    a = np.asarray(fig.canvas.buffer_rgba()).astype(int)
    plt.close(fig)
    return a


@pytest.mark.parametrize("kind", ["random walk + white", "sine + noise", "steps + spikes"])
@pytest.mark.parametrize("lw", [0.4, 1.0])
def test_decimated_line_renders_like_the_full_line(kind, lw):
    t, y = _series(kind)
    fig, ax = plt.subplots(figsize=(9, 3), dpi=100)
    line = plot_m4(ax, t, y, lw=lw)
    xd, yd = line.get_xdata(), line.get_ydata()
    plt.close(fig)
    assert xd.size <= 4 * 3600 < t.size / 10
    full = _render(t, y, lw, (t[0], t[-1]))
    dec = _render(xd, yd, lw, (t[0], t[-1]))
    off = np.abs(full - dec).max(axis=-1)
    visible = (off > 32).mean()  # pixels off by more than 1/8 of full scale
    assert visible < 0.005
    if kind == "sine + noise":
        assert visible < 0.002


def test_plot_m4_even_puts_kept_samples_at_their_times():
    y = np.sin(np.arange(500_000) / 700.0)
    fig, ax = plt.subplots(figsize=(9, 3), dpi=100)
    line = plot_m4_even(ax, y, 0.005, t0=10.0)
    i = np.round((line.get_xdata() - 10.0) / 0.005).astype(int)
    assert np.allclose(line.get_xdata(), 10.0 + 0.005 * i)
    assert np.array_equal(line.get_ydata(), y[i])
    assert i[0] == 0 and i[-1] == y.size - 1 and i.size <= 4 * 3600 + 4
    plt.close(fig)


def test_a_million_samples_render_at_least_as_close_as_block_min_max():
    """1e6 samples of a thin (0.4 pt) noisy trace, ~1400 per pixel: the full trace shades
    its band darker than any four-per-column subset can, so M4 is not pixel-exact here.
    It must stay within 1.5 % visible pixels and closer to the full trace than the block
    min/max envelope of 4000 blocks the vibration figures used before."""
    n = 1_000_000
    t = np.arange(n) / 200.0
    y = np.sin(t / 30) + 0.05 * np.random.default_rng(0).normal(size=n)
    full = _render(t, y, 0.4, (t[0], t[-1]))
    keep = m4_even_indices(y, 3600)
    k = n // 4000
    blocks = y[: k * 4000].reshape(4000, k)
    tb = np.repeat(t[: k * 4000 : k], 2)
    yb = np.column_stack([blocks.min(1), blocks.max(1)]).ravel()
    off_m4 = (np.abs(_render(t[keep], y[keep], 0.4, (t[0], t[-1])) - full).max(-1) > 32).mean()
    off_blk = (np.abs(_render(tb, yb, 0.4, (t[0], t[-1])) - full).max(-1) > 32).mean()
    assert off_m4 < 0.015
    assert off_m4 < off_blk


def test_log_x_is_decimated_in_log_space():
    f = np.geomspace(1e-3, 1e2, 100_000)
    y = np.random.default_rng(2).lognormal(size=f.size)
    fig, ax = plt.subplots(figsize=(6, 3))
    ax.set_xscale("log")
    line = plot_m4(ax, f, y)
    xd = line.get_xdata()
    n = columns_for(ax)
    assert xd.size <= 4 * n
    per_decade = np.histogram(np.log10(xd), bins=5, range=(-3, 2))[0]
    assert per_decade.min() > 0.8 * per_decade.max()  # columns uniform in log f
    assert line.get_ydata().max() == y.max()
    plt.close(fig)


def test_columns_cover_the_widest_the_axes_can_get():
    fig, axes = plt.subplots(2, 2, figsize=(10, 4), dpi=100)
    assert columns_for(axes[0, 0]) == 4 * 500  # half of 1000 px, four per pixel
    fig2, ax = plt.subplots(figsize=(9, 3), dpi=100)
    assert columns_for(ax) == 3600
    plt.close(fig)
    plt.close(fig2)
