"""PHASE.DAT-style reference tables: every statistic of the Allan family
on a 1001-point clock phase record, deviation to 1e-10 and 68.3 % interval bounds to 1e-3
of tables computed independently (allantools + the published SP 1065 EDFs; recipe and
provenance: tests/data/README.md), and the published EDF and bias formulas themselves."""

import math
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from inertialab.errors import InputError
from inertialab.noise.statistics import allan as A
from inertialab.noise.statistics import edf_clock as E
from inertialab.noise.statistics.theo import theo1
from inertialab.noise.statistics.tie import mtie, tierms
from inertialab.noise.statistics.total import htotdev, mtotdev, ttotdev

DATA = Path(__file__).resolve().parents[1] / "data"
FUNCS = {"adev": A.adev, "oadev": A.oadev, "mdev": A.mdev, "tdev": A.tdev, "hdev": A.hdev,
         "ohdev": A.ohdev, "totdev": A.totdev, "mtotdev": mtotdev, "ttotdev": ttotdev,
         "htotdev": htotdev, "theo1": theo1, "mtie": mtie, "tierms": tierms}


def _record():
    return np.loadtxt(DATA / "clock_phase_ref.dat")


def _tables():
    lines = [ln for ln in (DATA / "clock_phase_ref_tables.csv").read_text().splitlines()
             if ln and not ln.startswith("#")]
    out: dict[str, list] = {}
    for ln in lines[1:]:
        s, m, tau, dev, a, edf, lo, hi = ln.split(",")
        out.setdefault(s, []).append((int(m), float(tau), float(dev), int(a), float(edf),
                                      float(lo), float(hi)))
    return {k: np.array(v) for k, v in out.items()}


def test_record_and_tables_present():
    x = _record()
    assert x.size == 1001 and np.all(np.isfinite(x))
    assert sorted(_tables()) == sorted(FUNCS)


@pytest.mark.parametrize("stat", sorted(FUNCS))
def test_reference_table(stat):
    x = _record()
    t = _tables()[stat]
    m, tau, dev, alpha, edf, lo, hi = (t[:, k] for k in range(7))
    kw = {} if stat in ("mtie", "tierms") else {"alpha": alpha.astype(int)}
    # explicit taus in seconds (Theo1: 0.75 m tau0, as Stable32 prints them)
    r = FUNCS[stat](x, rate_hz=1.0, taus=tau, input="angle", **kw)
    np.testing.assert_array_equal(r.m, m.astype(int))
    np.testing.assert_allclose(r.taus_s, tau, rtol=1e-12)
    np.testing.assert_allclose(r.dev, dev, rtol=1e-10, atol=0)
    if stat in ("mtie", "tierms"):
        assert np.all(np.isnan(r.ci_low)) and np.all(np.isnan(r.ci_high))
        return
    np.testing.assert_allclose(r.edf, edf, rtol=1e-6)
    np.testing.assert_allclose(r.ci_low, lo, rtol=1e-3)
    np.testing.assert_allclose(r.ci_high, hi, rtol=1e-3)


def test_tables_cover_several_noise_types():
    alphas = set(np.concatenate([t[:, 3] for t in _tables().values()]).astype(int))
    assert {2, 1, 0, -1} <= alphas


# ----------------------------------------------------------------- the published formulas

@pytest.mark.parametrize("alpha", [2, 1, 0, -1, -2])
def test_mtot_edf_is_sp1065_table8_from_m16(alpha):
    at = pytest.importorskip("allantools")
    import contextlib
    import io

    for n, m in ((1001, 16), (1001, 64), (5000, 100)):
        with contextlib.redirect_stdout(io.StringIO()):
            ref = at.edf_mtotdev(n, m, alpha)
        assert E.edf_mtotdev(n, m, alpha)[0] == pytest.approx(ref, rel=1e-12)
    for n, m in ((1001, 1), (1001, 8), (5000, 15)):  # below m = 16: the MDEV EDF
        ref = at.edf_greenhall(alpha=alpha, d=2, m=m, N=n, overlapping=True, modified=True)
        assert E.edf_mtotdev(n, m, alpha)[0] == pytest.approx(ref, rel=1e-6)


def test_theo1_edf_published_values():
    # by hand from SP 1065 §5.2.15 (r = 0.75 m), N = 1253, m = 40 (r = 30):
    # FFM (2 N^2 - 1.3 N r - 3.5 r)/(N r) * r^3/(r^3 + 2.3)
    N, r = 1253, 30.0
    ffm = (2 * N * N - 1.3 * N * r - 3.5 * r) / (N * r) * r**3 / (r**3 + 2.3)
    assert E.edf_theo1(N, 40, -1)[0] == pytest.approx(ffm, rel=1e-12)
    assert ffm == pytest.approx(82.224, abs=1e-3)
    wfm = ((4.1 * N + 0.8) / r - (3.1 * N + 6.5) / N) * r**1.5 / (r**1.5 + 5.2)
    assert E.edf_theo1(N, 40, 0)[0] == pytest.approx(wfm, rel=1e-12)
    # every noise positive; the FM noises' EDF falls with m (WPM's stays near 0.86 N)
    for a in (2, 1, 0, -1, -2):
        e = E.edf_theo1(1001, [10, 100, 500], a)
        assert np.all(e > 0)
        assert a > 0 or np.all(np.diff(e) < 0)
    assert E.edf_theo1(1001, 100, 2)[0] == pytest.approx(0.86 * 1001, rel=0.1)


def test_htot_edf_switches_at_m16():
    from inertialab.noise.statistics import edf as _edf

    N = 1001
    # m >= 16, FM noise: Howe et al. (2000) (N/m)/(b0 + b1 m/N)
    assert E.edf_htotdev(N, 16, 0)[0] == pytest.approx(
        (N / 16) / (0.559 + 1.004 * 16 / N), rel=1e-12)
    assert E.edf_htotdev(N, 32, -2)[0] == pytest.approx(
        (N / 32) / (0.938 + 1.696 * 32 / N), rel=1e-12)
    # below m = 16 (default, Stable32's rule): SP 1065 Table 5, written out here
    m = 8
    wfm = (3 * (N - 1) / (2 * m) - 2 * (N - 2) / N) * 4 * m * m / (4 * m * m + 5)
    assert E.edf_htotdev(N, m, 0)[0] == pytest.approx(wfm, rel=1e-12)
    ffm1 = 2 * (N - 2) ** 2 / (2.3 * N - 4.9)  # m = 1, (N-2) squared (SP 1065 Table 5)
    assert E.edf_htotdev(N, 1, -1)[0] == pytest.approx(ffm1, rel=1e-12)
    rwfm = (N - 2) / (2 * (N - 3) ** 2) * ((N - 1) ** 2 - 6 * (N - 1) + 16)  # m = 2
    assert E.edf_htotdev(N, 2, -2)[0] == pytest.approx(rwfm, rel=1e-12)
    # phase noise at any m: Table 5 as well (WPM (N+1)(N-2m)/(2(N-m)))
    assert E.edf_htotdev(N, 64, 2)[0] == pytest.approx(
        (N + 1) * (N - 128) / (2 * (N - 64)), rel=1e-12)
    # no Table 5 row for FWFM/RRFM: the overlapping-Hadamard Greenhall EDF
    assert E.edf_htotdev(N, 8, -3)[0] == pytest.approx(
        _edf.edf_greenhall("ohdev", N, 8, -3), rel=1e-12)
    # the former rule stays available
    assert E.edf_htotdev(N, 8, 0, method="greenhall")[0] == pytest.approx(
        _edf.edf_greenhall("ohdev", N, 8, 0), rel=1e-12)
    with pytest.raises(InputError):
        E.edf_htotdev(N, 8, 0, method="exact")


# ------------------------------------------------ Stable32's chi-square (Wallin 2020)

def _as_chi2(q, nu, a1):
    """Abramowitz & Stegun 26.4.17 with the normal quantile of 26.2.22, by hand."""
    p = min(q, 1 - q)
    t = math.sqrt(math.log(1.0 / (p * p)))
    x = t - (2.30753 + a1 * t) / (1 + 0.99229 * t + 0.04481 * t * t)
    x = -x if q < 0.5 else x
    h = 2.0 / (9.0 * nu)
    return nu * (1 - h + x * math.sqrt(h)) ** 3


@pytest.mark.parametrize("nu", [101.0, 187.95, 1465.8, 1e5])
@pytest.mark.parametrize("q", [0.1585, 0.8415, 0.025, 0.975])
def test_stable32_chi2_is_the_published_approximation(nu, q):
    # above EDF 100: A&S 26.4.17/26.2.22 with Stable32's a1 = 0.27601 (A&S: 0.27061)
    assert E.chi2_stable32(q, nu)[()] == pytest.approx(_as_chi2(q, nu, 0.27601), rel=1e-13)
    assert E.chi2_stable32(q, nu, a1=0.27061)[()] == pytest.approx(
        _as_chi2(q, nu, 0.27061), rel=1e-13)
    exact = stats.chi2.ppf(q, nu)
    # the book's coefficients: within the approximation's own error of the exact value
    assert abs(E.chi2_stable32(q, nu, a1=0.27061)[()] / exact - 1) < 4e-4
    # the swapped digits: Wallin's "up to almost 1e-3 in chi2/EDF" at EDF 101
    err = abs(E.chi2_stable32(q, nu)[()] - exact) / nu
    assert err < 1e-3
    if nu == 101.0 and q in (0.1585, 0.8415):
        assert err > 5e-4


def test_stable32_chi2_exact_up_to_edf_100():
    for nu in (1.0, 2.5, 10.0, 57.3, 100.0):
        for q in (0.1585, 0.8415):
            assert E.chi2_stable32(q, nu)[()] == pytest.approx(stats.chi2.ppf(q, nu),
                                                               rel=1e-12)
    from inertialab.noise.statistics.edf import chi2_interval

    dev = np.array([1.0, 2.0, 3.0, 4.0])
    edf = np.array([3.7, 99.0, 0.0, -1.0])
    lo, hi = E.stable32_chi2_interval(dev, edf, 0.683)
    lo0, hi0 = chi2_interval(dev, edf, 0.683)
    np.testing.assert_allclose(lo[:2], lo0[:2], rtol=1e-12)
    np.testing.assert_allclose(hi[:2], hi0[:2], rtol=1e-12)
    assert np.all(np.isnan(lo[2:])) and np.all(np.isnan(hi[2:]))
    # above 100 the bounds are the published approximation's: dev sqrt(edf/chi2)
    lo, hi = E.stable32_chi2_interval(2.0, 300.0, 0.683)
    assert lo[()] == pytest.approx(2.0 * math.sqrt(300 / _as_chi2(0.8415, 300, 0.27601)))
    assert hi[()] == pytest.approx(2.0 * math.sqrt(300 / _as_chi2(0.1585, 300, 0.27601)))


def test_bias_factors_are_the_published_ones():
    assert [E.MTOT_BIAS[a] for a in (2, 1, 0, -1, -2)] == [0.94, 0.83, 0.73, 0.70, 0.69]
    # Htotvar 1 + a with a = -0.005, -0.149, -0.229, -0.283, -0.321 (Howe et al. 2000)
    for a, c in zip((0, -1, -2, -3, -4), (-0.005, -0.149, -0.229, -0.283, -0.321)):
        assert E.HTOT_BIAS[a] == pytest.approx(1 + c, abs=1e-12)
    assert E.TOTDEV_BIAS_A[-1] == pytest.approx(1 / (3 * math.log(2)), abs=5e-4)
    # Theo1: Avar/Theo1 = a + b / r^c -> 1 for white FM; WPM below 1, RWFM above
    assert E.theo1_bias(0, 100)[0] == 1.0
    assert E.theo1_bias(2, 40)[0] == pytest.approx(0.09 + 0.74 / 30**0.40, rel=1e-12)
    assert E.theo1_bias(-2, 40)[0] == pytest.approx(2.70 - 1.53 / 30**0.85, rel=1e-12)


def test_bias_corrections_applied():
    x = _record()
    for f, table in ((mtotdev, E.MTOT_BIAS), (ttotdev, E.MTOT_BIAS), (htotdev, E.HTOT_BIAS)):
        plain = f(x, rate_hz=1.0, taus=[2.0, 32.0], input="angle", alpha=-1)
        corr = f(x, rate_hz=1.0, taus=[2.0, 32.0], input="angle", alpha=-1,
                 bias_correction=True)
        np.testing.assert_allclose(corr.dev, plain.dev / math.sqrt(table[-1]), rtol=1e-12)
        np.testing.assert_allclose(corr.bias, table[-1])
    p = theo1(x, rate_hz=1.0, taus=[30.0], input="angle", alpha=-1)
    c = theo1(x, rate_hz=1.0, taus=[30.0], input="angle", alpha=-1, bias_correction=True)
    assert c.dev[0] == pytest.approx(p.dev[0] * math.sqrt(1.87 - 1.05 / 30**0.79), rel=1e-12)
    assert c.edf[0] == p.edf[0] == pytest.approx(E.edf_theo1(1001, 40, -1)[0], rel=1e-12)
