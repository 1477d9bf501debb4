"""Virtual-lab MEMS presets: the log looks like a real MEMS log and its
true terms are what the docstring says."""

from __future__ import annotations

import math

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.gmwm.fit import avar_ar1, avar_rw
from inertialab.noise.statistics.allan import oadev
from inertialab.sim import mems_presets as MP


def _brute_avar(acov, m):
    # AVAR(m) = (Var S_m - Cov(S_m, S'_m)) / m^2 from an autocovariance function
    k = np.arange(-(m - 1), m)
    var_s = np.sum((m - np.abs(k)) * acov(np.abs(k)))
    cov = np.sum((m - np.abs(k)) * acov(np.abs(m + k)))
    return (var_s - cov) / m**2


@pytest.mark.parametrize("phi", [0.0, 0.5, 0.99, 0.99999])
@pytest.mark.parametrize("m", [1, 2, 7, 64, 1000])
def test_ar1_avar_exact(phi, m):
    s2 = 2.5
    ref = _brute_avar(lambda k: s2 * phi ** k, m)
    assert float(avar_ar1(m, phi, s2)) == pytest.approx(ref, rel=1e-7)


def test_rw_avar_exact():
    # random walk r_k = sum e: AVAR from the increments of the m-averages, by Monte Carlo
    # is slow; use the identity AVAR = E[(mean2 - mean1)^2]/2 with exact variance algebra
    m, g2 = 5, 1.7
    # mean2 - mean1 = sum_j c_j e_j with c_j = weight of increment j
    c = np.zeros(2 * m)
    for i in range(m):  # r at positions 0..2m-1, r_t = sum_{j<=t} e_j
        c[: i + 1] -= 1.0 / m
        c[: m + i + 1] += 1.0 / m
    assert float(avar_rw(m, g2)) == pytest.approx(0.5 * g2 * np.sum(c**2), rel=1e-12)


def test_presets_cover_the_issue_ranges():
    rates = {p.rate_hz for p in MP.PRESETS.values()}
    assert min(rates) >= 100 and max(rates) >= 1000
    for p in MP.PRESETS.values():
        assert len(p.gm) >= 2 and p.lpf_fraction > 0 and p.lsb > 0 and p.tempco > 0
        t = p.truth()
        assert t["Q"]["value"] == 0.0 and t["N"]["value"] > 0 and t["B"]["value"] > 0
        # the textbook reading on the noise-free curve is above the IEEE flat-region B
        tb = p.textbook_b() * (1.0 if p.kind == "gyro" else 1 / 9.80665e-6)
        assert tb > t["B"]["value"]


def test_truth_units_gyro():
    p = MP.preset("consumer-100hz")
    t = p.truth()
    # N in deg/sqrt(h): the white density 0.30 deg/sqrt(h) plus LSB^2/12 white noise
    lsb = 3600.0 / 131.0
    assert t["N"]["value"] == pytest.approx(math.sqrt(0.3**2 + (lsb**2 / 1200.0) / 3600.0))
    assert t["K"]["value"] == pytest.approx(10.0)
    assert t["R"]["value"] == pytest.approx(18.0 * 0.1)
    # B: sigma of the GM sum at its flat (maximum) point = 0.6643 B
    taus = np.geomspace(0.01, 1e6, 20000)
    assert t["B"]["value"] == pytest.approx(
        np.sqrt(p.gm_avar(taus).max()) / MP.BI_FACTOR, rel=1e-4)


def test_simulated_log_looks_like_mems_and_matches_model():
    p = MP.preset("consumer-100hz")
    run = MP.simulate("consumer-100hz", hours=2.0, seed=3)
    assert run.y.size == 720_000 and run.unit == "dph"
    # quantised to the LSB
    q = run.y / p.lsb
    assert np.allclose(q, np.round(q), atol=1e-6)
    # reproducible by seed, different across seeds
    assert np.array_equal(run.y[:1000], MP.simulate("consumer-100hz", hours=2.0, seed=3).y[:1000])
    assert not np.array_equal(run.y[:1000], MP.simulate("consumer-100hz", hours=2.0, seed=4).y[:1000])
    r = oadev(run.y, rate_hz=run.rate_hz, taus="octave")
    model = np.sqrt(p.model_avar(r.taus_s))
    # the internal filter colours the first samples: sigma(tau0) far below the white line
    assert r.dev[0] < 0.3 * model[0]
    # from ~10 samples to T/20 the log follows the exact model (few-% scatter)
    sel = (r.m >= 16) & (r.taus_s <= 7200 / 20)
    assert np.all(np.abs(r.dev[sel] / model[sel] - 1) < 0.12), r.dev[sel] / model[sel]
    assert run.temperature_c[-1] - run.temperature_c[0] == pytest.approx(0.2, rel=1e-3)
    assert set(run.record().columns) == {"t_s", "rate_dph", "temp_c"}
    assert run.meta["truth_terms"]["B"]["unit"] == "deg/h"


def test_accel_preset_runs():
    run = MP.simulate("accel-200hz", hours=0.05, seed=0)
    assert run.unit == "mps2" and run.kind == "accel"
    assert run.truth["B"]["unit"] == "ug"


def test_bad_input():
    with pytest.raises(InputError, match="unknown MEMS preset"):
        MP.simulate("nope")
    with pytest.raises(InputError, match="too short"):
        MP.simulate("consumer-100hz", hours=1e-6)


# sha256 (first 16 hex) of simulate(preset, hours=0.05, seed).y.tobytes(), recorded with the
# generator before it was rewritten to work in place (commit 087e5bb): the in-place
# generator must reproduce every earlier record bit for bit
_RECORDED = {("consumer-100hz", 0): "53aee9a2c5c35ee0", ("consumer-100hz", 7): "ab967165d8608a89",
             ("industrial-400hz", 0): "bb53690bcb9613ed", ("consumer-1khz", 7): "2177011364f91bd1",
             ("accel-200hz", 0): "c67f4c4852a82ce9"}


@pytest.mark.parametrize("name,seed", sorted(_RECORDED))
def test_same_seed_same_record_as_before(name, seed):
    import hashlib

    run = MP.simulate(name, hours=0.05, seed=seed)
    assert hashlib.sha256(run.y.tobytes()).hexdigest()[:16] == _RECORDED[(name, seed)]
    again = MP.simulate(name, hours=0.05, seed=seed)
    assert np.array_equal(run.y, again.y) and np.array_equal(run.temperature_c,
                                                             again.temperature_c)
