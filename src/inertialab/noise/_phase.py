"""Angle (phase) sources and the per-tau sum-of-squares kernels of the Allan family.

Shared by :mod:`inertialab.noise.allan` (the statistics), :mod:`inertialab.noise.edf`
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
    for s in range(0, y.size, CHUNK):
        total += float(np.sum(y[s:s + CHUNK], dtype=np.float64))
    return total / y.size


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


def _rate_to_phase(y: np.ndarray, tau0: float, mean: float) -> np.ndarray:
    """``x_0 = 0, x_{k+1} = x_k + tau0 (y_k - mean)`` in float64, strictly sequential."""
    n = y.size
    x = np.empty(n + 1, dtype=np.float64)
    x[0] = 0.0
    for s in range(0, n, CHUNK):
        e = min(s + CHUNK, n)
        u = np.subtract(y[s:e], mean, dtype=np.float64)
        u *= tau0
        u[0] += x[s]
        np.cumsum(u, out=x[s + 1:e + 1])
    return x


class _PhaseFromRate:
    """Angle points of a (memory-mapped) rate record computed on demand.

    A first pass stores the mean and the angle at every ``CHECKPOINT``-th point; a
    window is recomputed from the checkpoint at or below it with the same sequential recurrence as
    :func:`_rate_to_phase`, so values equal the in-memory angle bit for bit.
    """

    def __init__(self, y: np.ndarray, tau0: float):
        self.y = y
        self.tau0 = tau0
        self.n = y.size + 1
        self.mean = _chunked_mean(y)
        # angle at every CHECKPOINT-th point (x_0 = 0), same sequential recurrence
        ck = np.empty(y.size // CHECKPOINT + 2, dtype=np.float64)
        ck[0] = 0.0
        lo = hi = None
        x_prev = 0.0
        for s in range(0, y.size, CHUNK):  # CHUNK is a multiple of CHECKPOINT
            e = min(s + CHUNK, y.size)
            u = np.subtract(y[s:e], self.mean, dtype=np.float64)
            bmin, bmax = float(u.min()), float(u.max())
            lo = bmin if lo is None else min(lo, bmin)
            hi = bmax if hi is None else max(hi, bmax)
            u *= tau0
            u[0] += x_prev
            np.cumsum(u, out=u)  # u[j] = x_{s+j+1}
            x_prev = float(u[-1])
            first = s // CHECKPOINT + 1
            last = e // CHECKPOINT
            if last >= first:
                ck[first:last + 1] = u[first * CHECKPOINT - s - 1:last * CHECKPOINT - s:CHECKPOINT]
        self.ck = ck
        self.constant = bool(lo == hi)

    block = CHUNK

    def window(self, start: int, length: int, step: int = 1) -> np.ndarray:
        return phase_window(self.y, self.ck, self.mean, self.tau0, start, length, step=step,
                            checkpoint=CHECKPOINT, block=CHUNK)


def phase_window(y: np.ndarray, ck: np.ndarray, mean: float, tau0: float, start: int,
                 length: int, *, step: int = 1, checkpoint: int = CHECKPOINT,
                 block: int = CHUNK) -> np.ndarray:
    """Angle points ``x[start + step*i]``, ``i < length``, of rate samples ``y``.

    ``ck[b]`` is the angle at point ``b*checkpoint`` (``x_0 = 0``); a window is recomputed
    from the checkpoint at or below it with the same sequential recurrence as
    :func:`_rate_to_phase` (``x_{k+1} = x_k + tau0 (y_k - mean)``, cumulative sums in
    blocks of ``block`` aligned to the checkpoints), so the values equal the in-memory
    angle bit for bit. ``block`` must be a multiple of ``checkpoint``. Serves the
    out-of-core path here and the Dask path of :mod:`inertialab.workflows.batch`.
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
        u = np.subtract(y[s0:s0 + cnt - 1], mean, dtype=np.float64)
        u *= tau0
        pos = 0
        while pos < u.size:
            e = min(pos + block, u.size)
            u[pos] += out[pos]
            np.cumsum(u[pos:e], out=out[pos + 1:e + 1])
            pos = e
    return out[start - s0:]


class _LazyPhase:
    """Angle source of a rate record built on first use (checkpointed, O(n/CHUNK) memory)."""

    def __init__(self, y: np.ndarray, tau0: float):
        self._y, self._tau0, self._src = y, tau0, None
        self.n = y.size + 1
        self.block = CHUNK

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

