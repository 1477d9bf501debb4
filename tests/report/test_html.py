"""The HTML report is one self-contained file carrying each section's figure and table."""

import base64
import json
import re

import matplotlib.pyplot as plt
import numpy as np

from inertialab.report.html import render_report
from inertialab.report.section import Figure, Section, Table


def test_dummy_section_has_its_figure_and_table(tmp_path):
    fig, ax = plt.subplots(figsize=(4, 3))
    ax.loglog([1, 10, 100], [1.0, 0.3, 0.1])
    sec = Section(key="dummy", title="Dummy <study>", paragraphs=["What was done & why."],
                  tables=[Table("Noise terms", ["term", "value"], [["N", 0.0123456], ["B", None]])],
                  figures=[Figure(fig, "A log-log curve")], results={"N": 0.0123456},
                  settings={"seed": 7})
    paths = render_report([sec], tmp_path, summary=[["dummy", "N", 0.0123456, 0.012, "deg/sqrt(h)"]])
    html = paths["index"].read_text()
    assert "Dummy &lt;study&gt;" in html and "What was done &amp; why." in html
    assert "<td>0.01235</td>" in html and "<td>–</td>" in html
    assert 'href="#dummy"' in html
    # self-contained: no script, no external references
    assert "<script" not in html.lower()
    assert not re.search(r'(src|href)="(https?:)?//', html)
    imgs = re.findall(r'src="data:image/png;base64,([^"]+)"', html)
    assert len(imgs) == 1
    png = base64.b64decode(imgs[0])
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 1000
    res = json.loads(paths["results"].read_text())
    assert np.isclose(res["studies"]["dummy"]["results"]["N"], 0.0123456)
    assert res["studies"]["dummy"]["settings"] == {"seed": 7}
    assert res["summary"][0][1] == "N"


def test_empty_report_says_no_study(tmp_path):
    paths = render_report([], tmp_path)
    assert "No studies are registered yet" in paths["index"].read_text()


def test_summary_shows_no_1_unit_and_no_issue_jargon(tmp_path):
    sec = Section(key="d", title="D", paragraphs=["p"], tables=[], figures=[], results={},
                  settings={})
    paths = render_report([sec], tmp_path, summary=[
        ["drift", "seeds within band", "18/20", None, "1"],
        ["allan", "N", 0.0101, 0.01, "deg/sqrt(h)"]])
    html = paths["index"].read_text()
    rows = re.findall(r"<tr>(.*?)</tr>", html, flags=re.S)
    cells = [re.findall(r"<td>(.*?)</td>", r, flags=re.S) for r in rows]
    cells = [[c.strip() for c in r] for r in cells if len(r) == 5]
    assert cells[0][-1] == "–" and cells[1][-1] == "deg/sqrt(h)"
    assert json.loads(paths["results"].read_text())["summary"][0][-1] == "1"  # data kept


def test_report_figure_captions_cite_papers_not_issues():
    import inspect

    from inertialab.report.figures import allan, drift, triaxial

    for mod in (allan, drift, triaxial):
        src = inspect.getsource(mod)
        assert not re.search(r"issue \d", src), mod.__name__
        assert not re.search(r'Figure\([^)]*spec 00\d', src, flags=re.S), mod.__name__
