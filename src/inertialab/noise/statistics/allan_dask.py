"""The overlapping Allan deviation of a log too long for memory, on Dask (docs/batch.md).

``oadev_dask(path, rate_hz=...)`` computes the overlapping Allan deviation of a rate log
in a ``.npy`` file, memory-mapped by each task: a parallel pass of per-chunk sums gives
the mean exactly as :mod:`inertialab.noise.statistics.allan` forms it, one sequential pass stores the
angle at every chunk boundary (the same recurrence as the noise core, so the angle values
agree to a few units of the last place), and then tasks of ``(summand range, tau)`` sum the squared second
differences in parallel. Only the order in which the partial sums are added differs from
the serial path, so the deviations agree to about 1e-15 relative (tested at 1e-12). The
noise type, EDF and confidence interval come from the noise core's functions on the same
angle values. ``dask.distributed`` is imported only when a client is opened.

Why hand-written: Dask schedules the work, but no library splits an Allan variance into
independent partial sums that reproduce a serial implementation; the kernel here is a few
lines of numpy on top of the noise core's definitions.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from inertialab.errors import InputError

__all__ = ["oadev_dask", "open_client"]


@contextlib.contextmanager
def open_client(scheduler: str = "local", workers: int = 2):
    """A ``dask.distributed.Client``: a new ``LocalCluster`` of ``workers``
    single-threaded worker processes for ``"local"``, else a connection to the
    scheduler at the address given. Closed on exit (a LocalCluster is shut down)."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise InputError("batch needs dask.distributed: pip install 'inertialab[dask]'") from None
    if scheduler == "local":
        if int(workers) < 1:
            raise InputError(f"argument 'workers' must be >= 1, got {workers}")
        cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=50)
        client = Client(cluster)
        try:
            yield client
        finally:
            client.close()
            cluster.close()
    else:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise InputError(f"argument 'scheduler' {scheduler}: cannot connect "
                             f"({type(exc).__name__})") from None
        try:
            yield client
        finally:
            client.close()



class _NpyPhase:
    """Angle points of a ``.npy`` rate log, recomputed from chunk checkpoints exactly as
    :class:`inertialab.noise.statistics.allan` does (values equal its angle's to a few ulps).
    Pickles as the file path: each Dask task memory-maps the file itself."""

    def __init__(self, path: str, tau0: float, mean: float, ck: np.ndarray, chunk: int):
        self.path = str(path)
        self.tau0 = float(tau0)
        self.mean = float(mean)
        self.ck = ck
        self.chunk = int(chunk)
        self._y = None
        self.n = int(self.y.size) + 1
        self.block = chunk

    @property
    def y(self) -> np.ndarray:
        if self._y is None:
            self._y = np.load(self.path, mmap_mode="r")
            if self._y.ndim == 2:
                self._y = self._y[:, 0]
        return self._y

    def __getstate__(self):
        d = dict(self.__dict__)
        d["_y"] = None
        return d

    def window(self, start: int, length: int, step: int = 1) -> np.ndarray:
        from inertialab.noise.statistics._phase import phase_window

        return phase_window(self.y, self.ck, self.mean, self.tau0, start, length, step=step,
                            checkpoint=self.chunk, block=self.chunk)


def _chunk_sums(path: str, c0: int, c1: int, chunk: int) -> list[float]:
    y = np.load(path, mmap_mode="r")
    y = y[:, 0] if y.ndim == 2 else y
    out = []
    for s in range(c0 * chunk, min(c1 * chunk, y.size), chunk):
        blk = y[s:s + chunk]
        if not np.issubdtype(blk.dtype, np.integer) and not np.isfinite(blk).all():
            bad = int(np.flatnonzero(~np.isfinite(blk))[0]) + s
            raise InputError(f"NaN or infinity at sample index {bad}", path=path)
        out.append(float(np.sum(blk, dtype=np.float64)))
    return out


def _checkpoints(path: str, mean: float, tau0: float, chunk: int) -> tuple[np.ndarray, bool]:
    """Angle at every chunk boundary (the noise core's compensated sum of the chunks'
    pairwise sums, :func:`inertialab.noise.statistics._phase._rate_to_phase`) and whether the data
    are constant."""
    y = np.load(path, mmap_mode="r")
    y = y[:, 0] if y.ndim == 2 else y
    from inertialab.noise.statistics._phase import _neumaier

    ck = np.empty(y.size // chunk + 2, dtype=np.float64)
    ck[0] = 0.0
    prev = comp = 0.0
    lo = hi = None
    for i, s in enumerate(range(0, y.size, chunk)):
        u = np.subtract(y[s:s + chunk], mean, dtype=np.float64)
        bmin, bmax = float(u.min()), float(u.max())
        lo = bmin if lo is None else min(lo, bmin)
        hi = bmax if hi is None else max(hi, bmax)
        u *= tau0
        prev, comp = _neumaier(prev, comp, float(np.sum(u)))  # as _rate_to_phase
        ck[i + 1] = prev + comp
    return ck, bool(lo == hi)


def _oadev_partial(src: _NpyPhase, ms: Sequence[int], a: int, b: int,
                   block: int = 1 << 15) -> list[float]:
    """``sum_{i in [a, b)} (x[i+2m] - 2 x[i+m] + x[i])^2`` for each m (summands beyond
    ``n - 2m`` are left out), with the noise core's operation order per element."""
    out = []
    nx = src.n
    base = None
    small = [m for m in ms if 2 * m <= b - a]
    reach = 2 * max(small) if small else 0
    for m in ms:
        stop = min(b, nx - 2 * m)
        if stop <= a:
            out.append(0.0)
            continue
        cnt = stop - a
        if base is not None and base[0] == a and base[1].size >= cnt + 2 * m:
            x = base[1]
            w0, w1, w2 = x[:cnt], x[m:m + cnt], x[2 * m:2 * m + cnt]
        elif 2 * m <= cnt:
            x = src.window(a, min(b - a + reach, nx - a))
            base = (a, x)
            w0, w1, w2 = x[:cnt], x[m:m + cnt], x[2 * m:2 * m + cnt]
        else:
            w0, w1, w2 = (src.window(a + j * m, cnt) for j in (0, 1, 2))
        acc = np.array(w2, dtype=np.float64)
        acc += w1 * -2.0
        acc += w0
        # dot products over the noise core's in-memory blocks, added in order: the task's
        # start is a multiple of the block, so the partial sums match its own
        tot = 0.0
        for s in range(0, cnt, block):
            seg = acc[s:s + block]
            tot += float(np.dot(seg, seg))
        out.append(tot)
    return out


def oadev_dask(path, *, rate_hz: float, taus="octave", client=None, scheduler: str = "local",
               workers: int = 2, chunk: int | None = None, range_chunks: int = 8,
               confidence: float = 0.683, alpha=None, edf_method: str = "default"):
    """Overlapping Allan deviation of a ``.npy`` rate log, computed by Dask in parallel.

    Parameters
    ----------
    path : str or Path
        A one-column ``.npy`` file of rate samples (memory-mapped by every task; the
        record never has to fit in memory).
    rate_hz : float
        Sample rate, Hz.
    taus : see :func:`inertialab.noise.statistics.allan.tau_grid`, default "octave"
    client : dask.distributed.Client, optional
        An open client; else one is opened with ``scheduler``/``workers``.
    chunk : int, optional
        Checkpoint spacing in samples (default: the noise core's ``CHUNK``, which the
        angle recurrence needs: windows start at checkpoints).
    range_chunks : int, default 8
        Summands per task, in chunks.
    confidence, alpha, edf_method
        As :func:`inertialab.noise.statistics.allan.deviation`.

    Returns
    -------
    DeviationResult
        Equal to ``oadev(np.load(path), rate_hz=...)`` up to the order of the final
        additions (tested at 1e-12 relative).
    """
    from inertialab.noise.statistics import allan as _allan

    p = Path(path)
    y = _open_npy(p)
    n = int(y.size)
    rate = float(rate_hz)
    if not math.isfinite(rate) or rate <= 0:
        raise InputError(f"rate_hz must be positive and finite, got {rate_hz}")
    tau0 = 1.0 / rate
    ms = _allan.tau_grid(n, taus, rate_hz=rate, statistic="oadev")
    ctx = contextlib.nullcontext(client) if client is not None else open_client(scheduler,
                                                                                  workers)
    with ctx as cl:
        src, partials = _dask_passes(cl, p, n, tau0, [int(m) for m in ms],
                                     int(chunk or _allan.CHUNK), range_chunks)
    var = np.empty(ms.size)
    nt = np.empty(ms.size, dtype=np.int64)
    for k, m in enumerate(int(v) for v in ms):
        s = 0.0
        for part in partials:  # in order, as the noise core adds them
            s += part[k]
        cnt = src.n - 2 * m
        tau = m * tau0
        var[k] = s / (2.0 * tau * tau * cnt)
        nt[k] = cnt
    return _allan._with_intervals("oadev", y, ms, tau0, np.sqrt(var),
                                  _allan._Sums(var, nt, src), alpha, "rate", confidence,
                                  edf_method)


def _open_npy(p: Path) -> np.ndarray:
    """The one numeric column of the ``.npy`` file ``p``, memory-mapped (at least 3
    samples), or :class:`InputError` naming the file."""
    if p.suffix.lower() != ".npy" or not p.is_file():
        raise InputError("the chunked Allan path reads a one-column .npy file", path=p)
    try:
        y = np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError) as exc:
        raise InputError(f"not a readable .npy file ({exc})", path=p) from None
    if y.ndim == 2 and y.shape[1] == 1:
        y = y[:, 0]
    if y.ndim != 1 or not np.issubdtype(y.dtype, np.number):
        raise InputError(f".npy log must be one numeric column, got shape {y.shape}", path=p)
    if y.size < 3:
        raise InputError(f"too few samples ({y.size}) for any tau", path=p)
    return y


def _dask_passes(cl, p: Path, n: int, tau0: float, mlist: list, C: int, range_chunks: int):
    """The three passes on the cluster ``cl``: per-chunk sums (parallel) for the mean,
    the angle at every chunk boundary (one task), then the partial OADEV sums per summand
    range, all taus in one task each (parallel). Returns ``(angle source, partials)``."""
    from inertialab.noise.statistics import allan as _allan

    spath = str(p.resolve())
    nchunks = -(-n // C)
    groups = [(c0, min(c0 + range_chunks, nchunks)) for c0 in range(0, nchunks, range_chunks)]
    parts = cl.gather(cl.map(_chunk_sums, [spath] * len(groups), [g[0] for g in groups],
                             [g[1] for g in groups], [C] * len(groups), pure=False))
    total = 0.0
    for part in parts:
        for v in part:
            total += v
    mean = total / n
    ck, constant = cl.submit(_checkpoints, spath, mean, tau0, C, pure=False).result()
    if constant:
        raise InputError("data are constant (zero deviation at every tau); nothing to "
                         "analyse", path=p)
    src = _NpyPhase(spath, tau0, mean, ck, C)
    span = C * range_chunks
    sfut = cl.scatter(src, broadcast=True)
    blk = int(getattr(_allan, "BLOCK", 1 << 15))
    if span % blk:
        span = -(-span // blk) * blk
    futs = [cl.submit(_oadev_partial, sfut, mlist, a, a + span, blk, pure=False)
            for a in range(0, n + 1, span)]
    return src, cl.gather(futs)
