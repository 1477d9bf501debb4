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
from pathlib import Path

import jinja2

from inertialab import __version__
from inertialab.io.modelfile import to_jsonable
from inertialab.io.writers import atomic_write_text
from inertialab.report.section import Figure, Section, Table


def figure_png(fig, *, dpi: int = 100) -> bytes:
    """PNG bytes of a matplotlib figure (the figure is closed afterwards).

    A figure without a layout engine gets matplotlib's "tight" engine, which lays the
    axes out inside the one draw that writes the PNG; ``bbox_inches="tight"`` (used
    before) draws every figure twice, once to measure and once to write (issue 18
    item 11: figure rendering was ~11 s of the full demo).
    """
    import matplotlib.pyplot as plt

    if fig.get_layout_engine() is None:
        fig.set_layout_engine("tight")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return buf.getvalue()


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
    summary_rows = [[_cell(c, ".4g") for c in r] for r in (summary or [])]
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
