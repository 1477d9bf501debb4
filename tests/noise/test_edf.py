"""EDF, chi-square intervals and noise identification."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import chi2

from inertialab.noise import allan as A
from inertialab.noise import edf as E
from inertialab.sensors.gyro import kasdin_flicker


def test_chi2_interval_matches_scipy():
    lo, hi = E.chi2_interval([2.0, 3.0], [10.0, 57.5], 0.9)
    for d, e, l, h in zip([2.0, 3.0], [10.0, 57.5], lo, hi):
        assert l == pytest.approx(d * np.sqrt(e / chi2.ppf(0.95, e)), rel=1e-14)
        assert h == pytest.approx(d * np.sqrt(e / chi2.ppf(0.05, e)), rel=1e-14)


def test_sp1065_closed_forms_known_values():
    # Hand-evaluated SP 1065 Table 5 formulas at N_x = 1001, m = 10.
    nx, m = 1001, 10
    assert E.edf_oadev_sp1065(nx, m, 2) == pytest.approx(1002 * 981 / (2 * 991))
    assert E.edf_oadev_sp1065(nx, m, 0) == pytest.approx((3 * 1000 / 20 - 2 * 999 / 1001)
                                                         * 400 / 405)
    assert E.edf_oadev_sp1065(nx, m, -1) == pytest.approx(5 * 1001**2 / (40 * 1031))
    assert E.edf_oadev_sp1065(nx, 1, -1) == pytest.approx(2 * 999**2 / (2.3 * 1001 - 4.9))
    assert E.edf_oadev_sp1065(nx, m, -2) == pytest.approx(
        999 / (10 * 998**2) * (1000**2 - 30 * 1000 + 400))
    # totvar: b T/tau - c (SP 1065 Table 7)
    assert E.edf_totdev_sp1065(nx, m, -1) == pytest.approx(1.17 * 100.1 - 0.22)


@pytest.mark.parametrize("alpha", [0, -1, -2])
@pytest.mark.parametrize("m", [4, 16, 100])
def test_gaussian_edf_near_sp1065_for_oadev(alpha, m):
    # The exact Gaussian EDF and the SP 1065 approximations are different
    # approximations of the same quantity; SP 1065 quotes its fits as good to ~10 %.
    nx = 10_001
    g = E.edf_gaussian("oadev", nx, m, alpha, nx - 2 * m)
    sp = float(E.edf_oadev_sp1065(nx, m, alpha))
    assert g == pytest.approx(sp, rel=0.10)


@pytest.mark.parametrize("stat, d, ov, mod", [("oadev", 2, True, False), ("adev", 2, False, False),
                                              ("mdev", 2, True, True), ("ohdev", 3, True, False),
                                              ("hdev", 3, False, False)])
@pytest.mark.parametrize("alpha", [2, 0, -1, -2])
@pytest.mark.parametrize("m", [4, 16, 100, 1000])
def test_gaussian_edf_agrees_with_greenhall(stat, d, ov, mod, alpha, m):
    # Independent implementation: allantools' Greenhall (2003) EDF algorithm. Both compute
    # the same Gaussian EDF; they differ by Greenhall's continuous-time approximations
    # (observed < 3 % for m >= 4), so 5 %.
    at = pytest.importorskip("allantools")
    if alpha == 0 and ov and not mod and m < 100:
        # Here allantools' Greenhall differs from both ours and SP 1065's white-FM formula
        # (which ours reproduces, see test_gaussian_edf_near_sp1065_for_oadev) by 5-13 %:
        # its continuous-time approximation at small m; the discrete value is exact.
        pytest.skip("Greenhall's small-m approximation; checked against SP 1065 instead")
    nx = 10_001
    nt = int(E._n_terms(stat, nx, np.array([m]))[0])
    ours = E.edf_gaussian(stat, nx, m, alpha, nt)
    ref = at.edf_greenhall(alpha=alpha, d=d, m=m, N=nx, overlapping=ov, modified=mod)
    assert ours == pytest.approx(ref, rel=0.05)


def test_gaussian_edf_white_fm_m1_exact():
    # For a sampled random-walk angle at m = 1 the SP 1065 white-FM formula is exact
    # in the limit; the numeric EDF reproduces it to 0.1 %.
    nx = 10_001
    assert E.edf_gaussian("oadev", nx, 1, 0, nx - 2) == pytest.approx(
        float(E.edf_oadev_sp1065(nx, 1, 0)), rel=1e-3)


def test_b1_theory():
    # SP 1065 §5.5.4: B1 = 1 for white FM (mu = -1), N/2 for RW FM (mu = 1).
    assert E.b1_theory(10, -1.0) == pytest.approx(1.0)
    assert E.b1_theory(10, 1.0) == pytest.approx(5.0)
    assert E.b1_theory(10, 0.0) == pytest.approx(10 * np.log(10) / (18 * np.log(2)))


@pytest.mark.parametrize("kind, alpha", [("white_angle", 2), ("white_rate", 0),
                                         ("flicker_rate", -1), ("rw_rate", -2)])
def test_lag1_identification(kind, alpha):
    # Power-law noises of known type; the lag-1 ACF method (>= 30 decimated points)
    # must return the type at m = 1, 2, 4 for 2^14 samples (at m = 16 flicker rate is
    # already called RW rate now and then: the method's own scatter).
    rng = np.random.default_rng(21)
    n = 2**14
    e = rng.standard_normal(n + 1)
    if kind == "white_angle":
        r = A.oadev(e, rate_hz=1.0, taus=[1, 2, 4], input="angle")
    elif kind == "white_rate":
        r = A.oadev(e, rate_hz=1.0, taus=[1, 2, 4])
    elif kind == "flicker_rate":
        r = A.oadev(kasdin_flicker(e), rate_hz=1.0, taus=[1, 2, 4])
    else:
        r = A.oadev(np.cumsum(e), rate_hz=1.0, taus=[1, 2, 4])
    assert r.alpha.tolist() == [alpha] * 3
    assert set(r.alpha_source) == {"lag1"}


def test_b1_fallback_used_with_few_points():
    rng = np.random.default_rng(5)
    r = A.oadev(rng.standard_normal(1000), rate_hz=1.0, taus=[100, 200])
    assert set(r.alpha_source) == {"b1"}
    assert set(r.alpha.tolist()) <= {2, 1, 0, -1, -2}


@pytest.mark.slow
def test_ci_coverage_white_rate():
    # Spec 001 §7 check 8: white rate noise, n = 2^14, 1000 trials (seeds 0-999), taus
    # m = 1, 64, n/16: the 68.3 % interval covers the truth in 64–73 % of trials
    # (+-3 binomial sd). The noise type is given (alpha = 0); EDF from SP 1065.
    n, trials = 2**14, 1000
    ms = [1, 64, n // 16]
    hits = np.zeros(3)
    for seed in range(trials):
        y = np.random.default_rng(seed).standard_normal(n)
        r = A.oadev(y, rate_hz=1.0, taus=ms, alpha=0)
        truth = 1.0 / np.sqrt(r.taus_s)
        hits += (r.ci_low <= truth) & (truth <= r.ci_high)
    cov = hits / trials
    assert np.all((cov >= 0.64) & (cov <= 0.73)), cov
