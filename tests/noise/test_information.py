"""Whittle Cramér–Rao bounds (noise.information) against analytic truth and against the
exact Gaussian Fisher information of the differenced record."""


import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.information import (
    exact_information,
    k_bound,
    preset_k_bound,
    whittle_information,
)
from inertialab.sim.mems_presets import preset


def test_white_noise_information_is_one_per_fourier_frequency():
    # each periodogram ordinate is exponential with mean sw2: the information on log sw2
    # is 1 per ordinate, n/2 - 1 ordinates
    names, info = whittle_information(4096, 2.5)
    assert names == ["log_sw2"]
    assert info[0, 0] == pytest.approx(4096 // 2 - 1, rel=1e-12)


def test_block_sum_equals_one_pass(monkeypatch):
    import inertialab.noise.information as inf

    args = (10_000, 1.0, [(0.5, 30.0)], 1e-4)
    _, one = whittle_information(*args)
    monkeypatch.setattr(inf, "BLOCK", 777)
    _, blocks = whittle_information(*args)
    np.testing.assert_allclose(blocks, one, rtol=1e-11)


def test_exact_information_of_a_scaled_covariance_is_half_the_length():
    # white noise alone: the covariance of the differences is sw2 times a fixed matrix, so
    # the information on log sw2 is tr(I)/2 = n/2 exactly
    names, info = exact_information(300, 2.5)
    assert names == ["log_sw2"] and info[0, 0] == pytest.approx(150.0, rel=1e-10)
    with pytest.raises(InputError, match="exact information"):
        exact_information(10_000, 1.0)


def test_gauss_markov_information_time_and_frequency_domain_agree():
    # the two analytic derivatives (d/dlog s2, d/dlog tc of the Toeplitz covariance and
    # of the spectrum) give the same information on white, s2 and tc: measured within
    # 1.1 % at n = 1024 (0.5 % at 2048); the random walk's entry converges more slowly
    # (Whittle the smaller, so its bound the larger: 2.1x at 1024, 1.3x at 2048)
    _, e = exact_information(1024, 1.0, [(1.0, 20.0)], 1e-3)
    _, w = whittle_information(1024, 1.0, [(1.0, 20.0)], 1e-3)
    np.testing.assert_allclose(np.diag(e)[:3], np.diag(w)[:3], rtol=0.02)
    assert e[3, 3] > w[3, 3]


@pytest.mark.parametrize("gm, sr2, tol_known, tol_free", [
    ((), 1e-3, 0.03, 0.03),
    ((), 1e-2, 0.03, 0.03),
    (((0.05, 50.0),), 1e-3, 0.06, 0.2),
])
def test_whittle_bound_against_exact_gaussian_information(gm, sr2, tol_known, tol_free):
    # measured at n = 2048: 0.5-1.7 % apart (white + RW), 4 % (known) and 14 % (free) with
    # one GM (1024: 3.5 % and 8.5 %, so the gap closes with n); the
    # Whittle bound is the larger (conservative)
    n, sw2 = 2048, 1.0
    e = k_bound(n, sw2, gm, sr2, exact=True)
    b = k_bound(n, sw2, gm, sr2)
    known, free = e.known, e.free
    assert b.known == pytest.approx(known, rel=tol_known)
    assert b.free == pytest.approx(free, rel=tol_free)
    assert b.known >= 0.99 * known and b.free >= 0.99 * free


def test_preset_bound_falls_with_record_length():
    p = preset("accel-200hz")
    b10, b40 = preset_k_bound(p, 10.0, rate_hz=20.0), preset_k_bound(p, 40.0, rate_hz=20.0)
    # four times the record: about half the sd (the random walk's information grows ~n)
    assert 0.4 < b40.known / b10.known < 0.6
    assert b40.free < b10.free
    assert b10.free_median_err == pytest.approx(0.6744897501960817 * b10.free)


def test_bad_input_named():
    with pytest.raises(InputError, match="at least 8 samples"):
        whittle_information(4, 1.0)
    with pytest.raises(InputError, match="random walk"):
        k_bound(100, 1.0)
    with pytest.raises(InputError, match="Gauss-Markov"):
        whittle_information(100, 1.0, [(1.0, -2.0)])


def test_bound_of_a_fitted_model_equals_the_preset_bound_for_its_truth():
    # a GMWM-style model holding the preset's own processes (and a drift, which the bound
    # leaves out) gives the preset's bound
    from inertialab.noise.gmwm import Process
    from inertialab.noise.information import processes_k_bound

    p = preset("accel-200hz")
    fs, hours = 20.0, 10.0
    tau0, n = 1 / fs, int(hours * 3600 * fs)
    procs = [Process("WN", {"sigma2": p.n_white**2 * fs + p.lsb**2 / 12}),
             Process("RW", {"gamma2": p.k_rw**2 / fs}), Process("DR", {"omega": 1e-9})]
    procs += [Process("GM", {"s2": s * s, "tc_s": tc}) for s, tc in p.gm]
    want = preset_k_bound(p, hours, rate_hz=fs)
    got = processes_k_bound(procs, tau0, n)
    assert got.known == pytest.approx(want.known, rel=1e-12)
    assert got.free == pytest.approx(want.free, rel=1e-12)
    with pytest.raises(InputError, match="no random walk"):
        processes_k_bound(procs[:1], tau0, n)


def test_whittle_sum_on_a_grid_matches_the_full_sum():
    # above SUM_EXACT Fourier indices the Whittle sum is integrated on a log grid: the
    # whole information matrix (white, a fast and a slow GM, random walk) within 1e-4
    import inertialab.noise.information as info_mod

    n = 2**22
    gm = [(0.02, 5.0), (0.01, 2000.0)]
    _, fast = info_mod.whittle_information(n, 1.0, gm, 1e-8)
    old = info_mod.SUM_EXACT
    try:
        info_mod.SUM_EXACT = n
        _, full = info_mod.whittle_information(n, 1.0, gm, 1e-8)
    finally:
        info_mod.SUM_EXACT = old
    np.testing.assert_allclose(fast, full, rtol=1e-4, atol=1e-4 * np.abs(full).max())
