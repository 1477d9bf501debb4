"""A dimensionless fractional frequency may be given as ``1``, ``ratio`` or ``frac``."""

from __future__ import annotations

import numpy as np
import pytest

from inertialab import units
from inertialab.workflows import allan as W


@pytest.mark.parametrize("alias", ["ratio", "frac", "RATIO"])
def test_ratio_aliases_are_dimensionless(alias):
    u = units.lookup(alias)
    assert u.dimension == "ratio" and u.scale == 1.0
    assert units.convert(2.5e-12, alias, "ppm") == pytest.approx(2.5e-6, rel=1e-15)
    assert units.convert(3.0, alias, "1") == 3.0


def test_clock_record_in_ratio_or_frac_equals_unit_one():
    y = np.random.default_rng(1).standard_normal(3000) * 1e-11
    ref = W.analyze(y, rate_hz=1.0, unit="1", input="rate", stats="oadev,theo1")
    for alias in ("ratio", "frac"):
        got = W.analyze(y, rate_hz=1.0, unit=alias, input="rate", stats="oadev,theo1")
        assert got.kind == "clock"
        for a, b in zip(got.results, ref.results):
            np.testing.assert_array_equal(a.dev, b.dev)
