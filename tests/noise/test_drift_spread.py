"""The spread of the drift a log's segments predict on their own (noise.segments.drift_spread)
against closed forms: a log whose second half carries 3x the white noise gives the
random-effects spread of ln V over its quarters, (ln 9)^2 / 5 after the pseudo-segment
shrinkage; a stationary white log gives none; the pieces (an interval's log-variance, the
between-segment estimate) against their formulas; and allan --imu's drift interval widens
by it where the noise changes within the fitted span."""

import math

import numpy as np
import pytest
from scipy.special import ndtri, stdtrit

from inertialab.noise.segments.drift_spread import (
    prediction_log_var,
    segment_log_var,
    segment_predictions,
    spread_log_var,
)
from inertialab.noise.statistics.allan import oadev
from inertialab.noise.terms.fit import fit_noise_terms
from inertialab.noise.terms.pooled import PRIOR_WEIGHT

FS = 50.0
Z = 1.959963984540054


def _fit(y):
    dev = oadev(y, rate_hz=FS, taus="octave")
    return dev, fit_noise_terms(dev, unit="dph", kind="gyro", rate_hz=FS)


def _white(scales, n_each=12000, seed=3):
    rng = np.random.default_rng(seed)
    return np.concatenate([s * rng.standard_normal(n_each) for s in scales])


def test_an_intervals_log_variance_is_its_half_width_over_z_squared():
    s = np.array([0.3, 0.05])
    ci = {"confidence": 0.95, "low": 2.0 * np.exp(-Z * s / 2), "high": 2.0 * np.exp(Z * s / 2)}
    assert prediction_log_var(ci) == pytest.approx(s * s, rel=1e-9)
    ci0 = {"confidence": 0.95, "low": np.array([0.0]), "high": np.array([3.0])}
    assert math.isinf(prediction_log_var(ci0)[0])


def test_spread_is_the_random_effects_estimate_shrunk_toward_none():
    rows = [(np.array([0.0, 1.0]), np.array([0.1, 0.0])),
            (np.array([2.0, 1.0]), np.array([0.1, 0.0]))]
    # sample variance 2 less the mean sampling 0.1, one dof against PRIOR_WEIGHT at 0
    assert spread_log_var(rows) == pytest.approx([1.9 / (1 + PRIOR_WEIGHT), 0.0])
    # a segment whose interval reaches zero tells nothing and is left out
    rows.append((np.array([9.0, 9.0]), np.array([np.inf, np.inf])))
    assert spread_log_var(rows) == pytest.approx([1.9 / (1 + PRIOR_WEIGHT), 0.0])


def test_white_noise_tripled_in_the_second_half_gives_the_closed_form_spread():
    y = _white([1.0, 1.0, 3.0, 3.0])
    parts = segment_predictions(y, FS, _fit, (1.0, 10.0), 10.0, segments=(4,))
    assert list(parts) == [4] and len(parts[4]) == 4
    d = math.log(9.0)
    lv = np.array([r[0] for r in parts[4]])
    # at 1 s the white noise is the drift: the busy quarters' ln V is ln 9 above the calm
    assert lv[2:, 0].mean() - lv[:2, 0].mean() == pytest.approx(d, abs=0.1)
    # ln V at 0, 0, d, d: s^2 = d^2/3 over 3 dof less the segments' own sampling, shrunk
    # by 3/(3 + PRIOR_WEIGHT); at 1 s that sampling is ~0.01
    shrink = 3.0 / (3.0 + PRIOR_WEIGHT)
    samp = np.mean([r[1] for r in parts[4]], axis=0)
    got = spread_log_var(parts[4])
    assert got[0] == pytest.approx(shrink * d * d / 3.0, abs=0.08)
    assert got == pytest.approx(shrink * (np.var(lv, axis=0, ddof=1) - samp), rel=1e-9)


def test_a_stationary_white_log_has_no_spread():
    got = segment_log_var(_white([1.0, 1.0, 1.0, 1.0], seed=5), FS, _fit, (1.0, 10.0), 10.0)
    assert np.all(got < 0.02)
    assert segment_log_var(np.ones(500), FS, _fit, (1.0,), 10.0).tolist() == [0.0]


def test_a_segment_the_fit_refuses_is_left_out():
    from inertialab.errors import InputError

    calls = []

    def refusing(y):
        calls.append(y.size)
        if len(calls) == 1:
            raise InputError("no terms")
        return _fit(y)

    parts = segment_predictions(_white([1.0, 3.0]), FS, refusing, (1.0,), 10.0, segments=(2,))
    assert len(parts[2]) == 1 and spread_log_var(parts[2]).tolist() == [0.0]


def test_allan_imu_widens_the_drift_interval_where_the_noise_changes_in_the_fitted_span():
    from inertialab.workflows.imu_drift import DriftOptions
    from inertialab.workflows.imu_noise import analyse_imu

    cols = {"gx": ("gx_dph", _white([1.0, 1.0, 3.0, 3.0]), "dph")}
    res = analyse_imu(cols, rate_hz=FS, drift=DriftOptions(horizons_s=(1.0,)), warmup="0")
    extra = res.axis("gx").drift["predicted_rms_ci"]["log_sd"]["extra"][0]
    # the quarters' spread (ln 9)^2/5, with the fit's misfit (none on white noise)
    assert extra == pytest.approx(math.log(9.0) * math.sqrt(0.2), abs=0.1)


def test_a_pools_between_log_prior_is_its_logs_segment_spread():
    from inertialab.workflows.imu_drift import DriftOptions
    from inertialab.workflows.imu_pool import drift_between

    rng = np.random.default_rng(11)
    logs = [rng.standard_normal(12000), 1.2 * rng.standard_normal(12000)]
    own = [_fit(y)[1] for y in logs]
    opts = DriftOptions(horizons_s=(1.0,))
    within = [np.array([0.3]), np.array([0.1])]
    # one log: nothing to spread, the prior (the mean within-log spread) times 1 + 1/1
    one = drift_between(own[:1], [FS], [None], opts, within=within[:1])
    assert one == pytest.approx([2.0 * 0.3])
    # two logs: their ln V differ by ln 1.44 (d^2 / 2 a spread of one dof), above the
    # mean prior 0.2: the prior is the floor, times 1 + 1/2 and (t_1 / z)^2
    t1z = (stdtrit(1, 0.975) / ndtri(0.975)) ** 2
    two = drift_between(own, [FS, FS], [None, None], opts, within=within)
    assert two == pytest.approx([0.2 * 1.5 * t1z], rel=1e-9)
    # with a small prior the logs' own spread counts (less the fits' own sampling), not
    # pulled down toward the prior (shrunk, it would be about a third of it)
    low = drift_between(own, [FS, FS], [None, None], opts,
                        within=[np.array([0.001]), np.array([0.001])])[0]
    d2 = math.log(1.44) ** 2 / 2.0
    assert 0.7 * d2 * 1.5 * t1z < low <= d2 * 1.5 * t1z
