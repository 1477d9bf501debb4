"""The out-of-core path (``chunked=True``) of OADEV/OHDEV/TOTDEV against the in-memory
one: the compiled octave windows, the taus beyond them from the spilled angle, and the
progress it reports."""

import numpy as np
import pytest

from inertialab.noise import _stream
from inertialab.noise._octave import fast_kernels
from inertialab.noise.allan import deviation, oadev_chunked


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
    # 256 in the windows, m = 512 ... 2^15 from the spilled angle)
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
    from inertialab.noise._octave import _Buffers

    x = np.cumsum(np.random.default_rng(q).standard_normal(5000))
    taps = [x[j * 700:j * 700 + 2000] for j in range(4)]
    K = fast_kernels()
    got = K.combine_taps(taps[0], taps[1], taps[2], taps[q], q, 2000)
    ref = _stream._combine_sumsq(taps[:q + 1], q, _Buffers(4096))
    assert got == pytest.approx(ref, rel=1e-13)
