"""Drawing the report's sections in forked processes: same sections in
the same order as in one process, warnings raised again in the parent, a failing section
raises its own error."""

import warnings

import matplotlib.pyplot as plt
import pytest

from inertialab.errors import InputError
from inertialab.report import build
from inertialab.report.html import rasterise
from inertialab.report.section import Figure, Section
from inertialab.studies.base import StudyResult


def _fake_section(result):
    if result.name == "bad":
        raise InputError("bad section")
    warnings.warn(f"drawing {result.name}", UserWarning, stacklevel=1)
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.plot([0, 1], [0, float(result.title)])
    ax.set_title(result.name)
    return rasterise(Section(key=result.name, title=result.title,
                             figures=[Figure(fig, "a line", name=result.name)]))


def _results(names):
    return [StudyResult(name=n, title=str(i + 1), settings={}) for i, n in enumerate(names)]


def test_two_processes_give_the_same_sections_and_warnings(monkeypatch):
    monkeypatch.setattr(build, "section_for", _fake_section)
    results = _results(["allan", "vibration", "thermal", "drift", "dual"])
    with warnings.catch_warnings(record=True) as w1:
        warnings.simplefilter("always")
        one = build.draw_sections(results, jobs=1)
    with warnings.catch_warnings(record=True) as w2:
        warnings.simplefilter("always")
        two = build.draw_sections(results, jobs=2)
    assert [s.key for s in two] == [r.name for r in results]
    assert [f.png for s in one for f in s.figures] == [f.png for s in two for f in s.figures]
    assert sorted(str(w.message) for w in w1) == sorted(str(w.message) for w in w2)
    assert len(w2) == len(results)


def test_a_failing_section_raises_its_own_error(monkeypatch):
    monkeypatch.setattr(build, "section_for", _fake_section)
    with warnings.catch_warnings(), pytest.raises(InputError, match="bad section"):
        warnings.simplefilter("ignore")
        build.draw_sections(_results(["allan", "bad", "drift"]), jobs=2)


def test_jobs_from_argument_and_environment(monkeypatch):
    monkeypatch.setenv(build.JOBS_ENV, "1")
    assert build.report_jobs() == 1
    assert build.report_jobs(1) == 1
    monkeypatch.setenv(build.JOBS_ENV, "two")
    with pytest.raises(InputError, match=build.JOBS_ENV):
        build.report_jobs()


class _Unpicklable:
    def __reduce__(self):
        raise TypeError("cannot be sent between processes")


def test_a_section_the_pool_cannot_send_back_is_drawn_here(monkeypatch):
    def section(result):
        sec = _fake_section(result)
        sec.results = {"handle": _Unpicklable()}
        return sec

    monkeypatch.setattr(build, "section_for", section)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        secs = build.draw_sections(_results(["allan", "drift"]), jobs=2)
    assert [s.key for s in secs] == ["allan", "drift"]
    assert all(isinstance(s.results["handle"], _Unpicklable) for s in secs)
