"""The self-contained HTML report and its ``results.json``.

One file, ``index.html``: figures embedded as PNG data URIs, inline CSS, no script and
no network reference, readable in any browser with JavaScript off. ``results.json``
carries the same numbers (each section's ``results`` plus the summary table).
"""

from __future__ import annotations

import base64
import datetime as _dt
import io
import json
import math
import struct
import zlib
from pathlib import Path

import jinja2

from inertialab import __version__
from inertialab.io.modelfile import to_jsonable
from inertialab.io.writers import atomic_write_text
from inertialab.report.section import Figure, Section, Table

#: zlib level of the PNGs: level 1 deflates ~2x faster than the default 6; with the "up"
#: row filter the files stay about the size matplotlib writes.
PNG_COMPRESS_LEVEL = 1


def _chunk(kind: bytes, data: bytes) -> bytes:
    return (struct.pack(">I", len(data)) + kind + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))


def encode_png(rgba, *, dpi: float | None = None, level: int = PNG_COMPRESS_LEVEL) -> bytes:
    """PNG bytes of an ``(h, w, 4)`` uint8 RGBA array (PNG spec, ISO/IEC 15948).

    Opaque images are written as 8-bit RGB, others as RGBA; every row uses filter type 2
    ("up": the byte-wise difference to the row above), then zlib at ``level``. ``dpi``
    goes into the pHYs chunk (pixels per metre).
    """
    import numpy as np

    a = np.asarray(rgba, dtype=np.uint8)
    if a.ndim != 3 or a.shape[2] != 4:
        raise ValueError(f"expected an (h, w, 4) RGBA array, got shape {a.shape}")
    h, w = a.shape[:2]
    px = a[..., :3] if bool((a[..., 3] == 255).all()) else a
    c = px.shape[2]
    rows = px.reshape(h, w * c)
    raw = np.empty((h, w * c + 1), dtype=np.uint8)
    raw[:, 0] = 2
    raw[0, 1:] = rows[0]
    np.subtract(rows[1:], rows[:-1], out=raw[1:, 1:])  # uint8 arithmetic wraps mod 256
    out = [b"\x89PNG\r\n\x1a\n",
           _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2 if c == 3 else 6, 0, 0, 0))]
    if dpi:
        ppm = int(round(dpi / 0.0254))
        out.append(_chunk(b"pHYs", struct.pack(">IIB", ppm, ppm, 1)))
    out.append(_chunk(b"IDAT", zlib.compress(raw.tobytes(), level)))
    out.append(_chunk(b"IEND", b""))
    return b"".join(out)


def figure_png(fig, *, dpi: int = 100) -> bytes:
    """PNG bytes of a matplotlib figure drawn once (the figure is closed afterwards).

    The layout is computed before the draw by :func:`inertialab.report.layout.fit` (no
    ``tight_layout`` pass, no ``bbox_inches="tight"``, which drew every figure twice;
    figure rendering was ~11 s of the full demo), and the Agg buffer is
    written by :func:`encode_png`. ``dpi`` is the figure's pixels per inch in the PNG.
    """
    import matplotlib.pyplot as plt
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.layout_engine import ConstrainedLayoutEngine, TightLayoutEngine

    from inertialab.report import layout

    try:
        one_pass = False
        if not isinstance(fig.get_layout_engine(), (ConstrainedLayoutEngine, TightLayoutEngine)):
            fig.set_dpi(dpi)  # measured at the dpi of the PNG
            one_pass = layout.fit(fig)
        if one_pass and isinstance(fig.canvas, FigureCanvasAgg) and fig.dpi == dpi:
            fig.canvas.draw()
            return encode_png(fig.canvas.buffer_rgba(), dpi=dpi)
        # no one-pass layout (no single grid, or labels longer than the figure): the
        # canvas grows to what was drawn, as before
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight",
                    pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
        return buf.getvalue()
    finally:
        plt.close(fig)


def _png_size(data: bytes) -> tuple[int, int]:
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    w, h = struct.unpack(">II", data[16:24])
    return int(w), int(h)


def _cell(v, fmt: str) -> str:
    if v is None:
        return "–"
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if not math.isfinite(v) else format(v, fmt)
    try:
        import numpy as np

        if isinstance(v, np.integer):
            return str(int(v))
        if isinstance(v, np.floating):
            return _cell(float(v), fmt)
    except ImportError:  # pragma: no cover
        pass
    return str(v)


def _render_table(t: Table) -> dict:
    return {"title": t.title, "columns": [str(c) for c in t.columns],
            "rows": [[_cell(c, t.fmt) for c in r] for r in t.rows], "note": t.note}


def rasterise(section: Section) -> Section:
    """Turn the section's matplotlib figures into PNG bytes now and close them, so a report
    of many studies never holds all their figures open at once."""
    for f in section.figures:
        if f.png is None and f.figure is not None:
            f.png = figure_png(f.figure)
            f.figure = None
    return section


def _render_figure(f: Figure) -> dict:
    data = f.png if f.png is not None else figure_png(f.figure)
    w, h = _png_size(data)
    return {"data": base64.b64encode(data).decode("ascii"), "caption": f.caption,
            "width": w, "height": h}


def _unit_cell(unit) -> str:
    """A unit as the report shows it: a dimensionless ratio or count ("1", or nothing)
    is shown as "–", never as "1"."""
    text = "" if unit is None else str(unit)
    return "–" if text in ("", "1") else text


def render_report(sections: list[Section], out_dir, *, title: str = "inertialab report",
                  summary: list[list] | None = None, notes: list[str] | None = None,
                  quick: bool = False, extra: dict | None = None) -> dict[str, Path]:
    """Write ``index.html`` and ``results.json`` into ``out_dir``.

    Parameters
    ----------
    sections : list of Section
    summary : rows ``[study, figure, ours, paper, unit]`` of the headline table
    notes : short lines under the summary (timings, warnings)
    extra : more JSON-ready data for results.json (e.g. wall times)
    """
    out = Path(out_dir)
    env = jinja2.Environment(
        loader=jinja2.PackageLoader("inertialab.report", "templates"),
        autoescape=jinja2.select_autoescape(["html", "j2"]),
        undefined=jinja2.StrictUndefined,
    )
    tpl = env.get_template("report.html.j2")
    created = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    rendered = []
    for s in sections:
        rendered.append({
            "key": s.key, "title": s.title, "paragraphs": s.paragraphs,
            "tables": [_render_table(t) for t in s.tables],
            "figures": [_render_figure(f) for f in s.figures],
            "settings": json.dumps(to_jsonable(s.settings), sort_keys=True) if s.settings else "",
        })
    summary_rows = [[_cell(c, ".4g") for c in r[:-1]] + [_unit_cell(r[-1])] if r else []
                    for r in (summary or [])]
    html = tpl.render(title=title, version=__version__, created=created, sections=rendered,
                      summary=summary_rows, notes=notes or [], quick=quick)
    results = {
        "inertialab_version": __version__,
        "created_utc": created,
        "quick": quick,
        "summary": to_jsonable(summary or []),
        "studies": {s.key: to_jsonable({"title": s.title, "settings": s.settings,
                                         "results": s.results}) for s in sections},
    }
    if extra:
        results.update(to_jsonable(extra))
    index = atomic_write_text(out / "index.html", html)
    rj = atomic_write_text(out / "results.json", json.dumps(results, indent=2, allow_nan=False) + "\n")
    return {"index": index, "results": rj}
