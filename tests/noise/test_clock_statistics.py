"""MTOTDEV, TTOTDEV, HTOTDEV, Theo1/TheoBR/TheoH, MTIE, TIE rms: published NBS14
values, allantools to 1e-10, brute-force definitions."""

from pathlib import Path

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.statistics import allan as A
from inertialab.noise.statistics.theo import theo1, theo1_variance, theobr, theoh
from inertialab.noise.statistics.tie import mtie, tierms
from inertialab.noise.statistics.total import htotdev, mtotdev, ttotdev

DATA = Path(__file__).resolve().parents[1] / "data"
NBS14_Y = np.array([892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0])
NBS14_X = np.array([0.0, 103.11111, 123.22222, 157.33333, 166.44444, 48.55555, -96.33333,
                    -2.22222, 111.88889, 0.0])
FUNCS = {"adev": A.adev, "oadev": A.oadev, "mdev": A.mdev, "totdev": A.totdev,
         "hdev": A.hdev, "ohdev": A.ohdev, "tdev": A.tdev, "mtotdev": mtotdev,
         "ttotdev": ttotdev, "htotdev": htotdev}


def _nbs14_table():
    lines = [ln for ln in (DATA / "nbs14.csv").read_text().splitlines()
             if ln and not ln.startswith("#")]
    rows = [ln.split(",") for ln in lines[1:]]
    return {r[0]: (float(r[1]), float(r[2]), r[3]) for r in rows}


@pytest.mark.parametrize("stat", sorted(FUNCS))
@pytest.mark.parametrize("source", ["frequency", "phase"])
def test_nbs14_published_values(stat, source):
    t1, t2, bias = _nbs14_table()[stat]
    data, inp = (NBS14_Y, "rate") if source == "frequency" else (NBS14_X, "angle")
    kw = {"bias_correction": True} if bias == "wfm" else {}
    r = FUNCS[stat](data, rate_hz=1.0, taus=[1.0, 2.0], input=inp, alpha=0, **kw)
    # 7 significant digits published (the phase set itself has 5 decimals)
    np.testing.assert_allclose(r.dev, [t1, t2], rtol=2e-6)


def test_nbs14_mtot_without_bias_matches_stable32():
    r = mtotdev(NBS14_Y, rate_hz=1.0, taus=[1.0, 2.0], alpha=0)
    np.testing.assert_allclose(r.dev, [64.509, 64.794], rtol=1e-4)
    assert np.all(r.bias == 1.0)
    rb = mtotdev(NBS14_Y, rate_hz=1.0, taus=[1.0, 2.0], alpha=0, bias_correction=True)
    np.testing.assert_allclose(rb.bias, [0.73, 0.73])


def _series(n=400, seed=3):
    rng = np.random.default_rng(seed)
    y = rng.standard_normal(n) + np.cumsum(0.05 * rng.standard_normal(n)) + 3.0
    return y, np.concatenate(([0.0], np.cumsum(y - y.mean()) * 0.5))


@pytest.mark.parametrize("name", ["mtotdev", "ttotdev", "htotdev", "mtie", "tierms"])
@pytest.mark.parametrize("kind", ["freq", "phase"])
def test_allantools_agreement(name, kind):
    at = pytest.importorskip("allantools")
    y, x = _series()
    ours = {"mtotdev": mtotdev, "ttotdev": ttotdev, "htotdev": htotdev, "mtie": mtie,
            "tierms": tierms}[name]
    data, inp = (y, "rate") if kind == "freq" else (x, "angle")
    r = ours(data, rate_hz=2.0, taus="octave", input=inp)
    t, dev, _, n = getattr(at, name)(data, rate=2.0, data_type=kind, taus=r.taus_s)
    np.testing.assert_allclose(t, r.taus_s)
    np.testing.assert_allclose(r.dev, dev, rtol=1e-10, atol=0)


def test_theo1_allantools_and_definition():
    at = pytest.importorskip("allantools")
    _, x = _series(300)
    r = theo1(x, rate_hz=2.0, taus="octave", input="angle")
    assert np.all(r.m % 2 == 0) and np.allclose(r.taus_s, 0.75 * r.m / 2.0)
    # allantools reports tau = m tau0 for the same m
    _, dev, _, _ = at.theo1(x, rate=2.0, data_type="phase", taus=r.m / 2.0)
    np.testing.assert_allclose(r.dev, dev, rtol=1e-10)
    # brute force of SP 1065 eq. 30 at m = 6
    m, N, tau0 = 6, x.size, 0.5
    s = sum((x[i] - x[i - d + m // 2] + x[i + m] - x[i + d + m // 2]) ** 2 / (m / 2 - d)
            for i in range(N - m) for d in range(m // 2))
    assert theo1_variance(x, m, tau0) == pytest.approx(s / (0.75 * (N - m) * (m * tau0) ** 2),
                                                       rel=1e-12)
    with pytest.raises(InputError, match="even"):
        theo1_variance(x, 5, tau0)


def test_theobr_and_theoh_on_white_fm():
    # white FM: Avar/Theo1 = 1 in expectation, so TheoBR ~ Theo1 ~ OADEV at the same tau
    y = np.random.default_rng(7).standard_normal(4000)
    br = theobr(y, rate_hz=1.0, taus=[30.0, 120.0, 480.0])
    a = A.oadev(y, rate_hz=1.0, taus=br.taus_s, alpha=0)
    np.testing.assert_allclose(br.dev, a.dev, rtol=0.15)
    np.testing.assert_allclose(br.dev, 1 / np.sqrt(br.taus_s), rtol=0.15)
    h = theoh(y, rate_hz=1.0, taus="octave")
    k = h.taus_s <= 0.1 * 3999
    o = A.oadev(y, rate_hz=1.0, taus="octave")
    short = h.taus_s < 256
    np.testing.assert_allclose(h.dev[short], o.dev[:short.sum()], rtol=1e-12)
    assert h.taus_s[-1] > 0.35 * 3999 and k.any()  # Theo1 reaches 0.75 (N - 1) tau0
    assert np.all(np.diff(h.taus_s) > 0)


def test_mtie_brute_force_and_units():
    rng = np.random.default_rng(2)
    x = np.cumsum(rng.standard_normal(200)) * 1e-9  # phase in s
    r = mtie(x, rate_hz=1.0, taus=[1.0, 3.0, 17.0], input="angle")
    for m, v in zip(r.m, r.dev):
        brute = max(x[i:i + m + 1].max() - x[i:i + m + 1].min() for i in range(x.size - m))
        assert v == brute
    assert np.all(np.isnan(r.ci_low)) and np.all(r.n_terms == x.size - r.m)
    t = tierms(x, rate_hz=1.0, taus=[5.0], input="angle")
    assert t.dev[0] == pytest.approx(np.sqrt(np.mean((x[5:] - x[:-5]) ** 2)), rel=1e-12)


def test_intervals_and_edf_present():
    y, _ = _series(600)
    r = mtotdev(y, rate_hz=1.0, taus="octave")
    assert r.edf_method.startswith("sp1065-table8") and np.all(r.ci_low < r.dev)
    assert np.all(r.dev < r.ci_high)
    h = htotdev(y, rate_hz=1.0, taus="octave")
    assert np.all(np.isfinite(h.edf)) and np.all(h.ci_low < h.dev)


def test_family_dispatch_and_totdev_bias():
    from inertialab.noise.statistics.family import ALL_STATISTICS, compute

    y, x = _series(800)
    plain = compute("totdev", y, rate_hz=1.0, taus="octave", alpha=-2)
    corr = compute("totdev", y, rate_hz=1.0, taus="octave", alpha=-2, bias_correction=True)
    T = 800.0
    np.testing.assert_allclose(corr.dev, plain.dev / np.sqrt(1 - 0.750 * plain.taus_s / T),
                               rtol=1e-12)
    wfm = compute("totdev", y, rate_hz=1.0, taus="octave", alpha=0, bias_correction=True)
    np.testing.assert_allclose(wfm.dev, plain.dev, rtol=1e-12)  # a = 0 for white FM
    for s in ALL_STATISTICS:
        r = compute(s, x, rate_hz=2.0, taus="octave", input="angle")
        assert r.statistic == s and np.all(np.isfinite(r.dev)) and np.all(r.dev > 0)
    with pytest.raises(InputError, match="unknown statistic"):
        compute("xdev", y, rate_hz=1.0)
