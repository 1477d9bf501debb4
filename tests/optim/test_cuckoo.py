"""Cuckoo search and adaptive cuckoo search (spec 002 §3.3, §3.4, §7.1 item 2, §7.2)."""

import math

import numpy as np
import pytest

from inertialab.optim.base import Target
from inertialab.optim.cuckoo import (
    adaptive_cuckoo_search,
    cuckoo_search,
    delta_factor,
    mantegna_sigma,
    mantegna_step,
    omega1,
)
from inertialab.sensors import triaxial as tx

X_TRUE = np.array([0.25, -0.35, 0.55, 1.021, 0.985, 1.012, 0.012, -0.008, 0.015])


def test_mantegna_sigma_value():
    assert math.isclose(mantegna_sigma(1.5), 0.696575, abs_tol=1e-6)  # spec 002 §3.3


def test_mantegna_steps_are_heavy_tailed_and_symmetric():
    L = mantegna_step(200_000, 0)
    # median of |L| is O(1) while the 99.9 % quantile is far larger (heavy tail); symmetric
    q = np.quantile(np.abs(L), [0.5, 0.999])
    assert q[1] / q[0] > 50
    assert abs(np.median(L)) < 0.01


def test_schedule_values_from_spec():
    # spec 002 §3.4 tables (three decimals)
    assert np.allclose(omega1([0, 0.25, 0.5, 0.75, 1]), [1.0, 0.931, 0.736, 0.444, 0.1], atol=5e-4)
    assert np.allclose(0.25 * delta_factor([0, 0.1, 0.25, 0.5, 0.75, 1]),
                       [0.25, 0.229, 0.150, 0.062, 0.050, 0.050], atol=5e-4)


def sphere_problem(n=100, seed=0):
    d = np.random.default_rng(seed).standard_normal((n, 3))
    r = 9.8 * d / np.linalg.norm(d, axis=1)[:, None]
    a = tx.forward(X_TRUE, r)
    return (lambda X: tx.objective_many(X, a, objective="scalar", ref=r)), a, r


@pytest.mark.parametrize("solver", [cuckoo_search, adaptive_cuckoo_search])
def test_recovers_sphere100_parameters(solver):
    # §7.1 item 2 (reduced to one seed here; the 30-seed run is in benchmarks/triaxial):
    # reaching J <= 1e-10 pins x to ~1e-5 (prototype <= 8e-6), so 1e-4 is the spec bound
    f, _, _ = sphere_problem()
    res = solver(f, tx.search_box("scalar"), rng=3, vectorized=True, target=Target(0.0))
    assert res.success and res.converged_at == res.nit
    assert np.max(np.abs(res.x - X_TRUE)) < 1e-4
    assert res.nfev == 25 + 2 * 25 * res.nit  # §3.9: 2N evaluations per generation
    assert res.history.shape == (res.nit + 1,)
    assert np.all(np.diff(res.history) <= 0)  # greedy: the best never gets worse


def test_scalar_and_vectorized_objectives_give_identical_runs():
    f, a, r = sphere_problem(30)
    box = tx.search_box("scalar")
    r1 = cuckoo_search(f, box, rng=5, vectorized=True, max_generations=30)
    r2 = cuckoo_search(lambda x: tx.objective_value(x, a, objective="scalar", ref=r), box, rng=5,
                       max_generations=30)
    assert np.allclose(r1.x, r2.x, rtol=0, atol=1e-12)
    assert r1.nfev == r2.nfev


def test_acs_short_run_improves_and_lowers_pa():
    # 200 generations from a box whose J is O(1): the best value falls below 1e-2 and the
    # discovery probability has followed delta(tau) below Pa = 0.25
    f, _, _ = sphere_problem(50)
    res = adaptive_cuckoo_search(f, tx.search_box("scalar"), rng=1, vectorized=True,
                                 max_generations=200)
    assert res.fun < 1e-2
    assert res.extra["pa_final"] < 0.25


def test_textbook_mask_option_runs_and_differs():
    f, _, _ = sphere_problem(30)
    box = tx.search_box("scalar")
    a = cuckoo_search(f, box, rng=2, vectorized=True, max_generations=50)
    b = cuckoo_search(f, box, rng=2, vectorized=True, max_generations=50, mask="textbook")
    assert not np.allclose(a.x, b.x)
    with pytest.raises(ValueError):
        cuckoo_search(f, box, rng=2, vectorized=True, mask="other")


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(4))
def test_cs_and_acs_recover_on_several_seeds(seed):
    # §7.1 item 2, reduced from 30 seeds (the full count runs in benchmarks/triaxial); the ACS
    # speed-up is a 30-seed statistic and is measured there, not asserted here.
    f, _, _ = sphere_problem(100, seed=10 + seed)
    box = tx.search_box("scalar")
    cs = cuckoo_search(f, box, rng=seed, vectorized=True, target=Target(0.0))
    acs = adaptive_cuckoo_search(f, box, rng=seed, vectorized=True, target=Target(0.0))
    assert cs.success and acs.success
    assert np.max(np.abs(acs.x - X_TRUE)) < 1e-4 and np.max(np.abs(cs.x - X_TRUE)) < 1e-4


@pytest.mark.parametrize("solver", [cuckoo_search, adaptive_cuckoo_search])
def test_callback_true_stops(solver):
    res = solver(lambda x: float(np.sum(x**2)), [(-1, 1)] * 2, pop_size=5, max_generations=50,
                 rng=0, callback=lambda t, x, f: t >= 3)
    assert res.nit == 3 and "callback" in res.message
