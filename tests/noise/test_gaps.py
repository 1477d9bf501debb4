"""Gap-resistant OADEV/ADEV/MDEV/TDEV/HDEV/OHDEV (noise.statistics.gaps): allantools
gradev, the gap-free path of every statistic, brute-force summands over gappy records,
and the frequency-data rule (no integration across a gap)."""

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.statistics.allan import adev, deviation, oadev
from inertialab.noise.statistics.gaps import count_gaps, gap_deviation


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


@pytest.mark.parametrize("stat", ["mdev", "tdev", "hdev", "ohdev"])
@pytest.mark.parametrize("inp", ["angle", "rate"])
def test_no_gaps_equals_the_core_every_statistic(stat, inp):
    # the gap-free record through the gap path equals the core (itself held to allantools)
    v = np.random.default_rng(3).standard_normal(1200)
    if inp == "angle":
        v = np.cumsum(v)
    r = gap_deviation(stat, v, rate_hz=4.0, input=inp)
    core = deviation(stat, v, rate_hz=4.0, input=inp)
    np.testing.assert_array_equal(r.m, core.m)
    np.testing.assert_allclose(r.dev, core.dev, rtol=1e-9)
    assert np.all(r.used_fraction == 1.0)
    assert np.all(np.isfinite(r.ci_low)) and np.all(r.ci_high > r.dev)


def _brute(stat, x, m, tau0):
    """Textbook summands over every start whose phase points are all finite."""
    n, out = x.size, []
    order = 3 if stat in ("hdev", "ohdev") else 2
    coef = (1, -2, 1) if order == 2 else (-1, 3, -3, 1)
    def diff(i):
        return sum(c * x[i + q * m] for q, c in enumerate(coef))
    if stat in ("mdev", "tdev"):
        for j in range(n - 3 * m + 1):
            w = x[j:j + 3 * m]
            if np.isfinite(w).all():
                out.append(sum(diff(i) for i in range(j, j + m)))
        out = np.array(out)
        var = np.mean(out ** 2) / (2 * m ** 4 * tau0 ** 2)
        return np.sqrt(var * ((m * tau0) ** 2 / 3 if stat == "tdev" else 1.0)), out.size
    stride = 1 if stat == "ohdev" else m
    for i in range(0, n - 3 * m, stride):
        d = diff(i)
        if np.isfinite(d):
            out.append(d)
    out = np.array(out)
    return np.sqrt(np.mean(out ** 2) / (6 * (m * tau0) ** 2)), out.size


@pytest.mark.parametrize("stat", ["mdev", "tdev", "hdev", "ohdev"])
def test_phase_gaps_every_statistic_match_brute_force(stat):
    x = np.cumsum(np.random.default_rng(7).standard_normal(900)) * 1e-9
    x[300:311] = np.nan
    x[640] = np.nan
    r = gap_deviation(stat, x, rate_hz=2.0, input="angle", taus=[0.5, 2.0, 8.0])
    for k, m in enumerate(r.m):
        dev, n = _brute(stat, x, int(m), 0.5)
        assert r.dev[k] == pytest.approx(dev, rel=1e-9)
        assert r.n_terms[k] == n
    assert (r.n_gaps, r.n_missing) == (2, 12)
    assert np.all(r.used_fraction < 1.0)


@pytest.mark.parametrize("stat", ["mdev", "ohdev"])
def test_frequency_gaps_every_statistic_leave_out_windows(stat):
    # frequency input: a summand is used only where all the samples it spans exist; the
    # gap-free answer equals the brute force on the phase of each gap-free window
    y = np.random.default_rng(8).standard_normal(1500)
    y[700:705] = np.nan
    r = gap_deviation(stat, y, rate_hz=1.0, input="rate", taus=[1.0, 4.0])
    mean = np.nanmean(y)
    for k, m in enumerate(int(q) for q in r.m):
        span = 3 * m if stat == "ohdev" else 3 * m - 1  # frequency samples per summand
        out = []
        for j in range(y.size - span + 1):
            w = y[j:j + span]
            if not np.isfinite(w).all():
                continue
            xw = np.concatenate(([0.0], np.cumsum(w - mean)))
            if stat == "ohdev":
                out.append(xw[3 * m] - 3 * xw[2 * m] + 3 * xw[m] - xw[0])
            else:
                out.append(sum(xw[i + 2 * m] - 2 * xw[i + m] + xw[i] for i in range(m)))
        out = np.array(out)
        ref = (np.sqrt(np.mean(out ** 2) / (6 * m * m)) if stat == "ohdev"
               else np.sqrt(np.mean(out ** 2) / (2 * m ** 4)))
        assert r.dev[k] == pytest.approx(ref, rel=1e-9)
        assert r.n_terms[k] == out.size


def test_errors():
    with pytest.raises(InputError, match="no gap-resistant form"):
        gap_deviation("totdev", np.ones(10), rate_hz=1.0)
    with pytest.raises(InputError, match="too few valid"):
        gap_deviation("oadev", np.array([1.0, np.nan, np.nan, 2.0]), rate_hz=1.0)
