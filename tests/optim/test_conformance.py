"""Shared conformance suite for every population optimiser in inertialab.optim.

Runs over every optimiser (CS, ACS, PSO, AFSA, IAFSA); one that fails to import is a
test failure, not a skip. Checks the
shared contract of the optimisers (inertialab.optim.base): signature, result type, counting, seeding, bounds,
targets, x_init, callbacks.
"""

import importlib

import numpy as np
import pytest

from inertialab.optim.base import OptimResult, Target

CANDIDATES = [
    ("inertialab.optim.cuckoo", "cuckoo_search"),
    ("inertialab.optim.cuckoo", "adaptive_cuckoo_search"),
    ("inertialab.optim.pso", "pso"),
    ("inertialab.optim.fish_swarm", "afsa"),
    ("inertialab.optim.fish_swarm", "iafsa"),
]


def _load(mod: str, name: str):
    return getattr(importlib.import_module(mod), name)


def test_every_optimiser_imports():
    missing = []
    for mod, name in CANDIDATES:
        try:
            _load(mod, name)
        except (ImportError, AttributeError) as exc:
            missing.append(f"{mod}.{name}: {exc}")
    assert not missing, "optimisers that fail to import:\n" + "\n".join(missing)


@pytest.fixture(params=CANDIDATES, ids=[name for _, name in CANDIDATES])
def opt(request):
    """Each optimiser; an import failure errors the test instead of skipping it."""
    return _load(*request.param)
BOX = [(-2.0, 2.0), (-1.0, 3.0), (0.0, 1.0)]
SHIFT = np.array([0.5, 1.0, 0.2])


def bowl(x):
    return float(np.sum((np.asarray(x) - SHIFT) ** 2))


def test_result_type_and_counts(opt):
    calls = []

    def f(x):
        calls.append(1)
        return bowl(x)

    res = opt(f, BOX, pop_size=10, max_generations=20, rng=0)
    assert isinstance(res, OptimResult)
    assert res.nfev == len(calls)  # nfev counts evaluations actually computed
    assert res.nit == 20
    assert res.history.shape == (res.nit + 1,)
    assert np.all(np.diff(res.history) <= 1e-15)
    assert res.fun == pytest.approx(bowl(res.x))
    assert res.fun == pytest.approx(res.history[-1])


def test_same_seed_same_result(opt):
    a = opt(bowl, BOX, pop_size=10, max_generations=15, rng=42)
    b = opt(bowl, BOX, pop_size=10, max_generations=15, rng=42)
    c = opt(bowl, BOX, pop_size=10, max_generations=15, rng=43)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.history, b.history)
    assert not np.array_equal(a.history, c.history)


def test_stays_inside_bounds(opt):
    lo = np.array([b[0] for b in BOX])
    hi = np.array([b[1] for b in BOX])
    seen = []

    def f(x):
        seen.append(np.array(x))
        return -float(np.sum(x))  # optimum at the upper corner: pushes against the box

    opt(f, BOX, pop_size=10, max_generations=30, rng=1)
    S = np.array(seen)
    assert np.all(S >= lo - 1e-12) and np.all(S <= hi + 1e-12)


def test_target_stops_early_and_marks_success(opt):
    # a loose target (1e-2 on a bowl whose box diagonal^2 is ~21) every method reaches quickly
    res = opt(bowl, BOX, pop_size=15, max_generations=2000, rng=3, target=Target(0.0, tol_abs=1e-2))
    assert res.success
    assert res.converged_at == res.nit < 2000
    assert res.fun <= 1e-2


def test_x_init_shared_population(opt):
    pop = np.tile(SHIFT, (10, 1))  # everyone already at the optimum
    res = opt(bowl, BOX, pop_size=10, max_generations=2, rng=0, x_init=pop)
    assert res.history[0] == 0.0
    assert res.fun == 0.0


def test_callback_sees_every_generation_best(opt):
    seen = []

    def cb(t, x, f):
        seen.append((t, bowl(x), f))

    res = opt(bowl, BOX, pop_size=10, max_generations=5, rng=0, callback=cb)
    assert [s[0] for s in seen] == [1, 2, 3, 4, 5]
    assert all(np.isclose(fx, f) for _, fx, f in seen)
    assert np.allclose([s[2] for s in seen], res.history[1:])
