"""docs/cli.md and docs/records.md are generated; they must match what the code says now,
and every example record in docs/examples loads as its kind."""

from pathlib import Path

import pytest

from inertialab.cli.docgen import cli_markdown, records_markdown
from inertialab.io import read_record

DOCS = Path(__file__).resolve().parents[2] / "docs"

EXAMPLES = {
    "gyro_log.csv": "gyro_log",
    "thermal_tumble.csv": "thermal_tumble",
    "triaxial.static.csv": "triaxial_static",
    "triaxial.raw.csv": "triaxial_raw",
    "dual_tumble.csv": "dual_tumble",
    "storage_drift.csv": "storage_drift",
    "clock_log.csv": "clock_log",
}


def test_cli_reference_is_current():
    assert (DOCS / "cli.md").read_text() == cli_markdown(), (
        "docs/cli.md is stale: run `python -m inertialab.cli.docgen`")


def test_record_reference_is_current():
    assert (DOCS / "records.md").read_text() == records_markdown(), (
        "docs/records.md is stale: run `python -m inertialab.cli.docgen`")


@pytest.mark.parametrize("name, kind", sorted(EXAMPLES.items()))
def test_example_files_load(name, kind):
    rec = read_record(DOCS / "examples" / name, kind)
    assert rec.n >= 1 and len(rec.sha256) == 64


def test_every_kind_has_an_example():
    from inertialab.io.schemas import SCHEMAS

    assert set(EXAMPLES.values()) == set(SCHEMAS)
