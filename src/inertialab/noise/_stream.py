"""Out-of-core sums of the overlapping Allan and Hadamard variances (and the total variance)
of a rate record read in chunks ("the out-of-core path at most 2x the
in-memory CPU, with identical numbers to 1e-12").

The angle is never held whole: :class:`inertialab.noise._phase._PhaseFromRate` (spilled to
a temporary file) returns any window. Two sweeps keep the number of windows read small:

* **small m** (the taps of a block of ``L`` summands fit one window of ``L + q m`` points,
  q = 2 Allan, 3 Hadamard): one sweep over the record computes each window once and
  evaluates every such m on it (the lag-m increments ``D`` shared by the taps, as the
  in-memory kernel);
* **large m, a multiple of L** (octave taus beyond the window): the blocks of one residue
  class modulo ``m/L`` are visited in order, so the window of block k serves as tap 0 of
  block k, tap 1 of block k-1, ... and each window is computed once per tau;
* any other m: the taps' windows are computed per block.

Memory: a few windows of ``L`` = :data:`inertialab.noise._phase.CHUNK` points.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from inertialab.noise._phase import CHUNK, _Releaser, _sumsq

#: Summands per window of the small-m sweep, in units of ``block``.
SWEEP = 4

#: Summands per window of the compiled octave sweep (a float64 window of WINDOW (1 +
#: 1/8) points: 144 MiB; every level of the kernel also updates the reach, so windows
#: much shorter than the record cost up to 1/8 more than the in-memory pass).
WINDOW = 1 << 24

#: Statistics with a streaming kernel (the others use the per-tau windows of allan.py).
STREAM_STATS = ("oadev", "ohdev", "totdev")


def stream_sums(src, statistic: str, ms: np.ndarray, block: int = CHUNK, progress=None):
    """Sums of squared filter outputs (angle units) and summand counts of ``statistic``
    (:data:`STREAM_STATS`) at each m, from the out-of-core angle source ``src`` (its
    ``window(start, length, out=...)`` fills a reused buffer; with the compiled kernels,
    octave m up to :data:`WINDOW` / (8 q) from windows of its rate record ``src.y``).
    ``progress`` (``update(done, total, note)``, :class:`inertialab.progress.Progress`),
    when given, hears the passes advance: 0.3-0.7 the windows, 0.7-1 the taus beyond
    (0-0.3 is the angle pass of the source)."""
    from inertialab.noise._octave import (
        OCT_BLOCK,
        _Buffers,
        _overlap_sum,
        fast_kernels,
        is_octave,
        n_terms,
        totdev_edge_sum,
    )

    nx = src.n
    q = 3 if statistic == "ohdev" else 2
    ms = np.asarray(ms, dtype=np.int64)
    nt = np.array([n_terms(statistic, nx, int(m)) for m in ms], dtype=np.int64)
    cnts = np.array([nx - q * int(m) for m in ms], dtype=np.int64)  # overlapping summands
    sums = np.zeros(ms.size)
    L = int(block)
    bufs = _Buffers(3 * OCT_BLOCK)
    K = fast_kernels()
    if K is not None and is_octave(ms) and hasattr(src, "y"):
        # compiled: octave m up to WINDOW / (8 q) by the lag-doubling kernel on windows
        # of the rate record (no angle); the larger ones from the spilled angle below
        win = [k for k in range(ms.size) if 8 * q * int(ms[k]) <= WINDOW and cnts[k] > 0]
        if win:
            sums[win] = _window_octave_sums(K, src, ms[win], q, WINDOW,
                                            Scaled(progress, 0.3, 0.7))
        small = []
        done = set(win)
    else:
        small = [k for k in range(ms.size) if q * int(ms[k]) <= L and cnts[k] > 0]
        done = set(small)
    if small:
        reach = max(q * int(ms[k]) for k in small)
        W = SWEEP * L  # summands per window (the window adds at most L: <= 25 %)
        top = max(int(cnts[k]) for k in small)
        wbuf = np.empty(min(W + reach, nx))
        for b0 in range(0, top, W):
            w = src.window(b0, min(W + reach, nx - b0), out=wbuf)
            for k in small:
                m, cnt = int(ms[k]), int(cnts[k])
                if b0 < cnt:  # the summands b0 .. b0+n-1 of this window, cache-blocked
                    n = min(W, cnt - b0)
                    sums[k] += _overlap_sum(w[:n + q * m], m, q, bufs)
    ring = None
    rest = [k for k in range(ms.size) if k not in done and cnts[k] > 0]
    for j, k in enumerate(rest):
        m, cnt = int(ms[k]), int(cnts[k])
        Lr = min(m, L)
        if m % Lr == 0:
            if ring is None or ring[0].size < Lr:
                ring = [np.empty(Lr) for _ in range(q + 2)]
            sums[k] = _residue_sweep(src, m, cnt, q, Lr, ring, bufs, K)
        else:
            sums[k] = _tap_windows(src, m, cnt, q, L, bufs)
        if progress is not None:
            progress.update(0.7 + 0.3 * (j + 1) / len(rest), 1.0,
                            f"tau {j + 1}/{len(rest)} from the spilled angle")
    if statistic == "totdev":
        for k in range(ms.size):
            sums[k] += totdev_edge_sum(src.window, nx, int(ms[k]))
    return sums, nt


def _combine_sumsq(taps, q: int, bufs) -> float:
    """Sum of squared second (q = 2) or third (q = 3) differences of the taps x_i,
    x_{i+m}, ... (equal-length arrays), in cache-sized blocks with reused buffers."""
    from inertialab.noise._octave import OCT_BLOCK

    n = taps[0].size
    total = 0.0
    for b0 in range(0, n, OCT_BLOCK):
        b1 = min(b0 + OCT_BLOCK, n)
        t = [a[b0:b1] for a in taps]
        u, v = bufs.get(0, b1 - b0), bufs.get(1, b1 - b0)
        np.subtract(t[q], t[q - 1], out=u)
        np.subtract(t[q - 1], t[q - 2], out=v)
        u -= v
        if q == 3:
            u -= v
            np.subtract(t[1], t[0], out=v)
            u += v
        total += _sumsq(u)
    return total


class Scaled:
    """A progress sink reporting ``done / total`` as the span ``lo`` .. ``hi`` of
    ``sink``'s 0..1 (a no-op without a sink)."""

    def __init__(self, sink, lo: float, hi: float):
        self.sink, self.lo, self.hi = sink, lo, hi

    def update(self, done: float, total: float, note: str = "") -> None:
        if self.sink is not None:
            f = 0.0 if total <= 0 else min(1.0, max(0.0, done / total))
            self.sink.update(self.lo + (self.hi - self.lo) * f, 1.0, note)


def _window_octave_sums(K, src, ms: np.ndarray, q: int, W: int, progress: Scaled) -> np.ndarray:
    """Sums at the octave ``ms`` (each ``8 q m <= W``) by the compiled lag-doubling
    kernel on windows of ``W`` summands (plus the reach ``q max(ms)``) of the rate
    record ``src.y`` minus its mean: the first differences of the angle up to tau0, as
    the in-memory path takes them, so every ``D(m)`` is the same sum of the same samples;
    each window adds its own summands (``lim``). Returned in angle units."""
    from inertialab.noise._octave import FAST_BLOCK

    y, mean, nx = src.y, src.mean, src.n
    lev = np.log2(ms).astype(np.int64)
    L = int(lev.max()) + 1
    want = np.zeros(L, dtype=np.bool_)
    want[lev] = True
    reach = q * int(ms.max())
    buf = np.empty(min(W + reach, nx) - 1)
    tmp = np.empty(FAST_BLOCK)
    z = np.zeros(L, dtype=np.int64)
    none = (np.empty(1), 0, 0, np.empty(1), np.empty(1))  # no noise test in the kernel
    cnt = nx - q * (1 << np.arange(L, dtype=np.int64))  # summands per level
    tot = np.zeros(L)
    rel = _Releaser(y)
    top = int(cnt[0])
    for b0 in range(0, top, W):
        P = min(W + reach, nx - b0)  # angle points of the window
        d = buf[:P - 1]
        np.subtract(y[b0:b0 + P - 1], mean, out=d, dtype=np.float64)
        rel(b0 + W)  # (the reach is read again by the next window)
        lim = np.clip(cnt - b0, 0, W)
        tot += K.octave_d(d, P, want, q, z, z, z, tmp, tmp, none, lim)
        progress.update(min(b0 + W, top), top, "octave windows")
    return tot[lev] * (src.tau0 * src.tau0)


def _residue_sweep(src, m: int, cnt: int, q: int, L: int, ring, bufs, K=None) -> float:
    nx = src.n
    Q = m // L
    total = 0.0
    for r in range(Q):
        wins = deque()
        free = deque(ring)
        k = 0
        while (r + k * Q) * L < cnt:
            start = (r + k * Q) * L
            while len(wins) < q + 1:  # windows of blocks k .. k+q
                s = start + len(wins) * m
                buf = free.popleft()
                wins.append((buf, src.window(s, min(L, nx - s), out=buf)))
            n = min(L, cnt - start)
            if K is not None:  # compiled (one pass, no temporaries)
                t = [w for _, w in wins]
                total += K.combine_taps(t[0], t[1], t[2], t[q], q, n)
            else:
                total += _combine_sumsq([w[:n] for _, w in wins], q, bufs)
            free.append(wins.popleft()[0])
            k += 1
    return total


def _tap_windows(src, m: int, cnt: int, q: int, L: int, bufs) -> float:
    total = 0.0
    for b0 in range(0, cnt, L):
        n = min(L, cnt - b0)
        taps = [src.window(b0 + j * m, n) for j in range(q + 1)]
        total += _combine_sumsq(taps, q, bufs)
    return total
