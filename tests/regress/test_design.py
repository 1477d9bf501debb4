"""D-optimal position design (spec 003 §7.2, AC-2)."""

import numpy as np
import pytest

from inertialab.errors import UnderdeterminedError
from inertialab.regress.design import d_optimal_design, design_criteria, trig_basis


@pytest.mark.parametrize("n", [7, 8, 12, 20, 36])
def test_equally_spaced_information_is_diagonal(n):
    t = 2 * np.pi * np.arange(n) / n
    F = trig_basis(t)
    M = F.T @ F
    # standard result: F^T F = diag(n, n/2, ..., n/2) for n >= 7
    np.testing.assert_allclose(M, np.diag([n] + [n / 2] * 6), atol=1e-9)
    c = design_criteria(t)
    assert c.cond == pytest.approx(np.sqrt(2), abs=1e-9)
    assert c.log_det == pytest.approx(np.log(n) + 6 * np.log(n / 2), rel=1e-12)


def test_exchange_finds_equally_spaced_optimum_on_full_circle():
    for n in (8, 20):
        d = d_optimal_design(n)
        opt = np.log(n) + 6 * np.log(n / 2)  # upper bound attained by equal spacing
        assert d.criteria.log_det == pytest.approx(opt, abs=1e-9)


def test_restricted_range_and_unequal_noise():
    cand = np.deg2rad(np.arange(0, 181, 1.0))
    d = d_optimal_design(12, candidates=cand)
    assert d.criteria.rank == 7
    assert np.all((d.theta >= 0) & (d.theta <= np.pi))
    # a random 12-point design on the same half circle is not better (D-criterion)
    rng = np.random.default_rng(0)
    for _ in range(20):
        rnd = rng.choice(cand, 12, replace=False)
        assert design_criteria(rnd).log_det <= d.criteria.log_det + 1e-9
    # weighting the lower half more pulls points there
    w = np.where(cand < np.pi / 2, 4.0, 1.0)
    dw = d_optimal_design(12, candidates=cand, weights=w)
    assert np.sum(dw.theta < np.pi / 2) >= np.sum(d.theta < np.pi / 2)


def test_too_few_positions_rejected():
    with pytest.raises(UnderdeterminedError):
        d_optimal_design(6)
    # six equally spaced points cannot see sin 3t (identically zero there)
    t = 2 * np.pi * np.arange(6) / 6
    assert design_criteria(t).rank == 6
