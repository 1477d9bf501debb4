"""The one-pass figure layout: margins measured before the draw leave
no text clipped or overlapping, axis labels sit where matplotlib's own rule puts them,
log labels stay readable without mathtext, and the PNG encoder writes the Agg pixels."""

import io
import re
import warnings

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.ticker import LogFormatterSciNotation
from PIL import Image

from inertialab.report import layout
from inertialab.report.html import encode_png, figure_png


def _loglog():
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    tau = np.geomspace(0.1, 3e4, 40)
    ax.loglog(tau, 0.3 / np.sqrt(tau) + 1e-3 * np.sqrt(tau), "o-", label="OADEV")
    ax.set_xlabel("averaging time τ (s)")
    ax.set_ylabel("deviation (deg/h)")
    ax.set_title("Allan family with confidence intervals and noise terms")
    ax.grid(True, which="both")
    ax.legend(loc="upper right")
    return fig


def _narrow_log():  # less than a decade: matplotlib labels minor ticks too
    fig, ax = plt.subplots(figsize=(6, 3.5))
    x = np.geomspace(2e-3, 9e-3, 30)
    ax.semilogy(np.arange(30), x)
    ax.set_ylabel("J (m/s²)²")
    return fig


def _symlog_grid():
    fig, axes = plt.subplots(2, 4, figsize=(12, 5.2), squeeze=False, sharey=True)
    rng = np.random.default_rng(3)
    for k, ax in enumerate(axes.ravel()[:7]):
        ax.scatter(rng.uniform(-40, 70, 80), rng.normal(0, 10 ** (k % 3 + 1), 80), s=4)
        ax.set_yscale("symlog", linthresh=10.0)
        ax.set_title(f"model {k}: RMSE {rng.uniform(1, 200):.1f} µg", fontsize=8)
        ax.set_xlabel("T (°C)", fontsize=8)
    axes.ravel()[7].axis("off")
    for ax in axes[:, 0]:
        ax.set_ylabel("residual (µg)", fontsize=8)
    return fig


def _colorbar():
    fig, ax = plt.subplots(figsize=(9, 4))
    f = np.geomspace(0.05, 100, 40)
    im = ax.pcolormesh(np.arange(60), f, np.random.default_rng(1).normal(20, 5, (40, 60)),
                       shading="auto")
    ax.set_yscale("log")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("frequency [Hz]")
    fig.colorbar(im, ax=ax, label="|W|^2 [dB re (deg/h)^2]")
    ax.set_title("CWT scalogram")
    return fig


def _twin_top_ticks():
    fig, ax = plt.subplots(figsize=(9, 6))
    ax.plot(np.arange(4000), np.sin(np.arange(4000) / 50.0))
    ax2 = ax.twiny()
    ax2.set_xlim(ax.get_xlim())
    ax2.set_xticks([500, 2000, 3500], ["1 Hz", "10 Hz", "100 Hz"], fontsize=7)
    ax.set_xlabel("time [s]")
    ax.set_title("Sweep run: details by level", fontsize=9)
    return fig


def _suptitle_rotated_offset():
    fig, axes = plt.subplots(1, 6, figsize=(11, 3.4))
    for k, ax in enumerate(axes):
        ax.errorbar(range(5), 1e5 + np.arange(5) * 1e-2 * (k + 1), yerr=0.01, fmt="o")
        ax.set_xticks(range(5), ["single-ls", "ls", "ebr", "ridge-hkb", "ridge-gcv"],
                      rotation=60, fontsize=7)
        ax.set_title(f"K{k}", fontsize=9)
    fig.supylabel("estimate (ug or ug/g^2)", fontsize=8)
    fig.suptitle("Coefficient estimates per method")
    return fig


def _stacked_long_ticks():
    fig, axes = plt.subplots(3, 1, figsize=(7.5, 6.5), sharex=True,
                             gridspec_kw={"height_ratios": [2.2, 1, 1]})
    t = np.arange(300.0)
    for k, ax in enumerate(axes):
        ax.plot(t, 1.2345e-4 * np.sin(t / (10 + k)), label=f"series {k}")
        ax.set_ylabel("bias (g)")
        ax.legend(loc="upper right", fontsize=7)
    axes[-1].set_xlabel("programme day")
    axes[0].set_title("unit QA001: bias fit")
    return fig


BUILDERS = [_loglog, _narrow_log, _symlog_grid, _colorbar, _twin_top_ticks,
            _suptitle_rotated_offset, _stacked_long_ticks]


@pytest.mark.parametrize("build", BUILDERS, ids=[b.__name__.strip("_") for b in BUILDERS])
def test_fit_leaves_no_clipped_or_overlapping_text(build):
    fig = build()
    fig.set_dpi(100)
    try:
        assert layout.fit(fig) is True
        assert layout.text_problems(fig) == []
        # the layout uses the figure: no axes shrunk to a sliver
        for ax in fig.axes:
            if ax.get_label() != "<colorbar>":
                assert ax.get_position().width * fig.get_figwidth() > 0.8
    finally:
        plt.close(fig)


def test_text_problems_reports_clipping_overlap_and_intrusion():
    fig, ax = plt.subplots(figsize=(4, 3))
    ax.plot([0, 1], [1000.5, 2000.25])
    ax.set_ylabel("a long y label that needs room")
    fig.subplots_adjust(left=0.0)  # y tick labels and label fall off the figure
    probs = layout.text_problems(fig)
    assert any(p.startswith("clipped by the figure edge") and "ylabel" in p for p in probs)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(4, 3))
    ax.text(0.5, 0.5, "first text", transform=ax.transAxes)
    ax.text(0.52, 0.51, "second text", transform=ax.transAxes)
    assert any(p.startswith("overlap: text 'first text'") for p in layout.text_problems(fig))
    plt.close(fig)

    fig, (a0, a1) = plt.subplots(1, 2, figsize=(5, 3))
    a1.plot([0, 1], [123456.0, 123457.5])
    fig.subplots_adjust(wspace=0.0)
    assert any(p.startswith("runs into another axes: ytick") for p in layout.text_problems(fig))
    plt.close(fig)


def test_pinned_axis_labels_sit_where_matplotlib_puts_them():
    """matplotlib's rule (Axis._update_label_position): the label is ``labelpad`` points
    outside the tick-label boxes. The pinned labels must land there within a pixel."""
    fig = _stacked_long_ticks()
    fig.set_dpi(100)
    layout.fit(fig)
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    for ax in fig.axes:
        boxes = [t.label1.get_window_extent(r) for t in ax.yaxis._update_ticks()
                 if t.label1.get_visible() and t.label1.get_text()]
        lab = ax.yaxis.label.get_window_extent(r)
        gap = min(b.x0 for b in boxes) - lab.x1
        assert gap == pytest.approx(ax.yaxis.labelpad * fig.dpi / 72, abs=1.0)
    ax = fig.axes[-1]
    boxes = [t.label1.get_window_extent(r) for t in ax.xaxis._update_ticks()
             if t.label1.get_visible() and t.label1.get_text()]
    lab = ax.xaxis.label.get_window_extent(r)
    gap = min(b.y0 for b in boxes) - lab.y1
    assert gap == pytest.approx(ax.xaxis.labelpad * fig.dpi / 72, abs=1.0)
    plt.close(fig)


_SUP = dict(zip("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789"))


def _parse_plain(s: str) -> float:
    s = s.replace("−", "-")
    m = re.fullmatch(r"(-?)(?:([\d.]+)×)?10([⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)|(-?[\d.]+)", s)
    assert m, s
    if m.group(4):
        return float(m.group(4))
    e = int("".join(_SUP[c] for c in m.group(3)))
    return (-1 if m.group(1) else 1) * float(m.group(2) or 1) * 10.0 ** e


@pytest.mark.parametrize("lims", [(1e-3, 1e4), (2e-3, 9e-3), (0.3, 2.0), (5.0, 6.0)])
def test_plain_log_labels_name_the_tick_values_matplotlib_labels(lims):
    """Each non-empty label reads back as its tick value, and exactly the ticks that
    matplotlib's own LogFormatterSciNotation labels carry a label."""
    fig, ax = plt.subplots()
    ax.set_yscale("log")
    ax.set_ylim(*lims)
    ref = {}
    for which in ("major", "minor"):
        axis = ax.yaxis
        locs = axis.get_majorticklocs() if which == "major" else axis.get_minorticklocs()
        fmt = axis.major.formatter if which == "major" else axis.minor.formatter
        assert isinstance(fmt, LogFormatterSciNotation)
        ref[which] = (locs, fmt.format_ticks(locs))
    layout.plain_log_labels(ax)
    for which, (locs, mathtext) in ref.items():
        fmt = ax.yaxis.major.formatter if which == "major" else ax.yaxis.minor.formatter
        plain = fmt.format_ticks(locs)
        assert [bool(s) for s in plain] == [bool(s) for s in mathtext]
        for loc, s in zip(locs, plain):
            if s:
                assert "$" not in s
                assert _parse_plain(s) == pytest.approx(loc, rel=2e-3)
    plt.close(fig)


def test_symlog_labels_have_sign_and_zero():
    fig, ax = plt.subplots()
    ax.set_yscale("symlog", linthresh=10.0)
    ax.set_ylim(-300, 300)
    layout.plain_log_labels(ax)
    locs = ax.yaxis.get_majorticklocs()
    labels = ax.yaxis.major.formatter.format_ticks(locs)
    got = {float(v): s for v, s in zip(locs, labels) if s}
    assert got[0.0] == "0" and got[-100.0] == "−10²" and got[10.0] == "10¹"
    plt.close(fig)


@pytest.mark.parametrize("opaque", [True, False])
def test_encode_png_round_trips_pixels(opaque):
    rng = np.random.default_rng(5)
    a = rng.integers(0, 256, (37, 53, 4), dtype=np.uint8)
    if opaque:
        a[..., 3] = 255
    data = encode_png(a, dpi=100)
    im = Image.open(io.BytesIO(data))
    assert im.mode == ("RGB" if opaque else "RGBA")
    assert np.array_equal(np.asarray(im.convert("RGBA")), a)
    assert im.info["dpi"][0] == pytest.approx(100, abs=0.01)


def test_figure_png_has_the_pixels_matplotlib_writes():
    """The PNG of figure_png decodes to the same pixels as matplotlib's own savefig of the
    same (laid-out) figure."""
    fig = _loglog()
    fig.set_dpi(100)
    layout.fit(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    ref = np.asarray(Image.open(io.BytesIO(buf.getvalue())).convert("RGB"))
    ours = np.asarray(Image.open(io.BytesIO(figure_png(fig, dpi=100))).convert("RGB"))
    assert ours.shape == ref.shape == (520, 750, 3)
    assert np.array_equal(ours, ref)


def test_labels_wider_than_the_figure_grow_the_canvas_as_before():
    """No room for a one-pass layout (a 300-character tick label from a unit id): fit says
    so and figure_png grows the PNG to what was drawn (bbox_inches="tight"), no warning."""
    fig, ax = plt.subplots(figsize=(7, 2.3))
    ax.set_yticks([0, 1], ["U" * 300, "x"])
    ax.set_xlabel("programme day")
    fig.set_dpi(110)
    assert layout.fit(fig) is False
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        png = figure_png(fig, dpi=110)
    assert Image.open(io.BytesIO(png)).size[0] > 3 * 7 * 110
