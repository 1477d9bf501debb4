"""Out-of-core Allan on Dask: parallel == in-memory (noise.statistics.allan_dask)."""

import numpy as np
import pytest

from inertialab.errors import InputError
from inertialab.noise.statistics.allan import oadev, oadev_chunked

pytest.importorskip("dask.distributed")

from inertialab.noise.statistics.allan_dask import oadev_dask, open_client  # noqa: E402


@pytest.fixture(scope="module")
def client():
    with open_client("local", workers=2) as cl:
        yield cl


def _white_plus_rw(n, seed):
    rng = np.random.default_rng(seed)
    return (0.1 * rng.standard_normal(n) + np.cumsum(1e-4 * rng.standard_normal(n)) + 5.0)


def test_chunked_allan_dask_equals_in_memory(tmp_path, client):
    y = _white_plus_rw(1_000_003, 11)
    p = tmp_path / "long.npy"
    np.save(p, y)
    # decade taus: the noise core's angle-based kernel (its octave grid may take a
    # lag-doubling shortcut with different rounding)
    ref = oadev(y, rate_hz=100.0, taus="decade")
    # small checkpoint spacing: many chunks and many tasks, taus straddling them
    r = oadev_dask(p, rate_hz=100.0, taus="decade", client=client, chunk=1 << 15,
                   range_chunks=3)
    np.testing.assert_array_equal(r.m, ref.m)
    np.testing.assert_array_equal(r.n_terms, ref.n_terms)
    # only the order of the final additions differs: 1e-12 relative
    np.testing.assert_allclose(r.dev, ref.dev, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(r.alpha, ref.alpha)
    np.testing.assert_allclose(r.ci_low, ref.ci_low, rtol=1e-12)
    np.testing.assert_allclose(r.ci_high, ref.ci_high, rtol=1e-12)


def test_chunked_allan_bad_input(tmp_path, client):
    with pytest.raises(InputError, match=".npy"):
        oadev_dask(tmp_path / "x.csv", rate_hz=1.0, client=client)
    p = tmp_path / "const.npy"
    np.save(p, np.ones(1000))
    with pytest.raises(InputError, match="constant"):
        oadev_dask(p, rate_hz=1.0, client=client)
    q = tmp_path / "nan.npy"
    y = np.ones(1000)
    y[500] = np.nan
    np.save(q, y)
    with pytest.raises(InputError, match="index 500"):
        oadev_dask(q, rate_hz=1.0, client=client)


@pytest.mark.slow
def test_chunked_allan_1e8_samples(tmp_path, client):
    """The issue's size: 1e8 samples on disk (float32, 400 MB, memory-mapped), the
    noise core's serial out-of-core path against Dask on 2 workers."""
    n = 100_000_000
    p = tmp_path / "1e8.npy"
    rng = np.random.default_rng(5)
    mm = np.lib.format.open_memmap(p, mode="w+", dtype=np.float32, shape=(n,))
    step = 1 << 24
    for s in range(0, n, step):
        e = min(s + step, n)
        mm[s:e] = rng.standard_normal(e - s, dtype=np.float32)
    mm.flush()
    del mm
    taus = [0.01, 1.0, 100.0, 10_000.0, 300_000.0]   # m from 1 to 3e7
    y = np.load(p, mmap_mode="r")
    ref = oadev_chunked(y, rate_hz=100.0, taus=taus)
    r = oadev_dask(p, rate_hz=100.0, taus=taus, client=client)
    np.testing.assert_array_equal(r.m, ref.m)
    np.testing.assert_allclose(r.dev, ref.dev, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(r.alpha, ref.alpha)
