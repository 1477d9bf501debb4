"""Batch rules and the unit option are checked before any unit is read: a bound that is
not a finite number and an empty unit entry are one line naming the option."""

import pytest

from inertialab.errors import InputError
from inertialab.io.mapping import parse_unit_option
from inertialab.workflows.batch_run import parse_tolerance


@pytest.mark.parametrize("rule", ["adev_1s<=nan", "adev_1s>=-inf", "kx=0..inf",
                                  "abs(bx)<=NaN", "kx=nan..1"])
def test_non_finite_bounds_are_refused(rule):
    with pytest.raises(InputError, match="'tolerance'.*finite"):
        parse_tolerance(rule)


def test_finite_rules_parse():
    (a, b) = parse_tolerance("adev_1s<=0.01,kx=0.99..1.01")
    assert (a.hi, b.lo, b.hi) == (0.01, 0.99, 1.01)
    assert not a.passes(float("nan")) and a.passes(0.005)


@pytest.mark.parametrize("text", [",,", "dps,,", ",g", "gx=dps,,ax=g"])
def test_empty_unit_entries_are_refused(text):
    with pytest.raises(InputError, match="'unit' has an empty entry"):
        parse_unit_option(text)


def test_unit_option_forms_still_parse():
    assert parse_unit_option("g,dps") == "g,dps"
    assert parse_unit_option("gx=dps,ax=g") == {"gx": "dps", "ax": "g"}
    assert parse_unit_option("  ") is None
