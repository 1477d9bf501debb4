"""The out-of-core path (``chunked=True``) of OADEV/OHDEV/TOTDEV against the in-memory
one: the compiled octave windows, the sweep over the taus beyond them (the angle
recomputed from checkpoints, never stored), the rows the noise identification reads,
the numpy fallback (the angle spilled to a temporary file) and the progress it reports."""

import tempfile

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.statistics import _stream
from inertialab.noise.statistics._octave import fast_kernels
from inertialab.noise.statistics.allan import deviation, oadev_chunked


@pytest.fixture
def record(tmp_path):
    """A float32 rate record on disk, memory-mapped (as the command line reads a .npy)."""
    p = tmp_path / "y.npy"
    np.save(p, np.random.default_rng(11).standard_normal(100_003, dtype=np.float32))
    return np.load(p, mmap_mode="r")


@pytest.mark.parametrize("statistic", ["oadev", "ohdev", "totdev"])
@pytest.mark.parametrize("window", [1 << 24, 1 << 12])
def test_chunked_equals_in_memory(record, statistic, window, monkeypatch):
    # one window covering the record, and windows of 4096 summands (25 of them, m up to
    # 256 in the windows, m = 512 ... 2^15 by the sweep over the angle)
    monkeypatch.setattr(_stream, "WINDOW", window)
    a = deviation(statistic, record, rate_hz=50.0)
    b = deviation(statistic, record, rate_hz=50.0, chunked=True)
    np.testing.assert_array_equal(a.m, b.m)
    np.testing.assert_allclose(b.dev, a.dev, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(a.alpha, b.alpha)
    np.testing.assert_allclose(b.ci_high, a.ci_high, rtol=1e-12, atol=0)


def test_progress_reaches_the_end(record, monkeypatch):
    monkeypatch.setattr(_stream, "WINDOW", 1 << 12)
    seen = []

    class Sink:
        def update(self, done, total, note=""):
            seen.append(done / total)

    r = oadev_chunked(record, rate_hz=50.0, progress=Sink())
    assert r.m.size == 16
    assert len(seen) > 10
    assert seen[-1] == pytest.approx(1.0)
    assert all(b >= a - 1e-12 for a, b in zip(seen, seen[1:]))  # never goes back


@pytest.mark.skipif(fast_kernels() is None, reason="numba (the [fast] extra) not installed")
@pytest.mark.parametrize("q", [2, 3])
def test_compiled_taps_equal_numpy(q):
    from inertialab.noise.statistics._octave import _Buffers

    x = np.cumsum(np.random.default_rng(q).standard_normal(5000))
    taps = [x[j * 700:j * 700 + 2000] for j in range(4)]
    K = fast_kernels()
    got = K.combine_taps(taps[0], taps[1], taps[2], taps[q], q, 2000)
    ref = _stream._combine_sumsq(taps[:q + 1], q, _Buffers(4096))
    assert got == pytest.approx(ref, rel=1e-13)


needs_fast = pytest.mark.skipif(fast_kernels() is None,
                                reason="numba (the [fast] extra) not installed")


def _memmap(tmp_path, y, name="r.npy"):
    np.save(tmp_path / name, y)
    return np.load(tmp_path / name, mmap_mode="r")


@needs_fast
@pytest.mark.parametrize("statistic", ["oadev", "ohdev", "totdev"])
@pytest.mark.parametrize("window, sweep_min, run", [
    (1 << 24, 1 << 14, 4096),  # one window; the top octaves by the sweep
    (1 << 13, 1 << 16, 4096),  # m = 128/256 .. by the sweep (runs of 128/256 points)
    (1 << 16, 1 << 9, 1024),  # several sweeps (a ring of 2 blocks: a factor 2 each)
])
def test_compiled_path_equals_in_memory(tmp_path, statistic, window, sweep_min, run,
                                        monkeypatch):
    # a gyro-like record: a large bias (the mean the angle subtracts) on white noise and
    # a random walk of rate (the angle grows as n^1.5: the hardest case for differences
    # of the recomputed angle); odd length, so the last run and block are partial
    rng = np.random.default_rng(5)
    n = 200_003
    y = (40.0 + rng.standard_normal(n) + np.cumsum(rng.standard_normal(n)) * 0.01)
    mm = _memmap(tmp_path, y.astype(np.float32))
    monkeypatch.setattr(_stream, "WINDOW", window)
    monkeypatch.setattr(_stream, "SWEEP_MIN", sweep_min)
    monkeypatch.setattr(_stream, "RUN", run)
    if sweep_min < 1 << 16:
        monkeypatch.setattr(_stream, "RING_BYTES", 8 * run * (2 * 3 + 4))
    calls = []
    real = _stream._sweep_beyond
    monkeypatch.setattr(_stream, "_sweep_beyond",
                        lambda *a, **k: calls.append(a[2].size) or real(*a, **k))
    a = deviation(statistic, np.asarray(mm), rate_hz=100.0)
    b = deviation(statistic, mm, rate_hz=100.0, chunked=True)
    assert calls and calls[0] >= 2  # the sweep took several taus
    np.testing.assert_allclose(b.dev, a.dev, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(b.alpha, a.alpha)
    assert b.alpha_source == a.alpha_source
    np.testing.assert_array_equal(b.n_terms, a.n_terms)
    np.testing.assert_allclose(b.ci_low, a.ci_low, rtol=1e-12, atol=0)


@needs_fast
def test_no_temporary_file_on_the_compiled_path(record, monkeypatch):
    def refuse(*a, **k):
        raise AssertionError("the compiled path wrote a temporary file")

    monkeypatch.setattr(tempfile, "TemporaryFile", refuse)
    monkeypatch.setattr(_stream, "WINDOW", 1 << 12)
    r = oadev_chunked(record, rate_hz=50.0)
    assert np.all(np.isfinite(r.dev))


def _checkpoints(y, mean, S):
    """The windows' kernel with no level: ``(y - mean, checkpoints every S points)``."""
    from inertialab.noise.statistics import _fast_stream as F

    z = np.zeros(0, dtype=np.int64)
    d, runsum = np.empty(y.size), np.empty((y.size + S - 1) // S)
    F.window_octave(y, mean, d, y.size + 1, np.zeros(0, dtype=np.bool_), 2, z, y.size, S,
                    runsum, 0, z, z, z, np.empty(1), np.empty((2, F.TILE + 1024)),
                    np.empty(4096))
    ck = np.empty(runsum.size + 1)
    F.checkpoints(runsum, ck)
    return d, ck


@needs_fast
@pytest.mark.parametrize("q", [2, 3])
@pytest.mark.parametrize("levels", [3, 8, 13])
def test_window_kernel_equals_octave_kernel(q, levels):
    # the fused windows' kernel (conversion, the low levels over tiles, the others in
    # place) against the in-memory lag-doubling kernel: the same sums to rounding, the
    # same gathered increments bit for bit, at most lim[l] summands per level
    from inertialab.noise.statistics import _fast_stream as F

    K = fast_kernels()
    n = 100_003
    y = (np.random.default_rng(q + levels).standard_normal(n) + 7).astype(np.float32)
    mean = float(np.mean(y, dtype=np.float64))
    want = np.ones(levels, dtype=np.bool_)
    want[1] = False
    lim = np.full(levels, n, dtype=np.int64)
    lim[0] = 5_000  # (a window's own summands)
    m = 1 << np.arange(levels, dtype=np.int64)
    use = np.minimum((n - 1000) // m - 2, 3000)  # rows across tiles (m >= 8)
    start = (7 * m) % 1000
    off = np.concatenate([[0], np.cumsum(use)[:-1]])
    dec_a, dec_b = np.zeros(int(use.sum()) + 1), np.zeros(int(use.sum()) + 1)
    d = np.subtract(y, mean, dtype=np.float64)
    none = (np.empty(1), 0, 0, np.empty(1), np.empty(1))
    ref = K.octave_d(d, n + 1, want, q, use, start, off, dec_a, np.empty(4096), none, lim)
    S = 4096
    got = F.window_octave(y, mean, np.empty(n), n + 1, want, q, lim, n, S,
                          np.empty((n + S - 1) // S), 0, use, start, off, dec_b,
                          np.empty((2, F.TILE + 1024)), np.empty(4096))
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=0)
    assert got[1] == 0.0 and np.all(got[want] > 0)
    np.testing.assert_array_equal(dec_b, dec_a)


@needs_fast
@pytest.mark.parametrize("run", [4096, 512])
def test_angle_blocks_are_the_angle(run):
    # every window of the recomputed angle (from any start: mid-run, whole runs taken four
    # at a time, the partial last run) is as close to a long-double cumulative sum as the
    # in-memory path's angle (both sum within runs: ~1e-11 here, where a plain running
    # sum drifts further), and a point has one value whichever window holds it
    from inertialab.noise.statistics import _fast_stream as F
    from inertialab.noise.statistics._phase import _rate_to_phase

    rng = np.random.default_rng(run)
    y = (rng.standard_normal(50_001) * 2 + 3).astype(np.float32)
    mean = float(np.mean(y, dtype=np.float64))
    d = np.subtract(y, mean, dtype=np.float64)
    ref = np.concatenate([[0], np.cumsum(d.astype(np.longdouble))]).astype(float)
    dd, ck = _checkpoints(y, mean, run)
    np.testing.assert_array_equal(dd, d)  # the in-memory working array, bit for bit
    whole = np.empty(y.size + 1)
    F.angle_block(y, ck, mean, run, 0, y.size + 1, whole)
    in_memory = float(np.abs(_rate_to_phase(y, 1.0, mean) - ref).max())
    assert float(np.abs(whole - ref).max()) < 3 * in_memory + 1e-13
    for start, length in [(1, 7), (run - 3, 2 * run), (3 * run, 4 * run + 5),
                          (run + 17, 9 * run), (y.size - run - 5, run + 6), (y.size, 1)]:
        out = np.empty(length)
        F.angle_block(y, ck, mean, run, start, length, out)
        np.testing.assert_array_equal(out, whole[start:start + length])


@needs_fast
@pytest.mark.parametrize("q", [2, 3])
def test_sweep_equals_direct_sums(q):
    # the residue-class sweep against the squared differences of the whole angle
    from inertialab.noise.statistics import _fast_stream as F

    S, n = 256, 60_000
    y = np.random.default_rng(q).standard_normal(n)
    _, ck = _checkpoints(y, 0.0, S)
    x = np.empty(n + 1)
    F.angle_block(y, ck, 0.0, S, 0, n + 1, x)
    ms = np.array([1024, 2048, 8192], dtype=np.int64)
    m0, Q = 1024, 1024 // S
    steps = ms // m0
    cnts = (n + 1 - q * ms).astype(np.int64)
    ring = np.empty((q * int(steps.max()) + 4, S))
    got = np.zeros(ms.size)
    for r in range(Q):
        F.sweep_class(y, ck, 0.0, S, n + 1, r, Q, q, steps, cnts, ring, got)
    for k, m in enumerate(ms):
        c = int(cnts[k])
        taps = [x[j * m:j * m + c] for j in range(q + 1)]
        v = taps[2] - 2 * taps[1] + taps[0] if q == 2 else (
            taps[3] - 3 * taps[2] + 3 * taps[1] - taps[0])
        assert got[k] == pytest.approx(float(np.dot(v, v)), rel=1e-12)


@needs_fast
def test_rows_for_the_identification_equal_in_memory(monkeypatch):
    # the lag-m increments the windows gather are the in-memory kernel's, bit for bit;
    # those beyond the windows (from the checkpoints) agree to rounding
    from inertialab.noise.statistics import _octave
    from inertialab.noise.statistics import identify as ident

    y = np.random.default_rng(9).standard_normal(150_001).astype(np.float32)
    monkeypatch.setattr(_stream, "WINDOW", 1 << 13)
    monkeypatch.setattr(_stream, "SWEEP_MIN", 1 << 16)
    ms = 2 ** np.arange(16, dtype=np.int64)
    mean = float(np.mean(y, dtype=np.float64))
    _, _, _, dec = _stream.octave_out_of_core(y, 0.01, mean, "oadev", ms, ident.MAX_POINTS)
    d = np.subtract(y, mean, dtype=np.float64)
    _, _, ref = _octave.octave_sums(d, "oadev", ms, decimate=ident.MAX_POINTS)
    np.testing.assert_array_equal(dec.uses, ref.uses)
    for r, m in enumerate(ms):
        a = dec.flat[dec.offs[r]:dec.offs[r] + dec.uses[r] - 1]
        b = ref.flat[ref.offs[r]:ref.offs[r] + ref.uses[r] - 1]
        if 8 * 2 * m <= 1 << 13:  # in the windows
            np.testing.assert_array_equal(a, b)
        else:
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12 * np.abs(b).max())


def test_numpy_fallback_spills_and_agrees(record, monkeypatch):
    # without the compiled kernels the angle is spilled to a temporary file (the
    # reference path), with the same numbers
    monkeypatch.setenv("INERTIALAB_FAST", "0")
    monkeypatch.setattr(_stream, "WINDOW", 1 << 12)
    made = []
    real = tempfile.TemporaryFile
    monkeypatch.setattr(tempfile, "TemporaryFile", lambda *a, **k: made.append(1) or real())
    a = deviation("oadev", np.asarray(record), rate_hz=50.0)
    b = deviation("oadev", record, rate_hz=50.0, chunked=True)
    assert made
    np.testing.assert_allclose(b.dev, a.dev, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(b.alpha, a.alpha)


def test_constant_record_is_refused(tmp_path):
    mm = _memmap(tmp_path, np.full(10_000, 2.5, dtype=np.float32))
    with pytest.raises(InputError, match="constant"):
        oadev_chunked(mm, rate_hz=10.0)


def test_big_endian_record_takes_the_reference_path(tmp_path):
    y = np.random.default_rng(3).standard_normal(20_000)
    mm = _memmap(tmp_path, y.astype(">f4"))
    assert not _stream.octave_fast("oadev", np.array([1, 2]), mm.dtype)
    a = deviation("oadev", y.astype(np.float32), rate_hz=10.0)
    b = deviation("oadev", mm, rate_hz=10.0, chunked=True)
    np.testing.assert_allclose(b.dev, a.dev, rtol=1e-12, atol=0)


@needs_fast
def test_memory_is_windows_not_the_record(tmp_path, monkeypatch):
    # tracemalloc peak of the compiled path (alpha given: no identification rows): the
    # window buffer (W + reach points), the sweep's ring (at most RING_BYTES) and the
    # checkpoints (8 bytes per RUN samples), not a copy of the record
    n = 1 << 22
    mm = _memmap(tmp_path, np.random.default_rng(1).standard_normal(n).astype(np.float32))
    monkeypatch.setattr(_stream, "WINDOW", 1 << 16)
    oadev_chunked(mm[:5000], rate_hz=1.0, alpha=0)
    import tracemalloc

    tracemalloc.start()
    try:
        oadev_chunked(mm, rate_hz=1.0, alpha=0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    window = 8 * ((1 << 16) * 9 // 8)
    assert peak < window + _stream.RING_BYTES + 8 * n // _stream.RUN + (1 << 20), peak
    assert peak < 0.6 * 8 * n  # a float64 copy of the record: 32 MiB
