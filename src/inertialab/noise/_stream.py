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

from inertialab.noise._phase import CHUNK, _sumsq

#: Summands per window of the small-m sweep, in units of ``block``.
SWEEP = 4

#: Statistics with a streaming kernel (the others use the per-tau windows of allan.py).
STREAM_STATS = ("oadev", "ohdev", "totdev")


def stream_sums(src, statistic: str, ms: np.ndarray, block: int = CHUNK):
    """Sums of squared filter outputs (angle units) and summand counts of ``statistic``
    (:data:`STREAM_STATS`) at each m, from the out-of-core angle source ``src`` (its
    ``window(start, length, out=...)`` fills a reused buffer)."""
    from inertialab.noise._octave import OCT_BLOCK, _Buffers, _overlap_sum, n_terms, totdev_edge_sum

    nx = src.n
    q = 3 if statistic == "ohdev" else 2
    ms = np.asarray(ms, dtype=np.int64)
    nt = np.array([n_terms(statistic, nx, int(m)) for m in ms], dtype=np.int64)
    cnts = np.array([nx - q * int(m) for m in ms], dtype=np.int64)  # overlapping summands
    sums = np.zeros(ms.size)
    L = int(block)
    bufs = _Buffers(3 * OCT_BLOCK)
    small = [k for k in range(ms.size) if q * int(ms[k]) <= L and cnts[k] > 0]
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
    for k in range(ms.size):
        m, cnt = int(ms[k]), int(cnts[k])
        if k in small or cnt <= 0:
            continue
        Lr = min(m, L)
        if m % Lr == 0:
            if ring is None or ring[0].size < Lr:
                ring = [np.empty(Lr) for _ in range(q + 2)]
            sums[k] = _residue_sweep(src, m, cnt, q, Lr, ring, bufs)
        else:
            sums[k] = _tap_windows(src, m, cnt, q, L, bufs)
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


def _residue_sweep(src, m: int, cnt: int, q: int, L: int, ring, bufs) -> float:
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
