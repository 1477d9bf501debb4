"""PSO baseline (spec 002 §3.5)."""

import numpy as np

from inertialab.optim.base import Target
from inertialab.optim.cuckoo import cuckoo_search
from inertialab.optim.pso import pso
from inertialab.sensors import triaxial as tx

X_TRUE = np.array([0.25, -0.35, 0.55, 1.021, 0.985, 1.012, 0.012, -0.008, 0.015])


def test_pso_on_sphere100_reaches_target():
    # the spec's prototype converged in 20/20 runs (~630 generations); J <= 1e-10 pins x ~1e-5
    d = np.random.default_rng(0).standard_normal((100, 3))
    r = 9.8 * d / np.linalg.norm(d, axis=1)[:, None]
    a = tx.forward(X_TRUE, r)
    res = pso(lambda X: tx.objective_many(X, a, objective="scalar", ref=r),
              tx.search_box("scalar"), rng=1, vectorized=True, target=Target(0.0))
    assert res.success
    assert np.max(np.abs(res.x - X_TRUE)) < 1e-4
    assert res.nfev == 25 * (res.nit + 1)  # §3.9: N evaluations per generation


def test_pso_shares_initial_population_with_cs():
    # common random numbers (§3.2): generation-0 best equals CS's for the same seed
    f = lambda X: np.sum((X - 0.3) ** 2, axis=1)  # noqa: E731
    box = [(-1, 1)] * 4
    p = pso(f, box, rng=7, vectorized=True, max_generations=1)
    c = cuckoo_search(f, box, rng=7, vectorized=True, max_generations=1)
    assert p.history[0] == c.history[0]


def test_pso_constant_inertia_option():
    f = lambda X: np.sum(X**2, axis=1)  # noqa: E731
    res = pso(f, [(-5, 5)] * 3, rng=0, vectorized=True, w=0.729, c1=1.49, c2=1.49,
              max_generations=300)
    assert res.fun < 1e-10  # a convex bowl: constriction-type PSO converges geometrically
