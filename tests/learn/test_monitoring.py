"""learn.monitoring: first-passage re-calibration, CUSUM, Hampel (spec 004 §2.2, §9)."""

from __future__ import annotations

import numpy as np

from inertialab.learn.monitoring import cusum_alarms, first_passage
from inertialab.workflows.drift import FitConfig

FAST = FitConfig(restarts=2, n_paths=50, baselines=("persistence", "ar_ls"))


def test_recalibration_first_passage_quantile():
    # deterministic ramps: path j rises by (j + 1) per step; tol 10 around 0
    paths = np.array([np.arange(1, 21) * (j + 1.0) for j in range(10)])
    k, t_star = first_passage(paths, 0.0, 10.0, quantile=0.1)
    # t* = first k with k (j+1) > 10 -> 11, 6, 4, 3, 3, 2, 2, 2, 2, 2 (10 is not > 10)
    np.testing.assert_array_equal(t_star, [11, 6, 4, 3, 3, 2, 2, 2, 2, 2])
    assert k == 2  # 10 % quantile (inverted CDF) of the ten passage times
    k, _ = first_passage(paths[:1], 0.0, 100.0)
    assert k is None  # never leaves the band within the horizon


def test_cusum_false_alarms_rare_and_step_found_fast():
    # k = 0.5, h = 5: in-control ARL of the two-sided scheme ~465, so 2000 white samples
    # give ~4 alarms on average (<= 12 is > 3 Poisson SD above); a 2-sigma step is
    # detected after ~4 samples on average (ARL1 ~ 3.4), 15 is a generous bound.
    e = np.random.default_rng(0).normal(size=2000)
    assert cusum_alarms(e).size <= 12
    # step in the last 50 of 600 samples (so the robust centre and scale barely move)
    e2 = np.random.default_rng(1).normal(size=600)
    e2[550:] += 2.0
    a = cusum_alarms(e2)
    after = a[a >= 550]
    assert after.size and after[0] - 550 <= 15
