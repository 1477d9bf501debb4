"""Angle (phase) sources and the per-tau sum-of-squares kernels of the Allan family.

Shared by :mod:`inertialab.noise.statistics.allan` (the statistics), :mod:`inertialab.noise.statistics.edf`
(the B1/R(n) noise identification needs the same sums) and the chunked/Dask paths, so
that none of them imports another's private helpers (this module breaks the former
``allan`` <-> ``edf`` import circle). A source exposes ``n`` (angle points),
``constant`` and ``window(start, length, step=1)``; :class:`_PhaseArray` holds the angle
in memory, :class:`_PhaseFromRate` recomputes it from a memory-mapped rate record in
chunks from checkpoints, bit for bit equal to the in-memory angle.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from inertialab.errors import InputError


def check_input_rate(input: str, rate_hz) -> float:
    """The checks every statistic makes on ``input`` ("rate" | "angle") and ``rate_hz``
    (a positive finite number, returned as float)."""
    if input not in ("rate", "angle"):
        raise InputError(f"input must be 'rate' or 'angle', got '{input}'")
    try:
        rate = float(rate_hz)
    except (TypeError, ValueError):
        raise InputError(f"rate_hz must be a number, got {rate_hz!r}") from None
    if not math.isfinite(rate) or rate <= 0:
        raise InputError(f"rate_hz must be positive and finite, got {rate_hz}")
    return rate

#: Block length (summands) of the per-tau kernel: 3 float64 windows plus one
#: accumulator stay in L2 cache, and the dot product stays below OpenBLAS's
#: threading threshold (a threaded ``ddot`` per block was measured 50x slower on a
#: loaded 2-core machine than the single-threaded one).
BLOCK = 8192


#: Chunk length (samples) of the out-of-core path and of the mean.
CHUNK = 1 << 20


#: Spacing (samples) of the angle checkpoints of the out-of-core path; a window is
#: recomputed from the checkpoint at or below its start.
CHECKPOINT = 1 << 14


def _chunked_mean(y: np.ndarray) -> float:
    """Mean in float64 as the sum of per-chunk sums (same order for every path)."""
    total = 0.0
    rel = _Releaser(y)
    for s in range(0, y.size, CHUNK):
        total += float(np.sum(y[s:s + CHUNK], dtype=np.float64))
        rel(s + CHUNK)
    return total / y.size


class PageReleaser:
    """Drops the pages of a memory-mapped 1-D array from this process's mapping once they
    have been read (``madvise(MADV_DONTNEED)``; the data stay in the page cache and are
    read again on access), so an out-of-core pass over a file larger than memory does not
    keep it resident in the process. A no-op for anything but a contiguous, read-only
    ``np.memmap`` (or where the platform lacks ``madvise``)."""

    def __init__(self, y):
        self.mm = None
        try:
            import mmap

            mm = getattr(y, "_mmap", None)
            if (mm is None or not y.flags.c_contiguous or y.flags.writeable
                    or not hasattr(mm, "madvise")):
                return  # read-only maps only (a copy-on-write map would lose its edits)
            base = np.frombuffer(mm, dtype=np.uint8)
            start = base.ctypes.data
            del base
            self.off = y.ctypes.data - start  # byte offset of y[0] in the mapping
            if not 0 <= self.off <= len(mm):
                return
            self.mm, self.item, self.page = mm, y.itemsize, mmap.PAGESIZE
            self.advice = mmap.MADV_DONTNEED
            self.done = 0
        except (AttributeError, TypeError, ValueError, OSError, ImportError):
            self.mm = None

    def drop_all(self) -> None:
        """Release every page of ``y`` mapped so far (for passes that read the record out
        of order; the next call of the releaser starts again from the beginning)."""
        if self.mm is None:
            return
        self.done = 0
        self(len(self.mm) // self.item)  # (clipped to the mapping)

    def __call__(self, upto: int) -> None:
        """Release the pages holding ``y[:upto]`` (whole pages only)."""
        if self.mm is None:
            return
        end = (self.off + upto * self.item) // self.page * self.page
        end = min(end, len(self.mm) // self.page * self.page)
        if end > self.done:
            try:
                self.mm.madvise(self.advice, self.done, end - self.done)
                self.done = end
            except (OSError, ValueError):
                self.mm = None


_Releaser = PageReleaser  # (the name this package uses)


class _PhaseArray:
    """Angle points held in memory; ``window(start, length)`` is a view."""

    def __init__(self, x: np.ndarray):
        self.x = x
        self.n = x.size
        d = np.diff(x[: min(x.size, 4 * CHUNK)])
        self.constant = bool(x.size < 3 or (np.ptp(d) == 0 and _all_diff_const(x, d[0])))

    def window(self, start: int, length: int, step: int = 1) -> np.ndarray:
        return self.x[start:start + (length - 1) * step + 1:step]


def _all_diff_const(x: np.ndarray, d0: float) -> bool:
    for s in range(0, x.size - 1, CHUNK):
        d = np.diff(x[s:s + CHUNK + 1])
        if d.size and (d != d0).any():
            return False
    return True


#: Run length of the angle's local cumulative sums (see :func:`angle_runs`).
SUB = 4096


def angle_runs(u: np.ndarray, start: float) -> None:
    """In place: increments ``u`` (float64) -> ``start + cumsum(u)``, the one angle
    recurrence of every path.

    The cumulative sums run within runs of ``SUB`` points; each run starts at ``start``
    plus the cumulative sum of the runs' pairwise sums. A plain running cumulative sum
    of 1e7-1e9 points drifts coherently (rounding errors of ~eps |x| per step add up
    along the record): 2.5e-13 relative was measured at the largest tau of a 1e7-point
    OADEV, 1.2e-11 at m = 3e7 of a 1e8 one; with runs the drift is bounded by one run,
    and paths that start their windows at different checkpoints agree to ~1e-15.
    """
    k = u.size // SUB
    tail_start = start
    if k:
        W = u[:k * SUB].reshape(k, SUB)
        sub = W.sum(axis=1)
        np.cumsum(W, axis=1, out=W)
        off = np.empty(k + 1)
        off[0] = 0.0
        np.cumsum(sub, out=off[1:])
        off += start
        W += off[:k, None]
        tail_start = float(off[k])
    t = u[k * SUB:]
    if t.size:
        np.cumsum(t, out=t)
        t += tail_start


def _neumaier(total: float, comp: float, v: float) -> tuple[float, float]:
    """Compensated addition (Neumaier): returns ``(total + v, compensation)``; the sum so
    far is ``total + comp``."""
    t = total + v
    if abs(total) >= abs(v):
        comp += (total - t) + v
    else:
        comp += (v - t) + total
    return t, comp


def _rate_to_phase(y: np.ndarray, tau0: float, mean: float) -> np.ndarray:
    """``x_0 = 0, x_{k+1} = x_k + tau0 (y_k - mean)`` in float64: chunks of ``CHUNK``
    points by :func:`angle_runs`, chunk starts as a compensated sum of the chunks'
    pairwise sums."""
    n = y.size
    x = np.empty(n + 1, dtype=np.float64)
    x[0] = 0.0
    prev = comp = 0.0
    for s in range(0, n, CHUNK):
        e = min(s + CHUNK, n)
        u = x[s + 1:e + 1]
        np.subtract(y[s:e], mean, out=u, dtype=np.float64)
        u *= tau0
        block_sum = float(np.sum(u))
        angle_runs(u, prev + comp)
        prev, comp = _neumaier(prev, comp, block_sum)
    return x


class _PhaseFromRate:
    """Angle points of a (memory-mapped) rate record, never held whole.

    One pass computes the mean, a second the angle chunk by chunk (the recurrence of
    :func:`_rate_to_phase`), keeping the angle at every ``CHECKPOINT``-th point, the
    decimated points asked for in ``gather`` (m -> sorted indices) and whether the data
    are constant. Windows are then either recomputed from the checkpoint at or below them
    (``spill=False``: O(n/CHECKPOINT) memory) or, with ``spill=True``, read back from a
    temporary file the pass wrote (8 bytes per point in the temporary directory, deleted
    by :meth:`close`): a cumulative sum costs ~4 ns per point (latency bound) against
    ~1 ns to read a point back, and recomputation was the largest cost of the out-of-core
    path.
    """

    def __init__(self, y: np.ndarray, tau0: float, *, spill: bool = False,
                 gather: dict | None = None, progress=None):
        self.y = y
        self.tau0 = tau0
        self.n = y.size + 1
        self.mean = _chunked_mean(y)
        self._f = None
        if spill:
            import tempfile

            self._f = tempfile.TemporaryFile()
            np.zeros(1).tofile(self._f)
        gather = gather or {}
        self.gathered = {m: np.zeros(idx.size) for m, idx in gather.items()}  # x_0 = 0
        ck = np.empty(y.size // CHECKPOINT + 2, dtype=np.float64)
        ck[0] = 0.0
        lo = hi = None
        prev = comp = 0.0
        u = np.empty(min(CHUNK, max(y.size, 1)))
        rel = _Releaser(y) if spill else None  # spilled: y is not read again
        for s in range(0, y.size, CHUNK):  # CHUNK is a multiple of CHECKPOINT
            e = min(s + CHUNK, y.size)
            w = u[:e - s]
            np.subtract(y[s:e], self.mean, out=w, dtype=np.float64)
            bmin, bmax = float(w.min()), float(w.max())
            lo = bmin if lo is None else min(lo, bmin)
            hi = bmax if hi is None else max(hi, bmax)
            w *= tau0
            block_sum = float(np.sum(w))
            angle_runs(w, prev + comp)  # w[j] = x_{s+j+1}
            prev, comp = _neumaier(prev, comp, block_sum)
            first = s // CHECKPOINT + 1
            last = e // CHECKPOINT
            if last >= first:
                ck[first:last + 1] = w[first * CHECKPOINT - s - 1:last * CHECKPOINT - s:CHECKPOINT]
            for m, idx in gather.items():
                a, b = np.searchsorted(idx, [s + 1, e + 1])
                if b > a:
                    self.gathered[m][a:b] = w[idx[a:b] - s - 1]
            if self._f is not None:
                w.tofile(self._f)
                rel(e)
            if progress is not None:  # (Progress protocol: update(done, total, note))
                progress.update(e, y.size, "angle")
        if self._f is not None:
            self._f.flush()
        self.ck = ck
        self.constant = bool(lo == hi)

    block = CHUNK

    def window(self, start: int, length: int, step: int = 1, out=None) -> np.ndarray:
        """Angle points ``x[start + step*i]``, ``i < length`` (into ``out[:length]`` when
        given and spilled: a reused buffer costs no page faults)."""
        if self._f is None:
            return phase_window(self.y, self.ck, self.mean, self.tau0, start, length,
                                step=step, checkpoint=CHECKPOINT, block=CHUNK)
        if step == 1:
            out = np.empty(length) if out is None else out[:length]
            self._f.seek(8 * start)
            self._f.readinto(memoryview(out).cast("B"))
            return out
        return strided_window(self.window, start, length, step)

    def close(self) -> None:
        if self._f is not None:
            self._f.close()
            self._f = None


def strided_window(window, start: int, length: int, step: int) -> np.ndarray:
    """``x[start + step*i]``, ``i < length``, from a source's contiguous ``window(start,
    length)``, read a chunk of about :data:`CHUNK` points at a time."""
    res = np.empty(length)
    per = max(1, CHUNK // step)
    for a in range(0, length, per):
        b = min(a + per, length)
        res[a:b] = window(start + a * step, (b - a - 1) * step + 1)[::step]
    return res


def phase_window(y: np.ndarray, ck: np.ndarray, mean: float, tau0: float, start: int,
                 length: int, *, step: int = 1, checkpoint: int = CHECKPOINT,
                 block: int = CHUNK) -> np.ndarray:
    """Angle points ``x[start + step*i]``, ``i < length``, of rate samples ``y``.

    ``ck[b]`` is the angle at point ``b*checkpoint`` (``x_0 = 0``); a window is recomputed
    from the checkpoint at or below it by :func:`angle_runs` (runs aligned to the
    checkpoint, a multiple of ``SUB``), so its values equal the in-memory angle's to a
    few units of the last place. ``block`` must be a multiple of ``checkpoint``. Serves
    the out-of-core path here and the Dask path of :mod:`inertialab.workflows.batch`.
    """
    if step != 1:
        idx = start + step * np.arange(length, dtype=np.int64)
        out = np.empty(length, dtype=np.float64)
        blocks = idx // block
        cuts = np.flatnonzero(np.diff(blocks)) + 1
        for lo, hi in zip(np.r_[0, cuts], np.r_[cuts, length]):
            b = int(blocks[lo])
            w = phase_window(y, ck, mean, tau0, b * block, int(idx[hi - 1]) - b * block + 1,
                             checkpoint=checkpoint, block=block)
            out[lo:hi] = w[idx[lo:hi] - b * block]
        return out
    b = start // checkpoint
    s0 = b * checkpoint  # angle index of the checkpoint
    cnt = start + length - s0  # angle points from s0 inclusive
    out = np.empty(cnt, dtype=np.float64)
    out[0] = ck[b]
    if cnt > 1:
        u = out[1:]
        np.subtract(y[s0:s0 + cnt - 1], mean, out=u, dtype=np.float64)
        u *= tau0
        angle_runs(u, float(ck[b]))
    return out[start - s0:]


class _LazyPhase:
    """Angle source of a rate record built on first use (checkpointed, O(n/CHUNK) memory).

    ``mean`` (the record's mean, when the caller has it) lets :meth:`block_phase` give the
    angle at every ``block``-th point and its block sums from the rate in one vectorised
    pass, without the running sum of the whole angle."""

    def __init__(self, y: np.ndarray, tau0: float, mean: float | None = None):
        self._y, self._tau0, self._src, self._mean = y, tau0, None, mean
        self.n = y.size + 1
        self.block = CHUNK

    def block_phase(self, block: int):
        """``(xb, C)``: ``xb[k] = x_{k block}`` for k = 0 .. (n - 1) // block and ``C[k] =
        sum(x[:k block])`` for k = 0 .. n // block, from the increments ``u = tau0 (y -
        mean)``: ``x_{k b}`` is the running sum of the increments' block sums, and a block
        of angle points sums to ``b x_{k b} + sum_{i<b-1} (b-1-i) u_{k b + i}``. Equal to
        the same quantities of the in-memory angle up to rounding (~1e-16 relative).
        None without the mean. Memory: one float64 copy of the record (taken after the
        caller's working copy is freed)."""
        y = self._y
        if self._mean is None:
            return None
        b, mean, tau0 = int(block), self._mean, self._tau0
        nu = y.size  # increments (n - 1)
        nf = nu // b  # whole blocks of increments
        W = np.empty((b, 2))  # per block of y: its sum and its sum weighted by b-1-i
        W[:, 0] = 1.0
        W[:, 1] = np.arange(b - 1, -1, -1)
        P = np.asarray(y[:nf * b], dtype=np.float64).reshape(nf, b) @ W
        xb = np.zeros(nf + 1)
        np.cumsum((P[:, 0] - b * mean) * tau0, out=xb[1:])
        nb = self.n // b  # whole blocks of angle points: nf, or nf + 1 (nu + 1 = nb b)
        wsum = (P[:, 1] - mean * (b * (b - 1) / 2)) * tau0
        if nb > nf:  # the last block's increments lack its (weight 0) last one
            tail = float(np.dot(np.asarray(y[nf * b:], dtype=np.float64) - mean,
                                W[:b - 1, 1])) * tau0
            wsum = np.append(wsum, tail)
        C = np.zeros(nb + 1)
        np.cumsum(b * xb[:nb] + wsum, out=C[1:])
        return xb, C

    def window(self, start: int, length: int, step: int = 1) -> np.ndarray:
        if self._src is None:
            self._src = _PhaseFromRate(self._y, self._tau0)
        return self._src.window(start, length, step)


def _make_source(data: np.ndarray, rate_hz: float, input: str, chunked: bool):
    tau0 = 1.0 / float(rate_hz)
    if input == "rate":
        if chunked:
            return _PhaseFromRate(data, tau0)
        y = data
        mean = _chunked_mean(y)
        x = _rate_to_phase(y, tau0, mean)
        src = _PhaseArray.__new__(_PhaseArray)
        src.x = x
        src.n = x.size
        src.constant = bool(np.ptp(y) == 0)
        return src
    x = np.asarray(data, dtype=np.float64)
    return _PhaseArray(x)


def _sum_sq_filter(src, m: int, coeffs: Sequence[float], stride: int, nterm: int,
                   start: int = 0, block: int | None = None) -> float:
    """``sum_{i<nterm} (sum_j c_j x[start + i*stride + j*m])^2`` over blocks of summands."""
    block = getattr(src, "block", BLOCK) if block is None else block
    total = 0.0
    acc = np.empty(min(block, nterm), dtype=np.float64)
    tmp = np.empty_like(acc)
    c = list(coeffs)
    for b0 in range(0, nterm, block):
        cnt = min(block, nterm - b0)
        a = acc[:cnt]
        t = tmp[:cnt]
        i0 = start + b0 * stride
        last = len(c) - 1
        span = last * m + cnt
        whole = src.window(i0, span) if (stride == 1 and last * m <= 2 * cnt) else None

        def tap(j, i0=i0, cnt=cnt, whole=whole):
            if whole is not None:
                return whole[j * m:j * m + cnt]
            return src.window(i0 + j * m, cnt, stride)

        # start from the last tap (coefficient +1 for every family used here)
        np.copyto(a, tap(last))
        if c[last] != 1.0:
            a *= c[last]
        for j in range(last - 1, -1, -1):
            w = tap(j)
            cj = c[j]
            if cj == 1.0:
                a += w
            elif cj == -1.0:
                a -= w
            else:
                np.multiply(w, cj, out=t)
                a += t
        total += _sumsq(a) if cnt > BLOCK else float(np.dot(a, a))
    return total


def _sum_sq_mod(src, m: int, nterm: int, block: int | None = None) -> float:
    """Modified Allan: ``sum_i (sum_{j<m} d2_{i+j})^2``, ``d2`` the second difference."""
    block = getattr(src, "block", BLOCK) if block is None else block
    total = 0.0
    blk = max(block, m)
    for b0 in range(0, nterm, blk):
        cnt = min(blk, nterm - b0)
        ln = cnt + m - 1
        d = np.array(src.window(b0 + 2 * m, ln), dtype=np.float64)
        w = src.window(b0 + m, ln)
        d -= w
        d -= w
        d += src.window(b0, ln)
        cs = np.empty(ln + 1)
        cs[0] = 0.0
        np.cumsum(d, out=cs[1:])
        z = cs[m:m + cnt] - cs[:cnt]
        total += _sumsq(z)
    return total


def _sumsq(v: np.ndarray) -> float:
    """``sum(v*v)`` in BLOCK-sized dot products (single-threaded BLAS, see BLOCK)."""
    return float(sum(np.dot(v[s:s + BLOCK], v[s:s + BLOCK]) for s in range(0, v.size, BLOCK)))


def _reflect(src) -> _PhaseArray:
    """Total-variance extension ``x*`` (NIST SP 1065 §5.2.11): both ends reflected,
    ``x*_{1-j} = 2x_1 - x_{1+j}``, ``x*_{N+j} = 2x_N - x_{N-j}``, j = 1..N-2."""
    cached = getattr(src, "_ext", None)
    if cached is not None:
        return cached
    x = src.window(0, src.n)
    nx = x.size
    left = 2.0 * x[0] - x[nx - 2:0:-1]
    right = 2.0 * x[-1] - x[-2:0:-1]
    ext = _PhaseArray.__new__(_PhaseArray)
    ext.x = np.concatenate([left, x, right])
    ext.n = ext.x.size
    ext.constant = False
    src._ext = ext
    return ext

