"""Batch rules and the unit option are checked before any unit is read: a bound that is
not a finite number and an empty unit entry are one line naming the option."""

import pytest

from inertialab.errors import InputError
from inertialab.io.mapping import parse_unit_option
from inertialab.workflows.batch import parse_tolerance


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


def test_the_command_in_one_module_and_the_old_name_warns():
    """workflows/batch.py holds the fleet runner and the command's settings and calls;
    batch_run still answers, with a DeprecationWarning."""
    import importlib
    import sys
    import warnings

    from inertialab.workflows import batch

    sys.modules.pop("inertialab.workflows.batch_run", None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = importlib.import_module("inertialab.workflows.batch_run")
    assert old.run is batch.run and old.BatchConfig is batch.BatchConfig
    assert old.parse_tolerance is batch.parse_tolerance
    assert any(issubclass(w.category, DeprecationWarning) for w in caught)
