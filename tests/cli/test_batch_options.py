"""CLI helpers of ``inertialab batch``: --tolerance rules and --inputs globs."""

import pytest

from inertialab.cli.batch import expand_inputs, parse_tolerance
from inertialab.errors import InputError
from inertialab.workflows.batch import Check


def test_parse_tolerance():
    cs = parse_tolerance(["adev_1s<=0.01,abs(bx)<=0.05", "kx=0.99..1.01", "tau_min_s>=10"])
    assert cs == (Check("adev_1s", hi=0.01), Check("bx", hi=0.05, abs=True),
                  Check("kx", 0.99, 1.01), Check("tau_min_s", lo=10.0))
    assert cs[1].passes(-0.04) and not cs[1].passes(0.06) and not cs[0].passes(float("nan"))
    assert [c.text() for c in cs] == ["adev_1s<=0.01", "abs(bx)<=0.05", "kx=0.99..1.01",
                                      "tau_min_s>=10"]
    for bad in ("kx", "kx<=abc", "kx=2..1"):
        with pytest.raises(InputError, match="tolerance"):
            parse_tolerance(bad)


def test_expand_inputs(tmp_path):
    for name in ("b.csv", "a.csv", "a.meta.json"):
        (tmp_path / name).write_text("x")
    assert [p.name for p in expand_inputs(str(tmp_path / "*"))] == ["a.csv", "b.csv"]
    with pytest.raises(InputError, match="matches no file"):
        expand_inputs(str(tmp_path / "*.parquet"))

