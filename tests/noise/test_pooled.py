"""Pooling logs against simulated truth: logs of one white + random-walk truth pool
into one curve whose EDFs add and whose fit finds the truth; logs of two truths differ
beyond sampling; the between-log spread beyond sampling is estimated and widens an
interval on each side; the leave-one-log-out score prefers the true model."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from inertialab.noise.statistics.allan import oadev
from inertialab.noise.terms.fit import fit_noise_terms
from inertialab.noise.terms.pooled import (
    QN_SPLIT_S,
    between_var,
    cv_score,
    homogeneity,
    next_log_var,
    pool_curves,
    widen_term,
)

FS = 100.0


def _log(seed, n_white=0.01, k=0.0, n=200_000):
    rng = np.random.default_rng(seed)
    y = n_white * math.sqrt(FS) * rng.standard_normal(n)
    if k:
        y += np.cumsum(k / math.sqrt(FS) * rng.standard_normal(n))
    return oadev(y, rate_hz=FS, taus="octave")


def test_logs_of_one_truth_pool_into_one_curve_and_are_near_stationary():
    curves = [_log(s) for s in range(3)]
    p = pool_curves(curves, [FS] * 3)
    np.testing.assert_allclose(p.edf[:5], sum(c.edf[:5] for c in curves), rtol=1e-9)
    terms = fit_noise_terms(p, unit="dps", kind="gyro", rate_hz=FS)
    n_true = 0.01 * 60  # deg/sqrt(h) from 0.01 deg/s/sqrt(Hz)
    assert terms.N.ci[0] <= n_true <= terms.N.ci[1]
    h = homogeneity(curves, [FS] * 3)
    assert h["verdict"] == "near-stationary" and h["dof"] == 2


def test_logs_of_two_truths_differ_beyond_sampling():
    curves = [_log(0), _log(1), _log(2, n_white=0.013)]
    h = homogeneity(curves, [FS] * 3)
    assert h["verdict"] == "differ beyond sampling" and h["p_value"] < 1e-3


def test_a_log_of_another_rate_joins_only_past_the_split():
    a = _log(0)
    rng = np.random.default_rng(5)
    b = oadev(0.02 * math.sqrt(200.0) * rng.standard_normal(400_000), rate_hz=200.0,
              taus="octave")
    p = pool_curves([a, b], [FS, 200.0])
    short = p.taus_s < QN_SPLIT_S
    np.testing.assert_allclose(p.dev[short], a.dev[: short.sum()], rtol=1e-12)
    assert np.all(p.dev[~short][:3] > a.dev[~short][:3])  # the noisier log joined


def test_between_var_is_the_spread_beyond_sampling_shrunk_to_the_prior():
    rng = np.random.default_rng(1)
    true_b, samp = 0.04, 0.01
    vals = rng.normal(0, math.sqrt(true_b + samp), 4000)
    got = between_var(vals, np.full(vals.size, samp))
    assert got == pytest.approx(true_b, rel=0.1)
    assert between_var([0.0], [0.01], prior=0.3) == 0.3
    # two logs with equal values: (1 * 0 + 2 * prior) / 3
    assert between_var([1.0, 1.0], [0.0, 0.0], prior=0.3) == pytest.approx(0.2)


def test_next_log_var_is_students_prediction_interval_for_a_new_log():
    """Three logs of a population whose log quantity has between-log sd 0.3 (no
    sampling): the pooled mean +- z sqrt(next_log_var) covers a fourth log's value on
    95 % of draws (Student's prediction interval is exact for normal draws); the former
    rule (the spread shrunk toward a prior of none, times 1 + 1/n, with z) covers less."""
    from scipy.special import ndtri

    rng = np.random.default_rng(3)
    z = float(ndtri(0.975))
    draws = rng.normal(0.0, 0.3, size=(20000, 4))
    hit_t, hit_old = 0, 0
    for row in draws:
        mean = row[:3].mean()
        v = next_log_var(row[:3], np.zeros(3))
        old = between_var(row[:3], np.zeros(3)) * (1 + 1 / 3)
        hit_t += abs(row[3] - mean) <= z * math.sqrt(v)
        hit_old += abs(row[3] - mean) <= z * math.sqrt(old)
    assert hit_t / draws.shape[0] == pytest.approx(0.95, abs=0.006)
    assert hit_old / draws.shape[0] < 0.85
    # a measured spread is never pulled below the prior's floor, nor down toward it
    assert next_log_var([0.0, 0.0, 0.0], np.zeros(3), prior=0.1) > 0.1 * 4 / 3
    assert next_log_var([0.0], [0.0], prior=0.1) == pytest.approx(0.2)


def test_widen_term_adds_the_spread_to_each_side_and_to_a_bound():
    t = SimpleNamespace(value=1.0, ci=(0.5, 4.0), significant=True, upper_bound=math.nan)
    import dataclasses

    @dataclasses.dataclass(frozen=True)
    class T:
        value: float
        ci: tuple
        significant: bool
        upper_bound: float

    w = widen_term(T(t.value, t.ci, True, math.nan), 0.1, z=2.0)
    assert math.log(w.ci[1]) == pytest.approx(math.sqrt(math.log(4.0) ** 2 + 0.4))
    assert -math.log(w.ci[0]) == pytest.approx(math.sqrt(math.log(2.0) ** 2 + 0.4))
    b = widen_term(T(0.5, (0.0, 2.0), False, 2.0), 0.25, z=2.0)
    assert b.ci == (0.0, pytest.approx(2.0 * math.e))


def test_leave_one_out_score_prefers_the_true_model():
    curves = [_log(s, k=0.002) for s in range(3)]
    left = curves[0]
    fit = fit_noise_terms(pool_curves(curves[1:], [FS] * 2), unit="dps", kind="gyro",
                          rate_hz=FS)
    white_only = fit_noise_terms(pool_curves(curves[1:], [FS] * 2), unit="dps", kind="gyro",
                                 rate_hz=FS, tau_range_s=(0.01, 2.0))
    s_true = cv_score(left, fit.model_dev(left.taus_s))
    s_bad = cv_score(left, white_only.model_dev(left.taus_s))
    assert s_true < 3.0 < s_bad
