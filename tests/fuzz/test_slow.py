"""The first fuzz's suite, slow set (``pytest -m hostile_slow tests/fuzz``; CI runs it):
2 GB sparse inputs under the watchdog (no address-space limit), disk full and read-only outputs on
a small tmpfs (skipped with the reason where mounting is not permitted), SIGTERM/SIGINT
mid-run, two concurrent writers, a re-used output folder, names from data, a long
forecast horizon. Each case runs in a subprocess, as a user runs the CLI."""

from __future__ import annotations

import pytest

from tests.fuzz import catalogue as cat
from tests.fuzz import second_round

CASES = cat.slow_cases()
CASES30 = second_round.slow_cases()


@pytest.mark.hostile_slow
@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_hostile_slow_case(case, tmp_path, request):
    try:
        outcome, bad = cat.run_case(case, tmp_path / "case")
    except cat._Skip as exc:
        pytest.skip(str(exc))
    assert not bad, f"{case.id}: {bad}"


@pytest.mark.hostile_slow
@pytest.mark.parametrize("case", CASES30, ids=[c.id for c in CASES30])
def test_second_fuzz_slow_case(case, tmp_path, request):
    """Memory bombs, endless searches and signals of the second fuzz, each in a
    subprocess under the watchdog (2 GB resident, 60 s), no address-space limit."""
    second_round.check_case(case, tmp_path, request)
