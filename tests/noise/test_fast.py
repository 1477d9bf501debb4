"""The compiled ``[fast]`` kernels (numba) against the numpy paths they
replace: every statistic, rate and angle input, octave / all / explicit taus, odd and
tiny records; deviations, EDFs and intervals to 1e-12 relative, noise types equal.
``INERTIALAB_FAST=0`` selects the numpy path (the reference here)."""

from __future__ import annotations

import re

import numpy as np
import pytest

pytest.importorskip("numba")

from inertialab.errors import InputError  # noqa: E402
from inertialab.noise.statistics import _octave as O  # noqa: E402
from inertialab.noise.statistics import identify as I  # noqa: E402
from inertialab.noise.statistics._phase import _PhaseArray  # noqa: E402
from inertialab.noise.statistics.allan import STATISTICS, deviation  # noqa: E402


def _both(monkeypatch, f):
    monkeypatch.setenv("INERTIALAB_FAST", "0")
    assert O.fast_kernels() is None
    ref = f()
    monkeypatch.setenv("INERTIALAB_FAST", "1")
    assert O.fast_kernels() is not None
    return ref, f()


def _rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
    ok = ~np.isnan(a) & (b != 0)
    np.testing.assert_array_equal(a[~ok & ~np.isnan(a)], b[~ok & ~np.isnan(b)])
    return float(np.max(np.abs(a[ok] / b[ok] - 1))) if ok.any() else 0.0


def _data(n, kind, seed, noise="white"):
    rng = np.random.default_rng(seed)
    y = rng.standard_normal(n)
    if noise == "rw":  # random-walk rate: B1/R(n) and the lag-1 differencing work too
        y = np.cumsum(y)
    elif noise == "wpm":  # white angle noise as a rate record
        y = np.diff(rng.standard_normal(n + 1))
    return (y * 0.3 + 5.0) if kind == "rate" else np.cumsum(y)


@pytest.mark.parametrize("stat", STATISTICS)
@pytest.mark.parametrize("kind", ["rate", "angle"])
def test_fast_equals_numpy(monkeypatch, stat, kind):
    worst = 0.0
    for n, noise in ((5, "white"), (8, "white"), (37, "rw"), (1001, "white"),
                     (4097, "wpm"), (30001, "rw"), (65537, "white")):
        data = _data(n, kind, n, noise)
        # (powers of two without m = 2, or without m = 1: the kernels' other branches)
        for taus in ("octave", "all", [1.0, 3.0, 7.0, 40.0, 300.0], [1.0, 4.0, 16.0, 64.0],
                     [2.0, 8.0, 32.0]):
            if taus == "all" and n > 5000:
                continue
            try:
                def run(taus=taus, data=data):
                    return deviation(stat, data, rate_hz=1.0, taus=taus, input=kind)
                ref, got = _both(monkeypatch, run)
            except InputError as exc:  # too short for the statistic: both must refuse
                for flag in ("0", "1"):
                    monkeypatch.setenv("INERTIALAB_FAST", flag)
                    with pytest.raises(InputError, match=re.escape(str(exc))):
                        deviation(stat, data, rate_hz=1.0, taus=taus, input=kind)
                continue
            np.testing.assert_array_equal(got.m, ref.m)
            np.testing.assert_array_equal(got.n_terms, ref.n_terms)
            np.testing.assert_array_equal(got.alpha, ref.alpha, err_msg=f"{n} {taus}")
            assert got.alpha_source == ref.alpha_source
            for f in ("dev", "edf", "ci_low", "ci_high"):
                worst = max(worst, _rel(getattr(got, f), getattr(ref, f)))
    assert worst < 1e-12, worst


@pytest.mark.parametrize("stat", ["oadev", "mdev", "ohdev"])
def test_fast_identification_equals_numpy(monkeypatch, stat):
    # every power-law type, lag-1 rows (>= 30 points) and B1/R(n) rows (fewer)
    rng = np.random.default_rng(4)
    seen = set()
    for k, noise in enumerate((rng.standard_normal(20001),  # white angle
                               np.cumsum(rng.standard_normal(20001)),  # white rate
                               np.cumsum(np.cumsum(rng.standard_normal(20001))))):
        src = _PhaseArray(noise)
        ms = np.unique(np.r_[1, 2, 3, 50, 400, 700, 900, 2000, 5000, np.arange(600, 660)])
        ms = ms[3 * ms < noise.size - 1]
        ref, got = _both(monkeypatch,
                         lambda src=src, ms=ms: I.identify_alpha(src, ms, statistic=stat))
        np.testing.assert_array_equal(got.alpha, ref.alpha, err_msg=str(k))
        assert got.source == ref.source
        assert "acf" in got.source and {"b1", "b1+rn"} & set(got.source)
        seen.update(got.alpha.tolist())
    assert len(seen) >= 3, seen  # several noise types (and R(n) on white angle noise)


def test_env_switch_off_uses_numpy(monkeypatch):
    monkeypatch.setenv("INERTIALAB_FAST", "0")
    assert O.fast_kernels() is None
    x = np.cumsum(np.random.default_rng(1).standard_normal(1000))
    r = deviation("oadev", x, rate_hz=1.0, input="angle")
    assert np.all(np.isfinite(r.dev))


@pytest.mark.parametrize("stat", STATISTICS)
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_fast_angle_non_finite_refused(monkeypatch, stat, bad):
    # the compiled angle path checks finiteness after its m = 1 sums: same error
    monkeypatch.setenv("INERTIALAB_FAST", "1")
    for pos in (0, 1, 500, 998, 999):
        x = np.cumsum(np.random.default_rng(pos).standard_normal(1000))
        x[pos] = bad
        for taus in ("octave", "all", [3.0, 10.0]):
            with pytest.raises(InputError, match=f"NaN or infinity at sample index {pos}"):
                deviation(stat, x, rate_hz=1.0, taus=taus, input="angle")
    with pytest.raises(InputError, match="NaN or infinity at sample index 1"):
        deviation(stat, np.array([0.0, np.nan, 1.0]), rate_hz=1.0, input="angle")


def test_fast_rn_sums_equal_numpy_kernels(monkeypatch):
    # the R(n) test's AVAR and MVAR sums from one compiled pass equal the numpy kernels
    x = np.cumsum(np.random.default_rng(8).standard_normal(30001))
    ms = np.array([1, 2, 7, 64, 1000, 4097, 9999])
    monkeypatch.setenv("INERTIALAB_FAST", "0")
    s_al, _ = O.dense_sums(x, "oadev", ms)
    s_mod, _ = O.dense_sums(x, "mdev", ms)
    monkeypatch.setenv("INERTIALAB_FAST", "1")
    K = O.fast_kernels()
    av = np.empty(ms.size)
    mod = K.dense_mod(x, ms, O.MOD_RESTART, np.empty(O.FAST_BLOCK), av)
    assert _rel(av, s_al) < 1e-12 and _rel(mod, s_mod) < 1e-12


@pytest.mark.parametrize("kind", ["rate", "angle"])
def test_fast_equals_numpy_tiny_records(monkeypatch, kind):
    # every length from 3 to 40 points (B1 and R(n) at m = 1, where R(n) = 1 sits on its
    # threshold and the numpy sums decide on both paths; kernels' edge branches)
    rng = np.random.default_rng(0)
    for n in range(3, 41):
        y = rng.standard_normal(n)
        data = (np.cumsum(y) if n % 3 == 0 else y) if kind == "rate" else np.cumsum(y)
        for stat in STATISTICS:
            for taus in ("octave", "all", [1.0, 2.0, 4.0, 8.0]):
                out = []
                for flag in ("0", "1"):
                    monkeypatch.setenv("INERTIALAB_FAST", flag)
                    try:
                        out.append(deviation(stat, data, rate_hz=1.0, taus=taus, input=kind))
                    except InputError as exc:
                        out.append(str(exc))
                a, b = out
                if isinstance(a, str) or isinstance(b, str):
                    assert a == b, (n, stat, taus)
                    continue
                np.testing.assert_array_equal(a.alpha, b.alpha, err_msg=f"{n} {stat} {taus}")
                assert _rel(b.dev, a.dev) < 1e-12 and _rel(b.edf, a.edf) < 1e-12


@pytest.mark.parametrize("order", [2, 3])
def test_level_pass_sums_and_compacts(order):
    # one level of the ADEV/HDEV kernel: the squared second (third) differences of the
    # level's points against their definition, and the next level's points x_{2j}
    from inertialab.noise.statistics import _fast as F

    rng = np.random.default_rng(11)
    for n in (2, 3, 4, 5, 6, 7, 17, 40, 1001, 4099, 20000):
        v = np.cumsum(rng.standard_normal(n)) + 1e3
        out = np.full((n - 1) // 2 + 1, np.nan)
        s = F._level_pairs(v, n, order, out)
        np.testing.assert_array_equal(out, v[::2])
        d = np.diff(v, order)
        assert s == pytest.approx(float(np.dot(d, d)), rel=1e-12, abs=0.0)
        assert F._level_sum(v, n, order) == pytest.approx(float(np.dot(d, d)), rel=1e-12,
                                                           abs=0.0)


@pytest.mark.parametrize("stat", ["adev", "hdev"])
def test_fast_identification_long_angle_records(monkeypatch, stat):
    # records whose level-1 row is the central 2^16 points (odd and even starts): the
    # compiled fused pass and the numpy identification give the same types and sources
    for n, noise in ((262147, "white"), (300001, "rw")):
        x = _data(n, "angle", n, noise)
        ref, got = _both(monkeypatch,
                         lambda x=x: deviation(stat, x, rate_hz=1.0, input="angle"))
        np.testing.assert_array_equal(got.alpha, ref.alpha)
        assert got.alpha_source == ref.alpha_source
        assert _rel(got.dev, ref.dev) < 1e-12


@pytest.mark.parametrize("case", ["offset", "spike_first", "spike_middle", "two_spikes",
                                  "trend"])
def test_fast_lag1_one_pass_sums_hold_on_offsets_and_spikes(monkeypatch, case):
    # the one-pass lag-1 sums (shifted by a median of three points) against the numpy
    # two-pass rule where a shift could cancel: a large offset, a spike at a row's first
    # or middle point, at both (the shift is a spike), a steep trend
    rng = np.random.default_rng(21)
    x = rng.standard_normal(40001)
    if case == "offset":
        x += 1e9
    elif case == "spike_first":
        x[0] += 1e12
    elif case == "spike_middle":
        x[20000] -= 1e12
    elif case == "two_spikes":
        x[0] += 1e12
        x[20000] += 1e12
    else:
        x += 1e6 * np.arange(x.size)
    for stat in ("adev", "hdev"):
        ref, got = _both(monkeypatch,
                         lambda s=stat: deviation(s, x, rate_hz=1.0, input="angle"))
        np.testing.assert_array_equal(got.alpha, ref.alpha)
        assert got.alpha_source == ref.alpha_source


def test_fast_lag1_rows_equal_numpy_rule():
    # the compiled lag-1 test of contiguous and strided rows (phase and frequency data)
    # against identify.lag1_alpha, unrounded, on every noise type it tells apart; 1e-9 on
    # alpha: the one-pass first round's sums err by ~n 1e-16 relative (n <= 9001 here),
    # far below the 0.5 that would change a rounded type
    from inertialab.noise.statistics import _fast as F

    rng = np.random.default_rng(5)
    e = rng.standard_normal(9001)
    for x in (e, np.cumsum(e), np.cumsum(np.cumsum(e)), e + 1e8, np.cumsum(e) - 3e7):
        for start, step, count in ((0, 1, 9001), (17, 1, 4000), (3, 2, 4000), (5, 7, 1200)):
            out = np.empty(1)
            F.lag1_strided(x, np.array([start]), np.array([step]), np.array([count]), 2, out,
                           np.empty(count), 2, True)
            ref = I.lag1_alpha(x[start:start + (count - 1) * step + 1:step], dmax=2)
            assert abs(out[0] - ref) < 1e-9, (start, step, out[0], ref)
            F.lag1_strided(x, np.array([start]), np.array([step]), np.array([count]), 2, out,
                           np.empty(count), 0, True)
            ref = I.lag1_alpha(np.diff(x[start:start + (count - 1) * step + 1:step]), dmax=2,
                               data_type="freq")
            assert abs(out[0] - ref) < 1e-9, (start, step, out[0], ref)


@pytest.mark.parametrize("stat", ["oadev", "ohdev", "totdev"])
def test_fast_chain_rows_equal_numpy_rows(monkeypatch, stat):
    # the lag-1 rows built as a chain (halved / summed in pairs from the first whole
    # decimated row) hand the same rows to B1 as the numpy gather (bit for bit: the
    # kernel's own additions), and the compiled lag-1 verdicts equal numpy's
    y = np.cumsum(np.random.default_rng(9).standard_normal(100003)) * 1e-3 + 2.0
    ms = 2 ** np.arange(15)
    monkeypatch.setenv("INERTIALAB_FAST", "0")
    _, _, ref = O.octave_sums(y - y.mean(), stat, ms, decimate=I.MAX_POINTS)
    monkeypatch.setenv("INERTIALAB_FAST", "1")
    _, _, got = O.octave_sums(y - y.mean(), stat, ms, decimate=I.MAX_POINTS,
                              acf=I.acf_rules(stat)[:2])
    done, alphas = got.acf
    assert done[:10].all() and not done[-2:].any()
    for k, m in enumerate(ms.tolist()):
        if done[k]:
            z = ref[m]
            a = I.lag1_alpha(np.diff(z), dmax=I.acf_rules(stat)[0], data_type="freq")
            assert alphas[k] == int(np.rint(a)), m
        else:
            np.testing.assert_array_equal(got[m], ref[m])
