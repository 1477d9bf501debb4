"""Figure layout computed once, before the one draw that writes the PNG.

matplotlib's ``tight_layout`` (and ``bbox_inches="tight"``) find the margins by laying out
every tick label, axis label and title, then draw the figure again; the draw itself then
positions each axis label and title from the tick-label boxes of the axis and of its
siblings (more tick updates). Together that was about a third of the report's figure time.

:func:`fit` measures the decorations instead: the strings the tick formatters will print,
the axis labels and titles, through the renderer's text-metrics cache (the draw reuses the
same cached metrics), sets the grid's margins and gaps from them, and pins every axis label
and title at its final place, so the draw computes no layout. :func:`text_problems` draws a
figure and lists text that is clipped by the figure edge, overlaps other text or runs into
another axes; the tests hold every report figure to an empty list.

:class:`PowerOfTenFormatter` labels log axes with plain text (``10⁻³``) instead of mathtext,
whose first parse of each label costs milliseconds in pyparsing.
"""

from __future__ import annotations

import math
import warnings
import weakref

import numpy as np
from matplotlib.text import Text
from matplotlib.ticker import Formatter, LogFormatterMathtext

__all__ = ["PowerOfTenFormatter", "fit", "plain_log_labels", "text_problems"]

#: Space between the outermost text and the figure edge (inches).
EDGE_PAD_IN = 0.06
#: Space between the decorations of neighbouring axes (inches).
GAP_IN = 0.14

_SUPER = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
_fitted: weakref.WeakSet = weakref.WeakSet()
_pinned: weakref.WeakSet = weakref.WeakSet()  # labels and titles that fit() placed


class PowerOfTenFormatter(Formatter):
    """Log-axis tick labels in plain text (``10⁻³``, ``2×10⁻³``, ``−10²``, ``0``) for the
    ticks that matplotlib's own log formatter ``inner`` labels (it decides which ticks get
    a label, from the decades in view); no mathtext, so no pyparsing per label."""

    def __init__(self, inner: LogFormatterMathtext):
        self.inner = inner

    def set_axis(self, axis):
        super().set_axis(axis)
        self.inner.set_axis(axis)

    def set_locs(self, locs):
        self.inner.set_locs(locs)

    @staticmethod
    def _power(k: int) -> str:
        return "10" + str(k).translate(_SUPER)

    def __call__(self, x, pos=None) -> str:
        if not self.inner(x, pos):
            return ""
        if x == 0:
            return "0"
        sign = "−" if x < 0 else ""
        e = math.log10(abs(x))
        k = round(e)
        if abs(e - k) < 1e-9:
            return sign + self._power(k)
        f = math.floor(e)
        m = abs(x) / 10.0 ** f
        return sign + (f"{m:.3g}" if f == 0 else f"{m:.3g}×" + self._power(f))


def plain_log_labels(ax) -> None:
    """Wrap matplotlib's mathtext log formatters (``LogFormatterSciNotation``, the default
    of log and symlog axes) of ``ax`` in :class:`PowerOfTenFormatter`; axes with other
    formatters are left alone. :func:`fit` calls it for every axes."""
    for axis in (ax.xaxis, ax.yaxis):
        if isinstance(axis.major.formatter, LogFormatterMathtext):
            axis.set_major_formatter(PowerOfTenFormatter(axis.major.formatter))
        if isinstance(axis.minor.formatter, LogFormatterMathtext):
            axis.set_minor_formatter(PowerOfTenFormatter(axis.minor.formatter))


# ---------------------------------------------------------------- measuring -------------

class _Ruler:
    """Text sizes in inches through one scratch Text (the renderer caches the metrics,
    so the draw that follows measures nothing twice)."""

    def __init__(self, fig, renderer):
        self.fig = fig
        self.renderer = renderer
        self.dpi = fig.dpi
        self.t = Text(0, 0, "")
        self.t.set_figure(fig)
        self._like = None

    def size(self, s: str, like: Text) -> tuple[float, float]:
        if not s:
            return 0.0, 0.0
        t = self.t
        if self._like is not like:
            t.set_fontproperties(like.get_fontproperties())
            t.set_rotation(like.get_rotation())
            t.set_linespacing(like.get_linespacing())
            self._like = like
        t.set_text(s)
        bb = t.get_window_extent(self.renderer)
        return bb.width / self.dpi, bb.height / self.dpi

    def own(self, text: Text) -> tuple[float, float]:
        if not text.get_visible() or not text.get_text():
            return 0.0, 0.0
        bb = text.get_window_extent(self.renderer)
        return bb.width / self.dpi, bb.height / self.dpi


def _tick_side_extents(axis, ruler: _Ruler) -> dict:
    """Outward extent (inches) of the ticks and tick labels on each side of ``axis``
    (side 1 = left/bottom, side 2 = right/top) and the width/height of the widest label."""
    out = {"ext1": 0.0, "ext2": 0.0, "label_w": 0.0, "label_h": 0.0, "edge": (0.0, 0.0)}
    if not axis.get_visible():
        return out
    lo, hi = sorted(axis.get_view_interval())
    tol = 1e-9 * max(abs(lo), abs(hi), 1e-300)
    sides = {1: 0.0, 2: 0.0}
    first_last = [0.0, 0.0]
    for major in (True, False):
        kw = axis._major_tick_kw if major else axis._minor_tick_kw
        if not axis._tick_group_visible(kw):
            continue
        locs = axis.get_majorticklocs() if major else axis.get_minorticklocs()
        if len(locs) == 0:
            continue
        ticks = axis.majorTicks if major else axis.minorTicks  # creates the first tick
        fmt = axis.major.formatter if major else axis.minor.formatter
        labels = fmt.format_ticks(locs)
        inview = [(lc, lab) for lc, lab in zip(locs, labels) if lo - tol <= lc <= hi + tol]
        tick = ticks[0]
        out_len = tick.get_tick_padding() / 72.0
        pad = (tick.get_pad() + tick.get_tick_padding()) / 72.0
        # the widest label is among the longest strings; the end labels overhang
        labs = [lab for _loc, lab in inview]
        longest = max((len(lab) for lab in labs), default=0)
        measure = {lab for lab in labs if lab and len(lab) >= longest - 1}
        if labs:
            measure |= {labs[0], labs[-1]}
        size = {lab: ruler.size(lab, tick.label1) for lab in measure}
        w = max((v[0] for v in size.values()), default=0.0)
        h = max((v[1] for v in size.values()), default=0.0)
        if major and labs:
            along = 0 if axis.axis_name == "x" else 1
            first_last = [size[labs[0]][along] / 2, size[labs[-1]][along] / 2]
        deep = w if axis.axis_name == "y" else h
        for side, line, label in ((1, tick.tick1line, tick.label1),
                                  (2, tick.tick2line, tick.label2)):
            e = out_len if line.get_visible() else 0.0
            if label.get_visible() and inview:
                e = pad + deep
            sides[side] = max(sides[side], e)
        out["label_w"] = max(out["label_w"], w)
        out["label_h"] = max(out["label_h"], h)
    out["ext1"], out["ext2"] = sides[1], sides[2]
    out["edge"] = tuple(first_last)
    return out


def _decorations(ax, ruler: _Ruler) -> dict:
    """Decorations of one axes outside its box, in inches: ``l, r, b, t`` (titles not
    included), ``above`` (ticks, tick labels and label on top) and the tick extents the
    axis labels are pinned against."""
    none = {"ext1": 0.0, "ext2": 0.0, "edge": (0.0, 0.0)}
    xt = _tick_side_extents(ax.xaxis, ruler) if ax.axison else none
    yt = _tick_side_extents(ax.yaxis, ruler) if ax.axison else none
    d = {"xt": xt, "yt": yt, "l": yt["ext1"], "r": yt["ext2"], "b": xt["ext1"],
         "t": xt["ext2"]}
    # tick labels at the ends of an axis stick out along it by half their size
    d["l"] = max(d["l"], xt["edge"][0])
    d["r"] = max(d["r"], xt["edge"][1])
    d["b"] = max(d["b"], yt["edge"][0])
    d["t"] = max(d["t"], yt["edge"][1])
    if ax.axison:
        for axis, key in ((ax.xaxis, "x"), (ax.yaxis, "y")):
            if not axis.get_visible():
                continue
            lw, lh = ruler.own(axis.label)
            pad = axis.labelpad / 72.0
            if key == "x" and lh:
                d["b" if axis.get_label_position() == "bottom" else "t"] += pad + lh
            elif key == "y" and lw:
                d["l" if axis.get_label_position() == "left" else "r"] += pad + lw
            _ow, oh = ruler.size(axis.major.formatter.get_offset(), axis.offsetText)
            if oh and key == "y":
                d["t"] = max(d["t"], oh + 0.04)
            elif oh:
                d["b"] = max(d["b"], xt["ext1"] + oh + 0.04)
    d["above"] = d["t"]
    d["title_h"] = max(ruler.own(t)[1] for t in (ax.title, ax._left_title, ax._right_title))
    return d


def _title_pad_in(ax) -> float:
    off = ax.titleOffsetTrans.get_matrix()[1, 2]  # pixels at the figure's dpi
    return off / ax.get_figure(root=True).dpi


# ---------------------------------------------------------------- fitting ---------------

def fit(fig, *, pad_in: float = EDGE_PAD_IN, gap_in: float = GAP_IN) -> bool:
    """Set the margins and gaps of ``fig``'s subplot grid from its measured decorations,
    then pin axis labels and titles where the draw would have put them.

    Works for figures whose axes come from one grid (``plt.subplots``, also with
    colorbars, twins, ``suptitle``/``supylabel``); any other figure gets matplotlib's
    ``tight_layout`` (one extra layout pass), and a figure whose labels are wider than
    the figure is left as it is. Returns True when the one-pass layout was used (else
    :func:`~inertialab.report.html.figure_png` grows the canvas to what is drawn).
    Calling it again re-measures (cheap: the metrics are cached).
    """
    axes = [ax for ax in fig.axes if ax.get_visible()]
    grids = set()
    for ax in axes:
        ss = ax.get_subplotspec()
        if ss is None:
            grids = None
            break
        grids.add(ss.get_topmost_subplotspec().get_gridspec())
    if not axes or grids is None or len(grids) != 1:
        if axes:
            with warnings.catch_warnings():  # it says so when it cannot; False says it too
                warnings.simplefilter("ignore", UserWarning)
                fig.tight_layout()
        _fitted.add(fig)
        return False
    gs = grids.pop()
    renderer = fig.canvas.get_renderer()
    ruler = _Ruler(fig, renderer)
    W, H = fig.get_size_inches()
    nrows, ncols = gs.get_geometry()
    left = np.zeros(ncols)
    right = np.zeros(ncols)
    top = np.zeros(nrows)
    bottom = np.zeros(nrows)
    decos = {}
    for ax in axes:
        plain_log_labels(ax)
        decos[ax] = _decorations(ax, ruler)
    for ax, d in decos.items():  # titles sit above the top decorations of all twins
        d["above"] = max(decos[s]["above"] for s in ax._twinned_axes.get_siblings(ax)
                         if s in decos)
        if d["title_h"]:
            d["t"] = max(d["t"], d["above"] + _title_pad_in(ax) + d["title_h"])
        top_ss = ax.get_subplotspec().get_topmost_subplotspec()
        rs, cs = top_ss.rowspan, top_ss.colspan
        left[cs.start] = max(left[cs.start], d["l"])
        right[cs.stop - 1] = max(right[cs.stop - 1], d["r"])
        top[rs.start] = max(top[rs.start], d["t"])
        bottom[rs.stop - 1] = max(bottom[rs.stop - 1], d["b"])
    L = pad_in + left[0]
    R = pad_in + right[-1]
    T = pad_in + top[0]
    B = pad_in + bottom[-1]
    sup = getattr(fig, "_suptitle", None)
    if sup is not None and sup.get_visible() and sup.get_text():
        T = max(T, (1 - sup.get_position()[1]) * H + ruler.own(sup)[1] + gap_in + top[0])
    sy = getattr(fig, "_supylabel", None)
    if sy is not None and sy.get_visible() and sy.get_text():
        L = max(L, sy.get_position()[0] * W + ruler.own(sy)[0] + gap_in + left[0])
    sx = getattr(fig, "_supxlabel", None)
    if sx is not None and sx.get_visible() and sx.get_text():
        B = max(B, sx.get_position()[1] * H + ruler.own(sx)[1] + gap_in + bottom[-1])
    wgap = max((right[j] + left[j + 1] for j in range(ncols - 1)), default=0.0) + gap_in
    hgap = max((bottom[i] + top[i + 1] for i in range(nrows - 1)), default=0.0) + gap_in
    ax_w = (W - L - R - (ncols - 1) * wgap) / ncols
    ax_h = (H - T - B - (nrows - 1) * hgap) / nrows
    if ax_w <= 0.2 or ax_h <= 0.2:  # decorations wider than the figure: not laid out
        _fitted.add(fig)
        return False
    gs.update(left=L / W, right=1 - R / W, bottom=B / H, top=1 - T / H,
              wspace=wgap / ax_w if ncols > 1 else None,
              hspace=hgap / ax_h if nrows > 1 else None)
    for ax, d in decos.items():
        _pin(ax, d, fig)
    _fitted.add(fig)
    return True


def _pin(ax, d: dict, fig) -> None:
    """Place the axis labels and the title of ``ax`` now (the draw then skips the
    tick-label-box search that positions them)."""
    locator = ax.get_axes_locator()  # a colorbar shrinks its box to its aspect at the draw
    ax.apply_aspect(locator(ax, fig.canvas.get_renderer()) if locator else None)
    pos = ax.get_position(original=False)
    W, H = fig.get_size_inches()
    aw, ah = pos.width * W, pos.height * H
    if aw <= 0 or ah <= 0:
        return
    if ax.axison:
        xa, ya = ax.xaxis, ax.yaxis
        if xa.get_visible() and xa.label.get_text():
            x = xa.label.get_position()[0] if _ours(xa) else None
            pad = xa.labelpad / 72.0
            if x is not None:
                if xa.get_label_position() == "bottom":
                    xa.set_label_coords(x, -(d["xt"]["ext1"] + pad) / ah)
                else:
                    xa.set_label_coords(x, 1 + (d["xt"]["ext2"] + pad) / ah)
        if ya.get_visible() and ya.label.get_text():
            y = ya.label.get_position()[1] if _ours(ya) else None
            pad = ya.labelpad / 72.0
            if y is not None:
                if ya.get_label_position() == "left":
                    ya.set_label_coords(-(d["yt"]["ext1"] + pad) / aw, y)
                else:
                    ya.set_label_coords(1 + (d["yt"]["ext2"] + pad) / aw, y)
    if getattr(ax, "_autotitlepos", None) is not False or ax.title in _pinned:
        y = 1.0 + d["above"] / ah
        for t in (ax.title, ax._left_title, ax._right_title):
            t.set_y(y)
            _pinned.add(t)
        ax._autotitlepos = False  # pinned: the draw does not search the twins' boxes


def _ours(axis) -> bool:
    """Whether the label of ``axis`` is placed by matplotlib or by an earlier :func:`fit`
    (a label the caller placed with ``set_label_coords`` stays where it is)."""
    if axis._autolabelpos or axis.label in _pinned:
        _pinned.add(axis.label)
        return True
    return False


def is_fitted(fig) -> bool:
    """Whether :func:`fit` has laid ``fig`` out."""
    return fig in _fitted


# ---------------------------------------------------------------- checking --------------

def _corners(bb, rotation: float) -> np.ndarray:
    """The oriented rectangle of a (possibly rotated) text from its axis-aligned box."""
    c, s = abs(math.cos(math.radians(rotation))), abs(math.sin(math.radians(rotation)))
    W, H = bb.width, bb.height
    cx, cy = (bb.x0 + bb.x1) / 2, (bb.y0 + bb.y1) / 2
    det = c * c - s * s
    if s < 1e-6 or c < 1e-6 or abs(det) < 0.2:
        return np.array([[bb.x0, bb.y0], [bb.x1, bb.y0], [bb.x1, bb.y1], [bb.x0, bb.y1]])
    w = (c * W - s * H) / det
    h = (c * H - s * W) / det
    th = math.radians(rotation)
    u = np.array([math.cos(th), math.sin(th)]) * w / 2
    v = np.array([-math.sin(th), math.cos(th)]) * h / 2
    ctr = np.array([cx, cy])
    return np.array([ctr - u - v, ctr + u - v, ctr + u + v, ctr - u + v])


def _overlap(p: np.ndarray, q: np.ndarray, tol: float) -> bool:
    """Separating-axis test of two convex quadrilaterals, overlap deeper than ``tol``."""
    for poly in (p, q):
        for i in range(4):
            e = poly[(i + 1) % 4] - poly[i]
            n = np.array([-e[1], e[0]])
            norm = np.hypot(*n)
            if norm == 0:
                continue
            n /= norm
            a, b = p @ n, q @ n
            if min(a.max(), b.max()) - max(a.min(), b.min()) <= tol:
                return False
    return True


def _texts(fig, renderer):
    """(what, owner axes or None, oriented box) of every visible text of the figure;
    a legend counts as one box."""
    items = []

    def add(t, what, owner):
        if t is None or not t.get_visible() or not t.get_text().strip():
            return
        bb = t.get_window_extent(renderer)
        if bb.width <= 0 or bb.height <= 0:
            return
        items.append((f"{what} {t.get_text()!r}", owner, bb, _corners(bb, t.get_rotation())))

    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for t in (ax.title, ax._left_title, ax._right_title):
            add(t, "title", ax)
        if ax.axison:
            for axis in (ax.xaxis, ax.yaxis):
                if not axis.get_visible():
                    continue
                add(axis.label, f"{axis.axis_name}label", ax)
                add(axis.offsetText, f"{axis.axis_name} offset", ax)
                for tick in axis._update_ticks():
                    add(tick.label1, f"{axis.axis_name}tick", ax)
                    add(tick.label2, f"{axis.axis_name}tick", ax)
        for t in ax.texts:
            add(t, "text", ax)
        leg = ax.get_legend()
        if leg is not None and leg.get_visible():
            bb = leg.get_window_extent(renderer)
            items.append(("legend", ax, bb, _corners(bb, 0.0)))
    seen = set()
    for t in (getattr(fig, "_suptitle", None), getattr(fig, "_supxlabel", None),
              getattr(fig, "_supylabel", None), *fig.texts):
        if id(t) not in seen:
            seen.add(id(t))
            add(t, "figure text", None)
    return items


def text_problems(fig, *, tol_px: float = 1.0) -> list[str]:
    """Draw ``fig`` and list its text problems: text clipped by the figure edge, two texts
    overlapping, and text of one axes (or of the figure) running into another axes' box.
    An empty list means every label, title, tick label and legend is readable."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    W, H = fig.bbox.width, fig.bbox.height
    items = _texts(fig, renderer)
    problems = []
    for what, _owner, bb, _c in items:
        if bb.x0 < -tol_px or bb.y0 < -tol_px or bb.x1 > W + tol_px or bb.y1 > H + tol_px:
            problems.append(f"clipped by the figure edge: {what} "
                            f"[{bb.x0:.0f}, {bb.y0:.0f}, {bb.x1:.0f}, {bb.y1:.0f}] "
                            f"in {W:.0f} x {H:.0f}")
    for i in range(len(items)):
        for j in range(i + 1, len(items)):
            a, b = items[i], items[j]
            if _overlap(a[3], b[3], tol_px):
                problems.append(f"overlap: {a[0]} and {b[0]}")
    boxes = []
    for ax in fig.axes:
        if ax.get_visible() and ax.axison:
            boxes.append((ax, ax.get_window_extent(renderer)))
    for what, owner, _bb, c in items:
        if what == "legend" or what.startswith("text "):
            continue  # drawn inside their own axes by design
        for ax, abox in boxes:
            if owner is not None and (ax is owner or ax in owner._twinned_axes.get_siblings(owner)):
                continue
            shrunk = abox.padded(-tol_px)
            rect = _corners(shrunk, 0.0)
            if shrunk.width > 0 and shrunk.height > 0 and _overlap(c, rect, tol_px):
                problems.append(f"runs into another axes: {what}")
                break
    return problems
