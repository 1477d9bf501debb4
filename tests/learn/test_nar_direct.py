"""Direct multi-step NAR (spec 004 §3.8 ablation)."""

from __future__ import annotations

import numpy as np
import pytest

from inertialab.errors import InputError, NotFittedError
from inertialab.learn.nar_direct import DirectNARForecaster


def test_direct_nets_learn_each_step_of_a_linear_map():
    # noise-free AR(1) y_t = 0.9 y_{t-1} + 0.5 from varied starts: the step-k net must learn
    # y_{T+k} = 0.9^k y_T + 0.5 (1 - 0.9^k) / 0.1 (exact truth), with no feedback
    rng = np.random.default_rng(0)
    segs = []
    for _ in range(6):
        y = [rng.uniform(-5, 10)]
        for _ in range(24):
            y.append(0.9 * y[-1] + 0.5)
        segs.append(y)
    y = np.concatenate([np.r_[s, np.nan * np.ones(2)] for s in segs])[:-2]
    m = DirectNARForecaster(horizon=5, order=1, hidden=3, restarts=3, rng=1).fit(y)
    f = m.forecast(5)
    k = np.arange(1, 6)
    truth = 0.9 ** k * y[-1] + 0.5 * (1 - 0.9 ** k) / 0.1
    np.testing.assert_allclose(f.values, truth, atol=0.05)  # range of y ~ 15
    assert np.all(f.lo95 <= f.values) and np.all(f.values <= f.hi95)
    assert m.order_ == 1 and len(m.nets_) == 5


def test_direct_reproducible_constant_and_errors():
    y = np.sin(np.arange(80) / 4.0)
    a = DirectNARForecaster(horizon=3, order=2, restarts=2, rng=5).fit(y).forecast(3)
    b = DirectNARForecaster(horizon=3, order=2, restarts=2, rng=5).fit(y).forecast(3)
    np.testing.assert_array_equal(a.values, b.values)
    c = DirectNARForecaster(horizon=3, order=2).fit(np.full(30, 2.5)).forecast(3)
    np.testing.assert_array_equal(c.values, 2.5)
    with pytest.raises(NotFittedError):
        DirectNARForecaster().forecast(3)
    m = DirectNARForecaster(horizon=3, order=2, restarts=1).fit(y)
    with pytest.raises(InputError, match="from 1 to the fitted 3"):
        m.forecast(4)
    with pytest.raises(InputError, match="too few samples"):
        DirectNARForecaster(horizon=20, order=3, restarts=1).fit(y[:25])
