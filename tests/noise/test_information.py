"""Whittle Cramér–Rao bounds (noise.information) against analytic truth and against the
spread of the Whittle maximum-likelihood estimate on simulated records."""

import math

import numpy as np
import pytest
from scipy.linalg import toeplitz

from inertialab.errors import InputError
from inertialab.noise.information import k_bound, preset_k_bound, whittle_information
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


def _exact_information(n, sw2, gm, sr2):
    """Exact Gaussian Fisher information of the first-differenced record (an independent
    route: Toeplitz autocovariances, I_ab = tr(S^-1 dS_a S^-1 dS_b) / 2), same parameter
    order as whittle_information."""
    lags = np.arange(n, dtype=float)

    def ar1_diff(s2, tc):
        phi = math.exp(-1.0 / tc)
        a = s2 * phi ** np.abs(lags)
        return 2 * a - s2 * phi ** np.abs(lags - 1) - s2 * phi ** (lags + 1)

    white = np.zeros(n)
    white[:2] = [2 * sw2, -sw2]
    comps = [white]
    for s2, tc in gm:
        h = 1e-6
        comps += [ar1_diff(s2, tc), (ar1_diff(s2, tc * math.exp(h)) - ar1_diff(s2, tc)) / h]
    rw = np.zeros(n)
    rw[0] = sr2
    comps.append(rw)
    total = white + rw + sum(ar1_diff(s2, tc) for s2, tc in gm)
    inv = np.linalg.inv(toeplitz(total))
    mats = [inv @ toeplitz(c) for c in comps]
    return np.array([[0.5 * np.sum(a * b.T) for b in mats] for a in mats])


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
    exact = _exact_information(n, sw2, gm, sr2)
    b = k_bound(n, sw2, gm, sr2)
    known = 0.5 / math.sqrt(exact[-1, -1])
    free = 0.5 * math.sqrt(np.linalg.inv(exact)[-1, -1])
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
