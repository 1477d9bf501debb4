"""One table of the studies (inertialab.studies.STUDIES) feeds the command list, the study
modules the demo runs and the report's figure modules; a study module, figure module or
command group that is not in the table (or an entry without them) fails here."""

from pathlib import Path

import inertialab
from inertialab.studies import STUDIES, study_module, study_modules

SRC = Path(inertialab.__file__).parent
NAMES = [s.name for s in STUDIES]


def test_the_study_modules_are_the_table():
    from inertialab.studies.base import STUDY_ORDER, discover_studies

    assert list(STUDY_ORDER) == NAMES
    on_disk = {p.stem for p in (SRC / "studies").glob("*.py")} - {"__init__", "base", "demo"}
    assert on_disk == set(NAMES)
    assert [m.__name__ for m in study_modules()] == [f"inertialab.studies.{n}" for n in NAMES]
    assert list(discover_studies()) == NAMES
    assert all(study_module(n).STUDY.name == n for n in NAMES)


def test_the_figure_modules_are_the_table():
    from inertialab.report.build import figure_modules

    mods = figure_modules()
    assert list(mods) == NAMES + ["batch"]
    assert all(m.__name__ == f"inertialab.report.figures.{n}" for n, m in mods.items())


def test_the_command_list_is_the_table():
    from inertialab.cli.main import _GROUP_HELP, TOP_LEVEL, command_module

    groups = [s.name for s in STUDIES if s.group is not None]
    assert [n for n in TOP_LEVEL if n in NAMES] == NAMES
    assert [n for n in _GROUP_HELP if n != "simulate"] == groups
    assert all(_GROUP_HELP[s.name] == s.group for s in STUDIES if s.group)
    for n in NAMES:  # every study has its command module and its one workflow module
        assert command_module(n).__name__ == f"inertialab.cli.{n}"
        assert (SRC / "workflows" / f"{n}.py").is_file()
