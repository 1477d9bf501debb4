"""Noise identification as Stable32 does it (lag-1 ACF, B1, R(n), carried), the bias
corrections that follow from it, and Theo1's correction: simulated ground truth, the
PHASE.DAT record rebuilt from its published recipe (NIST SP 1065 §12.3, a white-FM
record by Stable32's own verdict) and allantools as an independent implementation."""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path

import numpy as np
import pytest

from inertialab.noise.statistics import identify as I
from inertialab.noise.statistics._phase import _PhaseArray
from inertialab.noise.statistics.family import compute
from inertialab.sensors.gyro import kasdin_flicker

DATA = Path(__file__).resolve().parents[1] / "data"


def _phasedat() -> np.ndarray:
    """PHASE.DAT: the phase (x0 = 0, tau0 = 1 s) of the NBS 1000-point frequency set."""
    n = np.loadtxt(DATA / "nbs1000_lcg.txt")
    return np.concatenate(([0.0], np.cumsum(n / 2147483647.0)))


def _noise(kind: str, n: int, seed: int) -> tuple[np.ndarray, str]:
    e = np.random.default_rng(seed).standard_normal(n)
    return {"wpm": (e, "angle"), "wfm": (e, "rate"), "ffm": (kasdin_flicker(e), "rate"),
            "rwfm": (np.cumsum(e), "rate")}[kind]


@pytest.mark.parametrize("kind, alpha", [("wpm", 2), ("wfm", 0), ("ffm", -1), ("rwfm", -2)])
def test_acf_recovers_simulated_types(kind, alpha):
    for seed in range(3):
        x, inp = _noise(kind, 1 << 14, seed)
        # (m <= 4: at m = 16 flicker FM is called RW FM now and then, the method's scatter)
        r = compute("oadev", x, rate_hz=1.0, taus=[1, 2, 4], input=inp)
        assert r.alpha.tolist() == [alpha] * 3, (seed, r.alpha)
        assert set(r.alpha_source) == {"acf"}


def test_b1_and_rn_on_white_pm_and_white_fm():
    # fewer than 30 decimated points: B1; where it says phase noise R(n) splits white
    # from flicker PM (white here)
    ms = [150, 200, 250, 300, 400]
    seen = set()
    for seed in range(4):
        x = np.random.default_rng(seed).standard_normal(4001)  # white PM phase
        r = I.identify_alpha(_PhaseArray(x), ms, statistic="oadev")
        for a, how in zip(r.alpha.tolist(), r.source):
            seen.add(how)
            assert how in ("b1", "b1+rn") and (how == "b1" or a == 2), (seed, r)
        w = np.cumsum(np.random.default_rng(10 + seed).standard_normal(4001))  # white FM
        r = I.identify_alpha(_PhaseArray(w), ms, statistic="oadev")
        assert np.mean(r.alpha == 0) >= 0.6 and set(r.source) <= {"b1", "b1+rn"}, r
    assert "b1+rn" in seen


def test_b1_theory_matches_allantools():
    ci = pytest.importorskip("allantools.ci")
    for n in (5, 30, 703):
        for mu in (1, 0, -1, -2):
            assert I.b1_theory(n, mu) == pytest.approx(ci.b1_theory(n, mu), rel=1e-12)


def test_lag1_acf_scaled_as_stable32():
    # r1 carries the (n - 1)/n factor: for white noise alpha = 2 - 2 delta exactly
    z = np.random.default_rng(8).standard_normal(50)
    zc = z - z.mean()
    r1 = np.dot(zc[:-1], zc[1:]) / np.dot(zc, zc) * 49 / 50
    assert r1 / (1 + r1) < 0.25
    assert I.lag1_alpha(z) == pytest.approx(2 - 2 * r1 / (1 + r1), rel=1e-12)


def test_carried_beyond_stable32_range():
    x = np.cumsum(np.random.default_rng(6).standard_normal(1001))
    src = _PhaseArray(x)
    r = I.identify_alpha(src, [64, 100, 125, 126, 200, 400], statistic="oadev")
    # OADEV: identified while N/m >= 8 (m <= 125), carried from m = 125 beyond
    assert set(r.source[:3]) <= {"b1", "b1+rn"} and r.source[3:] == ("carried",) * 3
    assert r.alpha[3:].tolist() == [r.alpha[2]] * 3
    # a run with every m beyond takes the type at the largest identifiable m (125)
    only = I.identify_alpha(src, [300], statistic="oadev")
    top = I.identify_alpha(src, [125], statistic="oadev")
    assert only.source == ("carried",) and only.alpha[0] == top.alpha[0]
    # TOTDEV identifies down to 4 points per m
    t = I.identify_alpha(src, [250, 251], statistic="totdev", n_terms=[999, 999])
    assert t.source[0] in ("b1", "b1+rn") and t.source[1] == "carried"
    # too short to identify anything: white FM assumed, reported as such
    n = I.identify_alpha(_PhaseArray(x[:7]), [1, 2], statistic="oadev")
    assert n.source == ("none", "none") and n.alpha.tolist() == [0, 0]


@pytest.mark.parametrize("stat", ["adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev"])
def test_phasedat_is_white_fm_at_every_octave(stat):
    # Stable32 prints alpha 0 at every octave m of PHASE.DAT for these statistics (m up
    # to 128; TOTDEV to 64, where its 1.60 table carries 0 to m = 128 while its all-tau
    # table and this identification say flicker PM there); the identification used
    # before called m >= 64 flicker or random-walk FM or PM
    k = 7 if stat == "totdev" else 8
    r = compute(stat, _phasedat(), rate_hz=1.0, taus=[2.0**j for j in range(k)],
                input="angle", bias_correction=True)
    assert r.alpha.tolist() == [0] * k, r.alpha
    assert r.to_dict()["bias_factor"] == [1.0] * k


def test_totdev_uncorrected_on_white_fm_record():
    # TOTDEV's correction applies to FFM/RWFM only: on the white-FM record the
    # bias-corrected default equals the plain TOTDEV (it was 13 % low at m = 93-317)
    x = _phasedat()
    taus = np.arange(93.0, 318.0, 16.0)
    a = compute("totdev", x, rate_hz=1.0, taus=taus, input="angle", bias_correction=True)
    b = compute("totdev", x, rate_hz=1.0, taus=taus, input="angle", bias_correction=False)
    assert set(a.alpha.tolist()) <= {0, 1}
    np.testing.assert_allclose(a.dev, b.dev, rtol=1e-15)
    at = pytest.importorskip("allantools")
    ref = at.totdev(x, rate=1.0, data_type="phase", taus=taus)[1]
    np.testing.assert_allclose(a.dev, ref, rtol=1e-10)


def test_bias_factor_per_tau_in_json():
    w = np.cumsum(kasdin_flicker(np.random.default_rng(2).standard_normal(1 << 12)))
    r = compute("totdev", w, rate_hz=1.0, input="angle", bias_correction=True)
    d = r.to_dict()
    assert len(d["alpha_source"]) == len(d["bias_factor"]) == len(d["m"])
    T = (r.n_samples - 1) * r.tau0_s
    for a, tau, b in zip(r.alpha, r.taus_s, d["bias_factor"]):
        want = 1.0 - {-1: 0.481, -2: 0.750}.get(int(a), 0.0) * tau / T
        assert b == pytest.approx(want, rel=1e-12)
    assert -1 in r.alpha.tolist()  # flicker FM: a correction was applied somewhere


def _theo1_direct(x, m):
    """Theo1 variance by its defining double sum (SP 1065 eq. 30), tau0 = 1."""
    N, h = x.size, m // 2
    tot = 0.0
    for i in range(N - m):
        for d in range(h):
            v = (x[i] - x[i + h - d]) + (x[i + m] - x[i + h + d])
            tot += v * v / (h - d)
    return tot / (0.75 * (N - m) * m * m)


def _kf_allantools(x, n):
    at = pytest.importorskip("allantools")
    tot = 0.0
    with contextlib.redirect_stdout(io.StringIO()):
        for i in range(n + 1):
            ma, mt = 9 + 3 * i, 12 + 4 * i
            avar = at.oadev(x, rate=1.0, data_type="phase", taus=[ma])[1][0] ** 2
            tot += avar / _theo1_direct(x, mt)
    return tot / (n + 1)


def test_theo1_stable32_correction():
    # white FM: Theo1 printed uncorrected; another type: times the data's own
    # Avar(9+3i)/Theo1(12+4i) ratio over i <= floor(N/6) - 3 (Stable32's Theo1 tables of
    # PHASE.DAT), here against allantools' oadev and Theo1's defining double sum
    x = _phasedat()[:155]  # (the last Avar term keeps 5 summands)
    kf = _kf_allantools(x, int(math.floor(x.size / 6)) - 3)
    taus = [7.5, 15.0, 30.0]
    raw = np.sqrt([_theo1_direct(x, m) for m in (10, 20, 40)])
    r0 = compute("theo1", x, rate_hz=1.0, taus=taus, input="angle", alpha=0,
                 bias_correction=True)
    np.testing.assert_allclose(r0.dev, raw, rtol=1e-10)
    r1 = compute("theo1", x, rate_hz=1.0, taus=taus, input="angle", alpha=1,
                 bias_correction=True)
    np.testing.assert_allclose(r1.dev, raw * math.sqrt(kf), rtol=1e-10)
    np.testing.assert_allclose(r1.bias, 1.0 / kf, rtol=1e-10)
    assert r1.statistic == "theo1"
    br = compute("theobr", x, rate_hz=1.0, taus=taus, input="angle")
    assert br.statistic == "theobr"


@pytest.mark.parametrize("n", [7, 100, 1023, 1024, 1025, 100_000])
@pytest.mark.parametrize("block", [1, 2, 4, 256])
def test_rn_block_phase_from_the_rate_equals_the_phase(n, block):
    """R(n) of a rate record reads the phase at every block-th point and its block sums
    from the rate in one pass; they equal those of the in-memory phase (up to rounding)."""
    from inertialab.noise.statistics._phase import _LazyPhase, _rate_to_phase

    if block > n:
        pytest.skip("block longer than the record")
    y = np.random.default_rng(n).standard_normal(n) + 3.0
    mean = float(np.mean(y))
    x = _rate_to_phase(y, 0.5, mean)
    xb, C = _LazyPhase(y, 0.5, mean).block_phase(block)
    nb = x.size // block
    C0 = np.concatenate([[0.0], np.cumsum(x[:nb * block].reshape(nb, block).sum(axis=1))])
    assert xb.shape == x[::block].shape and C.shape == C0.shape
    scale = np.max(np.abs(x)) + 1e-300
    assert np.max(np.abs(xb - x[::block])) / scale < 1e-13
    assert np.max(np.abs(C - C0)) / (np.max(np.abs(C0)) + 1e-300) < 1e-13


def test_rate_record_identified_as_its_phase_by_every_branch():
    """A rate record and its phase (the same data as frequency averages) get the same
    verdicts from the in-memory rate path (lag-1 in the octave kernel, R(n) from the rate)
    as from the general identification on the phase."""
    from inertialab.noise.statistics._phase import _rate_to_phase
    from inertialab.noise.statistics.allan import deviation

    branches = set()
    for seed in range(6):  # seeds 2 and 3 take the B1 + R(n) branch at m = 4096
        y = np.random.default_rng(seed).standard_normal(100_000)
        r = deviation("adev", y, rate_hz=1.0)
        x = _rate_to_phase(y, 1.0, float(np.mean(y)))
        ref = I.identify_alpha(_PhaseArray(x), r.m, statistic="adev", data="freq",
                               n_terms=r.n_terms)
        np.testing.assert_array_equal(r.alpha, ref.alpha)
        assert r.alpha_source == ref.source
        branches |= set(r.alpha_source)
    # the B1 + R(n) branch's angle verdicts on these white-rate records follow rate-noise
    # verdicts, so rule 5 reports them "rate-carried"
    assert {"acf", "b1", "rate-carried", "carried"} <= branches


def test_no_angle_noise_after_rate_noise_in_rate_records():
    """Rule 5: on white-rate records no tau past a rate-noise verdict is called angle
    noise (B1 + R(n) called angle noise at m = 4096 on seeds 2 and 3); each such tau
    takes the type of the nearest shorter one."""
    from inertialab.noise.statistics.allan import deviation

    hits = 0
    for seed in (2, 3):
        y = np.random.default_rng(seed).standard_normal(100_000)
        r = deviation("adev", y, rate_hz=1.0)
        assert max(r.alpha.tolist()) <= 0, r.alpha
        for i, s in enumerate(r.alpha_source):
            if s == "rate-carried":
                hits += 1
                assert r.alpha[i] == r.alpha[i - 1]
    assert hits >= 2
