"""The fast paths of the Allan family against independent references:
lag-doubling octave kernels, per-m dense kernels, TOTDEV without the extension, the
out-of-core stream and the vectorised EDF / noise identification, each checked against
allantools, the scalar implementation it replaces, or a long-double computation."""

from __future__ import annotations

import tracemalloc

import allantools as at
import numpy as np
import pytest

from inertialab.noise.statistics import _octave as O
from inertialab.noise.statistics import _phase as P
from inertialab.noise.statistics import _stream as S
from inertialab.noise.statistics import edf as E
from inertialab.noise.statistics import identify as I
from inertialab.noise.statistics.allan import STATISTICS, deviation


def _vs_allantools(stat, data, kind, taus, rate=2.0):
    inp = "rate" if kind == "freq" else "angle"
    r = deviation(stat, data, rate_hz=rate, taus=taus, input=inp)
    t2, d2, _, _ = getattr(at, stat)(data, rate=rate, data_type=kind, taus=r.taus_s)
    common = np.isin(r.taus_s, t2)
    assert common.sum() >= min(2, r.taus_s.size)
    idx = np.searchsorted(t2, r.taus_s[common])
    return float(np.max(np.abs(r.dev[common] / d2[idx] - 1)))


@pytest.mark.parametrize("stat", STATISTICS)
@pytest.mark.parametrize("kind", ["freq", "phase"])
@pytest.mark.parametrize("block", [1 << 16, 64])
def test_kernels_match_allantools(monkeypatch, stat, kind, block):
    # block 64 forces many blocks and the large-m branches (taps read at their offsets,
    # running modified sums) on small records
    monkeypatch.setattr(O, "OCT_BLOCK", block)
    for n in (9, 100, 1001, 4097):
        y = np.random.default_rng(n).standard_normal(n)
        data = y if kind == "freq" else np.cumsum(y)
        for taus in ("octave", "all", [1.5, 7.0, 33.0]):
            if n < 20 and not isinstance(taus, str):
                continue
            assert _vs_allantools(stat, data, kind, taus) < 1e-10, (n, taus)


def test_totdev_edges_without_extension(monkeypatch):
    # dense path with the reflected summands taken from the record's ends (no extension)
    monkeypatch.setattr(O, "EXT_MAX", 0)
    for n in (5, 6, 7, 33, 1001):
        x = np.cumsum(np.random.default_rng(n).standard_normal(n))
        assert _vs_allantools("totdev", x, "phase", "all", rate=1.0) < 1e-10


@pytest.mark.parametrize("fast", ["0", "1"])   # numpy kernel, compiled one where numba is
def test_edf_greenhall_many_equals_scalar(monkeypatch, fast):
    monkeypatch.setenv("INERTIALAB_FAST", fast)
    worst = 0.0
    for stat in E.GREENHALL_STATS:
        for N in (10, 37, 1001, 100001):
            ms = np.unique(np.r_[np.arange(1, min(N, 300)),
                                 np.geomspace(1, N, 60).astype(np.int64)])
            for a in range(-4, 3):
                v = E.edf_greenhall_many(stat, N, ms, a)
                ref = np.array([E.edf_greenhall(stat, N, int(m), a) for m in ms])
                np.testing.assert_array_equal(np.isnan(v), np.isnan(ref))
                ok = ~np.isnan(ref)
                if ok.any():
                    worst = max(worst, float(np.max(np.abs(v[ok] / ref[ok] - 1))))
    assert worst < 1e-12


def test_lag1_many_equals_scalar():
    rng = np.random.default_rng(3)
    rows = [np.cumsum(rng.standard_normal(k)) ** p for k, p in
            [(3, 1), (4, 1), (5, 1), (31, 1), (100, 2), (511, 1), (512, 1), (3000, 1),
             (64, 1), (65, 1), (200, 1)]]
    rows.append(rng.standard_normal(300))  # white: stops at d = 0
    for dmax in (2, 3):
        many = I.lag1_alpha_many(rows, dmax=dmax)
        one = np.array([I.lag1_alpha(r, dmax=dmax) for r in rows])
        np.testing.assert_allclose(many, one, rtol=1e-9, atol=1e-12)


def test_identification_bounded_to_central_points():
    # the lag-1 test reads at most MAX_POINTS decimated points whatever the record length
    x = np.cumsum(np.random.default_rng(9).standard_normal(300_001))
    seen = []

    class Windows:  # a phase source without .x: identification reads through window()
        n = x.size

        def window(self, start, length, step=1):
            seen.append(length)
            return x[start:start + (length - 1) * step + 1:step]

    r = I.identify_alpha(Windows(), [1, 2, 4], statistic="oadev")
    assert seen == [I.MAX_POINTS] * 3
    assert set(r.alpha.tolist()) == {0}  # random-walk phase = white rate noise
    r2 = I.identify_alpha(P._PhaseArray(x), [1, 2, 4], statistic="oadev")
    np.testing.assert_array_equal(r.alpha, r2.alpha)


def test_angle_runs_do_not_drift():
    # long double reference: the run-wise angle stays within a few ulps of |x|
    y = np.random.default_rng(11).standard_normal(2_000_003).astype(np.float32)
    mean = float(np.mean(y, dtype=np.float64))
    x = P._rate_to_phase(y, 0.01, mean)
    u = np.subtract(y, mean, dtype=np.float64) * 0.01  # the same float64 increments
    ref = np.concatenate([[0], np.cumsum(u.astype(np.longdouble))])
    err = float(np.abs(x - ref.astype(float)).max())
    plain = float(np.abs(np.concatenate([[0], np.cumsum(u)]) - ref.astype(float)).max())
    assert err < 16 * np.finfo(float).eps * float(np.abs(ref).max())
    assert err < plain / 20  # the running cumulative sum drifts (7e-12 here)


def test_stream_sums_equal_dense_kernels():
    y = (np.random.default_rng(3).standard_normal(200_001) * 3 + 10).astype(np.float32)
    src = P._PhaseFromRate(y, 0.005, spill=True)
    try:
        x = P._rate_to_phase(y, 0.005, src.mean)
        np.testing.assert_allclose(src.window(0, src.n), x, rtol=0, atol=1e-12)
        for stat in S.STREAM_STATS:
            for ms in (2 ** np.arange(15), np.array([1, 3, 700, 2049, 5000, 12289, 30000])):
                if stat == "totdev" and ms[1] == 3:
                    continue
                a, na = S.stream_sums(src, stat, ms, block=4096)  # residue sweeps too
                b, nb = O.dense_sums(x, stat, ms)
                np.testing.assert_array_equal(na, nb)
                np.testing.assert_allclose(a, b, rtol=1e-13)
    finally:
        src.close()


@pytest.mark.parametrize("stat", ["oadev", "ohdev", "totdev", "mdev"])
def test_out_of_core_equals_in_memory(tmp_path, stat):
    y = (np.random.default_rng(7).standard_normal(300_000) * 3 + 10).astype(np.float32)
    np.save(tmp_path / "y.npy", y)
    mm = np.load(tmp_path / "y.npy", mmap_mode="r")
    a = deviation(stat, y, rate_hz=200.0)
    b = deviation(stat, mm, rate_hz=200.0, chunked=True)
    np.testing.assert_allclose(b.dev, a.dev, rtol=1e-12)
    np.testing.assert_array_equal(b.alpha, a.alpha)


@pytest.mark.parametrize("stat", STATISTICS)
@pytest.mark.parametrize("kind", ["rate", "angle"])
def test_extra_memory_at_most_one_copy(stat, kind):
    # extra memory at most one copy of the input (octave taus)
    n = 1 << 22  # fixed buffers (a few MB) are < 10 % of the input here
    y = np.random.default_rng(2).standard_normal(n)
    data = y if kind == "rate" else np.cumsum(y)
    deviation(stat, data[:4096], rate_hz=1.0, input=kind)
    tracemalloc.start()
    try:
        deviation(stat, data, rate_hz=1.0, input=kind)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak <= 1.25 * data.nbytes, peak / data.nbytes
