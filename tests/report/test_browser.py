"""The report renders in a real browser (Debian's chromium, headless, no Python driver):
the page loads without console errors, every figure decodes with a non-zero size, and a
screenshot is produced. Skips (with the reason) where chromium is not installed."""

import re
import shutil
import subprocess

import matplotlib.pyplot as plt
import numpy as np
import pytest

from inertialab.report.html import render_report
from inertialab.report.section import Figure, Section, Table

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars"]

# Appended to a *test copy* of the report only (the report itself has no script): after
# load it writes each image's decoded size into the DOM, which --dump-dom returns.
PROBE = """<script>
window.addEventListener('load', function () {
  var out = [];
  document.querySelectorAll('img').forEach(function (im) {
    out.push(im.naturalWidth + 'x' + im.naturalHeight + ':' + im.complete);
  });
  var d = document.createElement('pre'); d.id = 'probe'; d.textContent = out.join(';');
  document.body.appendChild(d);
});
</script>"""


def _chromium(args, tmp_path, timeout=90):
    profile = tmp_path / "profile"
    return subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", *args],
                          capture_output=True, text=True, timeout=timeout)


def check_report_in_browser(index, tmp_path):
    """Load ``index`` in chromium; return (image sizes, console errors, screenshot path)."""
    html = index.read_text()
    probe_page = tmp_path / "probe.html"
    probe_page.write_text(html.replace("</body>", PROBE + "</body>"))
    res = _chromium(["--virtual-time-budget=5000", "--enable-logging=stderr", "--v=0",
                     "--dump-dom", probe_page.as_uri()], tmp_path)
    m = re.search(r'<pre id="probe">([^<]*)</pre>', res.stdout)
    assert m, f"probe did not run: {res.stderr[-500:]}"
    sizes = [s for s in m.group(1).split(";") if s]
    console_errors = [ln for ln in res.stderr.splitlines()
                      if "CONSOLE" in ln and ("ERROR" in ln or "Uncaught" in ln)]
    shot = tmp_path / "shot.png"
    _chromium(["--window-size=1200,1600", f"--screenshot={shot}", index.as_uri()], tmp_path)
    return sizes, console_errors, shot


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (.ci/run installs it as root)")
def test_report_loads_in_chromium(tmp_path):
    fig, ax = plt.subplots(figsize=(5, 3))
    ax.plot(np.arange(10), np.arange(10) ** 2)
    fig2, ax2 = plt.subplots(figsize=(3, 3))
    ax2.loglog([1, 10, 100], [3, 1, 0.5])
    sec = Section(key="s", title="Study", paragraphs=["text"],
                  tables=[Table("T", ["a", "b"], [[1, 2.5]])],
                  figures=[Figure(fig, "quadratic"), Figure(fig2, "log-log")])
    paths = render_report([sec], tmp_path / "rep")
    sizes, errors, shot = check_report_in_browser(paths["index"], tmp_path)
    assert len(sizes) == 2
    for s in sizes:
        wh, complete = s.split(":")
        w, h = (int(v) for v in wh.split("x"))
        assert w > 0 and h > 0 and complete == "true"
    assert errors == []
    assert shot.exists() and shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert shot.stat().st_size > 5000


@pytest.mark.skipif(CHROMIUM is None, reason="chromium not installed (.ci/run installs it as root)")
def test_quick_demo_report_loads_in_chromium(tmp_path, quick_study):
    """The real report: every study's quick demo, rendered and loaded in chromium."""
    from inertialab.report.build import section_for
    from inertialab.studies.demo import select_studies, summary_rows

    results = [quick_study(s.name) for s in select_studies()]
    assert len(results) == 6
    sections = [section_for(r) for r in results]
    paths = render_report(sections, tmp_path / "rep", summary=summary_rows(results), quick=True)
    n_figures = sum(len(s.figures) for s in sections)
    sizes, errors, shot = check_report_in_browser(paths["index"], tmp_path)
    assert len(sizes) == n_figures >= 12
    for s in sizes:
        wh, complete = s.split(":")
        w, h = (int(v) for v in wh.split("x"))
        assert w > 0 and h > 0 and complete == "true", s
    assert errors == []
    assert shot.stat().st_size > 5000
