"""Out-of-core sums of the overlapping Allan and Hadamard variances (and the total variance)
of a rate record read in chunks, equal to the in-memory path's to ~1e-13.

Two paths:

* **compiled, octave m** (:func:`octave_out_of_core`, kernels in
  :mod:`inertialab.noise.statistics._fast_stream`): no angle is stored. Windows of :data:`WINDOW`
  summands go through one kernel that converts them, sums runs of :data:`RUN` samples
  (the angle's checkpoints) and takes the lag-doubling levels; the top octaves (from
  :data:`SWEEP_MIN` up) come from one sweep over the record by residue classes, each
  block of the angle recomputed once from its checkpoint into a cache-held ring.
* **otherwise** (:func:`stream_sums`): the angle, spilled to a temporary file by
  :class:`inertialab.noise.statistics._phase._PhaseFromRate`, returns any window. Two sweeps keep
  the number of windows read small: **small m** (the taps of a block of ``L`` summands
  fit one window of ``L + q m`` points, q = 2 Allan, 3 Hadamard): one sweep computes each
  window once and evaluates every such m on it; **large m, a multiple of L**: the blocks
  of one residue class modulo ``m/L`` are visited in order, so the window of block k
  serves as tap 0 of block k, tap 1 of block k-1, ... and each window is computed once
  per tau; any other m: the taps' windows are computed per block. Memory: a few windows
  of ``L`` = :data:`inertialab.noise.statistics._phase.CHUNK` points.

Definitions: NIST SP 1065 (Riley 2008) §5.2.4 (overlapping Allan), §5.2.8 (overlapping
Hadamard), §5.2.11 (total variance).
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from inertialab.noise.statistics._phase import CHUNK, _Releaser, _sumsq, strided_window

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
    from inertialab.noise.statistics._octave import (
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
            sums[win] = _window_octave_sums(K, src.y, src.mean, ms[win], q, WINDOW,
                                            Scaled(progress, 0.3, 0.7)) * (src.tau0 * src.tau0)
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


#: Samples per run of the compiled path's angle checkpoints (and per block of its
#: sweep over the taus beyond the windows): the angle at every run start is kept
#: (8 bytes per 4096 samples), a point is recomputed from its run's start.
RUN = 1 << 12

#: Classes of the sweep beyond the windows between two releases of the record's mapped
#: pages (each class reads one block in ``Q``, scattered over the file).
RELEASE_CLASSES = 8

#: Points of the angle read by windows between two releases of the record's mapped pages
#: (64 MiB of float32).
RELEASE_POINTS = 1 << 24

#: Smallest m the compiled path takes by the sweep over the angle rather than in the
#: windows. The sweep takes the top octaves that one ring of blocks holds (a factor
#: :func:`_ring_span` from the largest m), but none below this (where ``8 q m`` exceeds
#: :data:`WINDOW` it takes them anyway): a tau of the sweep reads three blocks of the
#: angle held in the cache (0.26 ns per sample measured at 1e8), a level of the
#: windows' kernel reads and writes the window (0.58 ns, and every level of a window
#: also updates its reach, ``q`` times the largest m in it), but the sweep recomputes
#: the angle once (0.9 ns per sample) and the angle's differences carry its rounding
#: (~1e-16 of the angle's size), so m stays large against the record.
SWEEP_MIN = 1 << 16

#: Most bytes of the sweep's ring of blocks (taus further apart go to separate sweeps,
#: each recomputing the angle once): a ring held in the cache.
RING_BYTES = 16 << 20


def octave_fast(statistic: str, ms, dtype) -> bool:
    """True when the compiled out-of-core octave path (:func:`octave_out_of_core`) takes
    ``statistic`` at ``ms`` on a record of ``dtype``: the compiled kernels are on, the
    statistic has a streaming kernel, every m is a power of two and the samples are
    native-order integers or float32/float64 (what the compiled kernels read)."""
    from inertialab.noise.statistics._octave import fast_kernels, is_octave

    dt = np.dtype(dtype)
    return (statistic in STREAM_STATS and fast_kernels() is not None and is_octave(ms)
            and dt.isnative and (dt.kind in "iu" or dt in (np.float32, np.float64)))


def _stream_kernels():
    from inertialab.noise.statistics import _fast_stream

    return _fast_stream


class CheckpointedAngle:
    """Angle source of a rate record ``y`` (``tau0`` s per sample, minus ``mean``) from
    the angle at every ``S``-th point (``ck``, in units of ``y`` times samples): any
    window is recomputed from the run it starts in (compiled, one run at a time, the
    order of :func:`inertialab.noise.statistics._fast_stream.angle_block`). Memory: ``ck``; the
    record's mapped pages are released whenever the windows read since the last release
    reach :data:`RELEASE_POINTS` (TOTDEV's reflected summands read up to 6 m points near
    the record's ends)."""

    block = CHUNK
    constant = False

    def __init__(self, y, tau0: float, mean: float, ck: np.ndarray, S: int):
        self.y, self._y = y, np.asarray(y)
        self.tau0, self.mean, self.ck, self.S = tau0, mean, ck, S
        self.n = y.size + 1
        self._rel = _Releaser(y)
        self._read = 0  # points read since the last release

    def window(self, start: int, length: int, step: int = 1, out=None) -> np.ndarray:
        """Angle points ``x[start + step*i]``, ``i < length`` (angle units)."""
        if step != 1:
            return strided_window(self.window, start, length, step)
        out = np.empty(length) if out is None else out[:length]
        _stream_kernels().angle_block(self._y, self.ck, self.mean, self.S, start, length, out)
        out *= self.tau0
        self._read += length
        if self._read >= RELEASE_POINTS:
            self._rel.drop_all()
            self._read = 0
        return out

    def close(self) -> None:
        pass


def octave_out_of_core(y, tau0: float, mean: float, statistic: str, ms, max_points: int = 0,
                       progress=None):
    """The compiled out-of-core path of ``statistic`` (:data:`STREAM_STATS`) at the octave
    ``ms`` of the rate record ``y`` (any length, read in order twice at most; its angle
    is never stored).

    1. The windows' pass: windows of :data:`WINDOW` summands are converted to ``y -
       mean`` (float64; the in-memory working array's values) and run through the
       lag-doubling kernel for every m up to ``WINDOW / (8 q)``; the same conversion sums
       every run of :data:`RUN` samples, whose compensated running sum is the angle at
       every run start.
    2. The sweep beyond the windows: the larger m (``m_0 2^j``) in one sweep over the
       record by residue classes of blocks modulo ``m_0 / RUN``, every block of the angle
       recomputed once from its checkpoint, each tau's taps read from a ring of the
       last ``q 2^j_max + 1`` blocks.

    Returns ``(src, sums, nt, decimated)``: a :class:`CheckpointedAngle`, the sums of
    squares (angle units) and summand counts per m, and with ``max_points`` the
    :class:`inertialab.noise.statistics._octave.Decimated` rows of lag-m increments (the central
    ``max_points`` frequency averages per m, the in-memory kernel's rows: from the
    windows for m inside them, from the checkpoints beyond), else None. ``progress``:
    0-0.85 the windows, 0.85-1 the sweep."""
    from inertialab.noise.statistics._octave import (
        Decimated,
        _decimated_layout,
        fast_kernels,
        n_terms,
        totdev_edge_sum,
    )

    K, F = fast_kernels(), _stream_kernels()
    ms = np.asarray(ms, dtype=np.int64)
    nx = y.size + 1
    q = 3 if statistic == "ohdev" else 2
    nt = np.array([n_terms(statistic, nx, int(m)) for m in ms], dtype=np.int64)
    cnts = nx - q * ms
    # the sweep takes the top octaves one ring holds (from SWEEP_MIN up), the windows
    # the others (up to WINDOW / (8 q))
    m0 = max(SWEEP_MIN, int(ms.max()) // _ring_span(q, RUN)) if ms.size else SWEEP_MIN
    inwin = (8 * q * ms <= WINDOW) & (ms < m0)
    beyond = ms[~inwin]
    S = RUN if beyond.size == 0 else min(RUN, int(beyond.min()))
    S = math.gcd(S, WINDOW, F.TILE)  # (runs never straddle a window or a tile)
    runsum = np.empty((y.size + S - 1) // S)
    gather = dec = None
    if max_points:
        uses, starts, offs, flat = _decimated_layout(nx, ms, max_points)
        gather = (uses[inwin], starts[inwin], offs[inwin], flat)
        dec = Decimated(ms, uses, offs, flat, increments=True)
    sums = np.zeros(ms.size)
    sums[inwin] = _window_octave_sums(K, y, mean, ms[inwin], q, WINDOW,
                                      Scaled(progress, 0.0, 0.85), (F, S, runsum), gather)
    ck = np.empty(runsum.size + 1)
    F.checkpoints(runsum, ck)
    src = CheckpointedAngle(y, tau0, mean, ck, S)
    if beyond.size:
        sums[~inwin] = _sweep_beyond(F, src, beyond, cnts[~inwin], q, Scaled(progress, 0.85, 1.0))
        if dec is not None:  # the rows beyond the windows: increments of checkpoints
            for r in np.flatnonzero(~inwin):
                idx = (starts[r] + ms[r] * np.arange(uses[r])) // S  # (multiples of S)
                flat[offs[r]:offs[r] + uses[r] - 1] = np.diff(ck[idx])
    sums *= tau0 * tau0
    if statistic == "totdev":
        for k in range(ms.size):
            sums[k] += totdev_edge_sum(src.window, nx, int(ms[k]))
    if progress is not None:
        progress.update(1.0, 1.0, "done")
    return src, sums, nt, dec


def _ring_span(q: int, S: int) -> int:
    """The largest power of two ``p`` whose ring of ``q p + 4`` blocks of ``S`` points fits
    :data:`RING_BYTES`: one sweep takes the taus ``m_0 .. p m_0``."""
    cap = max(1, (RING_BYTES // (8 * S) - 4) // q)
    return 1 << (cap.bit_length() - 1)


def _sweep_beyond(F, src: CheckpointedAngle, ms: np.ndarray, cnts: np.ndarray, q: int,
                  progress: Scaled) -> np.ndarray:
    """Sums (angle-point units) at the octave ``ms`` beyond the windows, by residue classes
    (:func:`inertialab.noise.statistics._fast_stream.sweep_class`): blocks of ``S`` points, ``Q =
    m_0 / S`` classes, a ring of ``q max(m) / m_0 + 4`` blocks."""
    S = src.S
    out = np.zeros(ms.size)
    cap = _ring_span(q, S)  # largest step of one sweep
    groups, g0 = [], 0
    for k in range(1, ms.size + 1):
        if k == ms.size or ms[k] > cap * ms[g0]:
            groups.append((g0, k))
            g0 = k
    total = sum(int(ms[a]) // S for a, _ in groups)  # classes
    done = 0
    for a, b in groups:
        m0 = int(ms[a])
        Q = m0 // S
        steps = (ms[a:b] // m0).astype(np.int64)
        ring = np.empty((q * int(steps.max()) + 4, S))  # (+ 3: blocks computed four at once)
        part = np.zeros(b - a)
        for r in range(Q):
            F.sweep_class(src._y, src.ck, src.mean, S, src.n, r, Q, q, steps,
                          cnts[a:b].astype(np.int64), ring, part)
            if (r + 1) % RELEASE_CLASSES == 0 or r + 1 == Q:
                src._rel.drop_all()
                progress.update(done + r + 1, total, f"taus beyond the windows, "
                                f"class {done + r + 1}/{total}")
        out[a:b] = part
        done += Q
    return out


def _combine_sumsq(taps, q: int, bufs) -> float:
    """Sum of squared second (q = 2) or third (q = 3) differences of the taps x_i,
    x_{i+m}, ... (equal-length arrays), in cache-sized blocks with reused buffers."""
    from inertialab.noise.statistics._octave import OCT_BLOCK

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


def _window_octave_sums(K, y, mean: float, ms: np.ndarray, q: int, W: int, progress: Scaled,
                        runs=None, gather=None) -> np.ndarray:
    """Sums at the octave ``ms`` (each ``8 q m <= W``) by the compiled lag-doubling
    kernel on windows of ``W`` summands (plus the reach ``q max(ms)``) of the rate
    record ``y`` minus its ``mean``: the first differences of the angle up to tau0, as
    the in-memory path takes them, so every ``D(m)`` is the same sum of the same samples;
    each window adds its own summands (``lim``). In units of ``y`` squared (times tau0^2:
    angle units).

    ``runs = (F, S, runsum)``: the windows are converted by ``F.convert_runs``, which also
    sums every run of ``S`` samples into ``runsum`` (the angle's checkpoints), and every
    sample is visited. ``gather = (uses, starts, offs, flat)`` (rows of
    :class:`inertialab.noise.statistics._octave.Decimated`, one per m of ``ms``): each window
    gathers the lag-m increments ``D(m)_{start + k m}`` it owns, as the in-memory kernel
    gathers them from the whole record."""
    from inertialab.noise.statistics._octave import FAST_BLOCK

    nx = y.size + 1
    lev = np.log2(ms).astype(np.int64) if ms.size else np.zeros(0, dtype=np.int64)
    L = int(lev.max()) + 1 if ms.size else 0
    want = np.zeros(L, dtype=np.bool_)
    want[lev] = True
    reach = q * int(ms.max()) if ms.size else 0
    buf = np.empty(max(min(W + reach, nx) - 1, 1))
    tmp = np.empty(FAST_BLOCK)
    z = np.zeros(L, dtype=np.int64)
    use, start, off = z.copy(), z.copy(), z.copy()
    flat = np.empty(1) if gather is None else gather[3]
    none = (np.empty(1), 0, 0, np.empty(1), np.empty(1))  # no noise test in the kernel
    cnt = nx - q * (1 << np.arange(L, dtype=np.int64))  # summands per level
    tot = np.zeros(L)
    rel = _Releaser(y)
    yv = np.asarray(y) if runs is not None else y
    top = nx - 1 if runs is not None else int(cnt[0])
    if runs is not None:
        F, S, runsum = runs
        tiles = np.empty((2, F.TILE + (q + 1) * (1 << (F.FUSED - 1))))
    for b0 in range(0, top, W):
        P = min(W + reach, nx - b0)  # angle points of the window
        d = buf[:P - 1]
        own = min(W, nx - 1 - b0)
        if gather is not None and L:
            _window_rows(gather, lev, ms, b0, own, use, start, off)
        lim = np.clip(cnt - b0, 0, W)
        if runs is None:
            np.subtract(y[b0:b0 + P - 1], mean, out=d, dtype=np.float64)
            if L:
                tot += K.octave_d(d, P, want, q, use, start, off, flat, tmp, none, lim)
        else:  # converted, run-summed and the low levels in one pass over tiles
            tot += F.window_octave(yv[b0:b0 + P - 1], mean, d, P, want, q, lim, own, S,
                                   runsum, b0 // S, use, start, off, flat, tiles, tmp)
        rel(b0 + W)  # (the reach is read again by the next window)
        progress.update(min(b0 + W, top), top, "octave windows")
    return tot[lev]


def _window_rows(gather, lev, ms, b0: int, own: int, use, start, off) -> None:
    """Per level, the part of each gathered row (``gather``: uses, starts, offs of the
    rows of ``ms``) whose increments ``D(m)_{s + k m}``, ``k < uses - 1``, lie in the
    window's own summands ``b0 .. b0 + own - 1``: the kernel's ``(use, start, off)``
    (``use`` = increments + 1, 0 for none; ``start`` relative to the window)."""
    uses, starts, offs = gather[0], gather[1], gather[2]
    lo = np.maximum(0, -((starts - b0) // ms))  # first k with s + k m >= b0
    hi = np.minimum(uses - 1, -((starts - b0 - own) // ms))  # first k at or past the end
    n = np.maximum(hi - lo, 0)
    use[lev] = np.where(n > 0, n + 1, 0)
    start[lev] = starts + lo * ms - b0
    off[lev] = offs + lo


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
