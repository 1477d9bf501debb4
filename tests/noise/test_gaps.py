"""Gap-resistant OADEV/ADEV (noise.gaps, issue 15 item 3): allantools gradev, the gap-free
path, and the frequency-data rule (no integration across a gap)."""

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.allan import adev, oadev
from inertialab.noise.gaps import count_gaps, gap_deviation


def test_no_gaps_equals_the_core():
    x = np.cumsum(np.random.default_rng(0).standard_normal(1500))
    for stat, f in (("oadev", oadev), ("adev", adev)):
        r = gap_deviation(stat, x, rate_hz=2.0, input="angle")
        np.testing.assert_allclose(r.dev, f(x, rate_hz=2.0, input="angle").dev, rtol=1e-12)
        assert np.all(r.used_fraction == 1.0) and r.n_gaps == 0


def test_phase_gaps_match_allantools_gradev():
    at = pytest.importorskip("allantools")
    x = np.cumsum(np.random.default_rng(1).standard_normal(2000))
    x[500:520] = np.nan
    x[1500] = np.nan
    r = gap_deviation("oadev", x, rate_hz=1.0, input="angle")
    t, d, _, n = at.gradev(x, rate=1.0, data_type="phase", taus=r.taus_s)
    np.testing.assert_allclose(r.dev, d, rtol=1e-10)
    np.testing.assert_array_equal(r.n_terms, n.astype(int))
    assert (r.n_gaps, r.n_missing) == (2, 21) == count_gaps(x)
    # fraction used: summands without a gap over the gap-free count
    m1 = r.m == 1
    assert r.used_fraction[m1][0] == pytest.approx(r.n_terms[m1][0] / (2000 - 2))


def test_frequency_gaps_leave_out_windows_touching_a_gap():
    y = np.random.default_rng(2).standard_normal(3000)
    yg = y.copy()
    yg[1000:1010] = np.nan
    r = gap_deviation("oadev", yg, rate_hz=1.0, input="rate", taus=[1.0, 8.0])
    # brute force at m = 8: phase differences only over gap-free windows of 2m samples
    m, out = 8, []
    mean = np.nanmean(yg)
    for i in range(3000 - 2 * m + 1):
        w = yg[i:i + 2 * m]
        if np.isfinite(w).all():
            out.append(np.sum(w[m:] - mean) - np.sum(w[:m] - mean))
    out = np.array(out)
    assert r.dev[1] == pytest.approx(np.sqrt(np.mean(out ** 2) / (2 * m * m)), rel=1e-10)
    assert r.n_terms[1] == out.size
    # the gap-free estimate stays close to the full record's (white FM)
    np.testing.assert_allclose(r.dev, oadev(y, rate_hz=1.0, taus=[1.0, 8.0]).dev, rtol=0.05)


def test_errors():
    with pytest.raises(InputError, match="no gap-resistant form"):
        gap_deviation("mdev", np.ones(10), rate_hz=1.0)
    with pytest.raises(InputError, match="too few valid"):
        gap_deviation("oadev", np.array([1.0, np.nan, np.nan, 2.0]), rate_hz=1.0)
