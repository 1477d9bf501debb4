"""The first fuzz's suite, fast set (normal test run): the explicit hostile cases of
:mod:`tests.fuzz.catalogue` for every command that reads a file or writes an output, and
hypothesis-drawn garbage inputs and cells. Every case is strict: ``owner`` only records which
change fixed it; the slow set is ``tests/fuzz/test_slow.py``."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.fuzz import catalogue as cat
from tests.fuzz import second_round

CASES = cat.fast_cases()
CASES30 = second_round.fast_cases()


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_hostile_case(case, tmp_path, request):
    outcome, bad = cat.run_case(case, tmp_path / "case")
    assert not bad, f"{case.id}: {bad}"


@pytest.mark.parametrize("case", CASES30, ids=[c.id for c in CASES30])
def test_second_fuzz_case(case, tmp_path, request):
    """The second fuzz's findings (tests/fuzz/second_round.py): FIFOs and other cases that
    could block run under the watchdog; a case owned by another change is xfail."""
    second_round.check_case(case, tmp_path, request)


ROLES_WITH_OUTPUT = [r for r, (_s, _b, kind, _src) in cat._recipes().items()
                     if kind is not None and r in ("allan", "thermal apply", "triaxial apply")]


@pytest.mark.parametrize("role", ROLES_WITH_OUTPUT)
def test_hypothesis_garbage_never_half_writes(role, tmp_path_factory):
    """Random bytes spliced into a valid input: a result or one error line, and a failed
    run leaves its directory as it was."""
    src = cat._recipes()[role][3]
    raw = src.read_bytes()

    @settings(max_examples=4, deadline=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(cut=st.integers(0, len(raw)), junk=st.binary(min_size=1, max_size=64))
    def inner(cut, junk):
        case = cat._input_case("half-written", role, "hypothesis",
                               raw[:cut] + junk + raw[cut:])
        _, bad = cat.run_case(case, tmp_path_factory.mktemp("h"))
        assert not bad, bad

    inner()


@pytest.mark.parametrize("role", ["validate", "thermal apply"])
def test_hypothesis_weird_cells(role, tmp_path_factory):
    """Extreme and non-numeric cell values: never exit 1, never a non-finite output
    written by a failed run."""
    @settings(max_examples=4, deadline=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(value=st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr),
                           st.sampled_from(["1e308", "-1e308", "1e-320", "", "0x10", "1,5",
                                            "\u00e9", "9" * 400])))
    def inner(value):
        case = cat._input_case("non-finite", role, "hypothesis",
                               lambda raw: cat._cell(raw, value))
        _, bad = cat.run_case(case, tmp_path_factory.mktemp("w"))
        assert not bad, bad

    inner()
