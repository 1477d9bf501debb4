"""Stationarity by segments against simulated truth: stationary MEMS logs pass and show
no between-segment spread beyond sampling; a log whose white noise doubles half-way is
"not stationary" with the spread measured at the short taus."""

import numpy as np
import pytest

from inertialab.noise.segments.stationarity import check_stationarity, excess_at
from inertialab.sim.mems_presets import simulate


@pytest.mark.parametrize("seed", [0, 1])
def test_a_stationary_log_is_stationary(seed):
    r = simulate("accel-200hz", hours=1.0, seed=seed)
    st = check_stationarity(r.y, r.rate_hz)
    assert st.verdict == "stationary" and st.p_value > 0.05
    d = st.to_dict()
    assert d["segments"] == [2, 4] and set(d) >= {"statistic", "p_value", "verdict",
                                                  "worst_tau_s"}


def test_noise_that_changes_half_way_is_not_stationary_and_its_spread_is_measured():
    rng = np.random.default_rng(7)
    fs, n = 100.0, 360_000
    y = rng.standard_normal(n)
    y[n // 2:] *= 1.5  # white noise 1.5x in the second half: AVAR 2.25x
    st = check_stationarity(y, fs)
    assert st.verdict == "not stationary" and st.p_value < 1e-6
    # halves differ by ln 2.25 in ln AVAR: their sample variance (ln 2.25)^2 / 2, the
    # quarters' (two at each level) (ln 2.25)^2 / 3; the excess is the larger, less sampling
    ex = float(excess_at(st, [1.0])[0])
    assert 0.7 * np.log(2.25) ** 2 / 2 < ex < 1.05 * np.log(2.25) ** 2 / 2


def test_white_noise_has_no_excess():
    rng = np.random.default_rng(3)
    y = rng.standard_normal(200_000)
    st = check_stationarity(y, 100.0)
    assert st.verdict == "stationary"
    assert float(np.max(excess_at(st, [0.1, 1.0, 10.0]))) < 0.01
