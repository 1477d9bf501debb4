"""Compiled kernels of the out-of-core octave path (optional ``[fast]`` extra, numba).

Used by :mod:`inertialab.noise.statistics._stream` when :func:`inertialab.noise.statistics._octave.fast_kernels`
is on; the out-of-core numpy path (:class:`inertialab.noise.statistics._phase._PhaseFromRate`, the
angle spilled to a temporary file) stays the fallback. The angle of a rate record ``y``
is never stored: the pass that converts ``y`` to the working array of the lag-doubling
kernel (:func:`window_octave`) also sums it in runs of ``S`` samples, the running
(compensated) sum of those run sums is the angle at every ``S``-th point, and any
stretch of the angle is recomputed from the checkpoint at or below it, one run at a
time (:func:`angle_block`).

Units: the kernels work on the increments ``d_i = y_i - mean`` (rate units); the angle
``x_{k+1} = x_k + d_k`` is in rate units times samples (the caller multiplies by
``tau0``). Kernels allocate nothing of the record's size; no kernel here calls one in
another module (numba's cache tracks a kernel's own file only).
"""

from __future__ import annotations

import numba as nb
import numpy as np

#: Reductions that may be re-associated (vectorised), as the other compiled kernels.
_jit = nb.njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})

#: Running sums kept in the order written (the angle recurrence, compensated sums).
_exact = nb.njit(cache=True, nogil=True)


@_exact
def checkpoints(runsum, ck):
    """``ck[0] = 0``, ``ck[k + 1] = ck[k] + runsum[k]`` as a compensated (Neumaier) running
    sum: the angle at the start of every run, accurate to ~1 unit of its last place
    however long the record (a plain running sum drifts ~sqrt(n) units)."""
    total = 0.0
    comp = 0.0
    ck[0] = 0.0
    for k in range(runsum.size):
        v = runsum[k]
        t = total + v
        if abs(total) >= abs(v):
            comp += (total - t) + v
        else:
            comp += (v - t) + total
        total = t
        ck[k + 1] = total + comp


@_exact
def angle_block(y, ck, mean, S, p0, n, out):
    """``out[j] = x_{p0 + j}`` for ``j < n``: the angle from the checkpoint of each run
    (``ck[r] = x_{r S}``) plus the run's own running sum of ``y - mean``, always from the
    run's start in the same order, so a point has one value whichever window asks. Runs
    wholly inside the window are taken four at a time, interleaved (four independent
    running sums: the latency of one addition is spread over four points)."""
    ny = y.size
    j = 0
    p = p0
    while j < n:
        r = p // S
        base = r * S
        if p == base and j + 4 * S <= n:  # four whole runs
            _four_runs(y, ck, mean, S, r, r + 1, r + 2, r + 3, out[j:], out[j + S:],
                       out[j + 2 * S:], out[j + 3 * S:])
            j += 4 * S
            p += 4 * S
            continue
        c = ck[r]
        s = 0.0
        e = min(base + S, p + n - j)  # to the end of this run or of the window
        for i in range(base, e):  # from the run's start (stored from p on)
            if i >= p:
                out[j + i - p] = c + s
            if i < ny:
                s += np.float64(y[i]) - mean
        j += e - p
        p = e


@_exact
def _four_runs(y, ck, mean, S, r0, r1, r2, r3, o0, o1, o2, o3):
    """The whole runs ``r0 .. r3`` (each in the record) into ``o0[:S] .. o3[:S]``, the
    additions of :func:`angle_block` in the same order per run, the four interleaved."""
    a0, a1, a2, a3 = r0 * S, r1 * S, r2 * S, r3 * S
    c0, c1, c2, c3 = ck[r0], ck[r1], ck[r2], ck[r3]
    s0 = s1 = s2 = s3 = 0.0
    for i in range(S):
        o0[i] = c0 + s0
        o1[i] = c1 + s1
        o2[i] = c2 + s2
        o3[i] = c3 + s3
        if i + 1 < S:  # (a run's last increment belongs to the next checkpoint)
            s0 += np.float64(y[a0 + i]) - mean
            s1 += np.float64(y[a1 + i]) - mean
            s2 += np.float64(y[a2 + i]) - mean
            s3 += np.float64(y[a3 + i]) - mean


@_jit
def _taps(t0, t1, t2, t3, q, n):
    """Sum over ``i < n`` of the squared second (``q = 2``) or third (``q = 3``)
    differences of the taps ``x_i, x_{i+m}, ...``, written as differences of the lag-m
    increments (the lag-doubling kernel's ``D(m)_{i+m} - D(m)_i``)."""
    s = 0.0
    if q == 2:
        for i in range(n):
            b = t1[i]
            u = (t2[i] - b) - (b - t0[i])
            s += u * u
    else:
        for i in range(n):
            a1 = t1[i]
            a2 = t2[i]
            v = a2 - a1
            u = ((t3[i] - a2) - v) - v + (a1 - t0[i])
            s += u * u
    return s


@_jit
def sweep_class(y, ck, mean, S, nx, r, Q, q, steps, cnts, ring, sums):
    """One residue class of the sweep over the taus beyond the windows.

    Blocks of ``S`` angle points (one run each) of class ``r`` modulo ``Q`` (blocks ``r,
    r + Q, r + 2Q, ...``) are computed once each, in order (:func:`angle_block`, four
    blocks at a time where whole), into a ring of the last ``ring.shape[0]`` blocks
    (at least ``q max(steps) + 4``). Tau ``j`` has ``m_j = steps[j] Q S``: its summands
    in the block ``k`` sweep steps back read the blocks ``k``, ``k + steps[j]``, ... ``k
    + q steps[j]``, all in the ring when block ``k + q steps[j]`` arrives. Adds into
    ``sums[j]`` the squared differences of the summands ``i < cnts[j]`` of this class
    (in angle-point units)."""
    R = ring.shape[0]
    k = 0
    while True:
        p0 = (r + k * Q) * S
        if p0 >= nx:
            break
        if p0 + 3 * Q * S + S <= nx:  # four whole blocks
            b = r + k * Q
            _four_runs(y, ck, mean, S, b, b + Q, b + 2 * Q, b + 3 * Q, ring[k % R],
                       ring[(k + 1) % R], ring[(k + 2) % R], ring[(k + 3) % R])
            got = 4
        else:
            angle_block(y, ck, mean, S, p0, min(S, nx - p0), ring[k % R])
            got = 1
        for kk in range(k, k + got):
            _combine_new(ring, kk, r, Q, S, q, steps, cnts, sums)
        k += got


@_jit
def _combine_new(ring, k, r, Q, S, q, steps, cnts, sums):
    """The summands of every tau whose last tap is the block ``k`` of the sweep."""
    R = ring.shape[0]
    for j in range(steps.size):
        st = steps[j]
        k0 = k - q * st
        if k0 < 0:
            continue
        b0 = (r + k0 * Q) * S
        c = min(S, cnts[j] - b0)
        if c <= 0:
            continue
        t0 = ring[k0 % R]
        t1 = ring[(k0 + st) % R]
        t2 = ring[(k0 + 2 * st) % R]
        t3 = ring[(k0 + 3 * st) % R] if q == 3 else t2
        sums[j] += _taps(t0, t1, t2, t3, q, c)


# ----------------------------------------------------------------------------- windows

#: Levels (m = 1 .. 2^(FUSED - 1)) that :func:`window_octave` takes in one pass over
#: cache-sized tiles of the record (the others one pass over the window each).
FUSED = 8

#: Entries per tile of the fused levels (a multiple of every run length used; two tiles
#: plus their halo stay in the L2 cache).
TILE = 1 << 14


@_jit
def _lag_pass(a, b, c3, out, q, c, nu):
    """One lag-doubling level on the lag-m views ``a = D[i]``, ``b = D[i + m]``, ``c3 =
    D[i + 2m]`` (q = 3): returns the sum over ``i < c`` of the squared second (``q = 2``:
    ``b - a``) or third (``(c3 - b) - (b - a)``) differences and writes ``D(2m)_i = a + b``
    into ``out[i]`` for ``i < nu`` (``out`` disjoint from the views). Every loop starts
    at 0 (on views): a loop from a run-time start keeps numba's negative-index check and
    is not vectorised (4x slower)."""
    k = min(c, nu)
    s = 0.0
    if q == 2:
        for i in range(k):
            ai = a[i]
            bi = b[i]
            t = bi - ai
            s += t * t
            out[i] = ai + bi
    else:
        for i in range(k):
            ai = a[i]
            bi = b[i]
            t = (c3[i] - bi) - (bi - ai)
            s += t * t
            out[i] = ai + bi
    if c > k:
        s += _diff_sumsq(a[k:c], b[k:c], c3[k:c] if q == 3 else a[k:c], q)
    if nu > k:
        _add(a[k:nu], b[k:nu], out[k:nu])
    return s


@_jit
def _diff_sumsq(a, b, c3, q):
    s = 0.0
    if q == 2:
        for i in range(a.size):
            t = b[i] - a[i]
            s += t * t
    else:
        for i in range(a.size):
            bi = b[i]
            t = (c3[i] - bi) - (bi - a[i])
            s += t * t
    return s


@_jit
def _add(a, b, out):
    for i in range(out.size):
        out[i] = a[i] + b[i]


@_jit
def _lag_inplace(a, b, c3, q, c, nu):
    """:func:`_lag_pass` writing ``D(2m)`` over ``a`` itself (``b``, ``c3`` disjoint from
    it): the same arithmetic in a loop of its own. Passing ``out = a`` to
    :func:`_lag_pass` instead makes the compiler's aliasing check fail and the loop run
    unvectorised (12.6 against 7.3 ns per sample for 20 levels, measured), and routing
    the levels above the tiles through a scratch block costs as much."""
    k = min(c, nu)
    s = 0.0
    if q == 2:
        for i in range(k):
            ai = a[i]
            bi = b[i]
            t = bi - ai
            s += t * t
            a[i] = ai + bi
    else:
        for i in range(k):
            ai = a[i]
            bi = b[i]
            t = (c3[i] - bi) - (bi - ai)
            s += t * t
            a[i] = ai + bi
    if c > k:
        s += _diff_sumsq(a[k:c], b[k:c], c3[k:c] if q == 3 else a[k:c], q)
    if nu > k:
        _add_into(a[k:nu], b[k:nu])
    return s


@_jit
def _add_into(a, b):
    for i in range(a.size):
        a[i] = a[i] + b[i]


@_jit
def _convert(ys, mean, out):
    """``out[i] = ys[i] - mean`` in float64 (a loop from 0 over slices: vectorised)."""
    for i in range(out.size):
        out[i] = np.float64(ys[i]) - mean


@_jit
def _sum(v):
    s = 0.0
    for i in range(v.size):
        s += v[i]
    return s


@_jit
def _gather(v, base, lo, hi, m, st, u, off, dec):
    """``dec[off + k] = v[st + k m - base]`` for the ``k < u - 1`` with ``lo <= st + k m <
    hi`` (the lag-m increments of the decimated points that lie in ``v``'s span)."""
    if u <= 1:
        return
    k0 = max(0, -((st - lo) // m))
    k1 = min(u - 1, -((st - hi) // m))
    for k in range(k0, k1):
        dec[off + k] = v[st + k * m - base]


@_jit
def window_octave(y, mean, d, nx, want, q, lim, own, S, runsum, r0, use, start, off, dec,
                  tiles, tmp):
    """The lag-doubling sums of one window (``nx`` angle points, ``y`` its ``nx - 1``
    rate samples) into an array per level, as :func:`inertialab.noise.statistics._fast.octave_d`
    computes them from ``d = y - mean`` (the same ``D(m)`` values, bit for bit; the sums
    in another order), with the conversion fused in:

    * levels ``0 .. FUSED - 1`` in one pass over tiles of :data:`TILE` entries (plus a halo
      of ``(q + 1) 2^(FUSED - 1)``): each tile is converted from ``y``, run through those
      levels in the cache (two tiles in ``tiles``, ping-pong) and leaves ``D(2^FUSED)`` in
      ``d``; the conversion also sums runs of ``S`` samples of the first ``own`` entries
      into ``runsum[r0 + k]`` (the angle's checkpoints);
    * the levels above on ``d`` in place, in blocks of at most m and ``tmp.size``.

    ``want``, ``lim`` (at most ``lim[l]`` summands at level l) and the gather rows
    ``(use, start, off, dec)`` as :func:`inertialab.noise.statistics._fast.octave_d`."""
    L = want.size
    sums = np.zeros(L)
    nd = nx - 1
    F = min(FUSED, L)
    H = (q + 1) << max(F - 1, 0)
    ta = tiles[0]
    tb = tiles[1]
    top = nd  # tiles cover every entry (the run sums need them all)
    outn = max(nd - ((1 << F) - 1), 0)  # entries of D(2^F)
    for t in range(0, top, TILE):
        n0 = min(TILE + H, nd - t)  # entries of the tile with its halo
        mine = min(TILE, nd - t)
        # convert (and the run sums of the entries this window owns)
        _convert(y[t:t + n0], mean, ta[:n0])
        e = min(t + mine, own)
        for p in range(t, e, S):
            runsum[r0 + p // S] = _sum(ta[p - t:min(p + S, e) - t])
        src, dst = ta, tb
        valid = n0
        m = 1
        for lev in range(F):
            if use[lev] > 0:
                _gather(src, t, t, t + mine, m, start[lev], use[lev], off[lev], dec)
            c = 0
            if want[lev]:
                c = max(0, min(min(nx - q * m, lim[lev]) - t, mine))
            nu = max(valid - m, 0)
            if c > 0 or nu > 0:
                c3 = src[2 * m:] if q == 3 else src
                sums[lev] += _lag_pass(src, src[m:], c3, dst, q, c, nu)
            valid = nu
            m *= 2
            src, dst = dst, src
        k = min(mine, max(outn - t, 0))  # D(2^F) of the tile's own entries
        d[t:t + k] = src[:k]
    m = 1 << F
    nd = outn
    B = tmp.size
    for lev in range(F, L):
        nxt = nd - m
        more = lev + 1 < L and nxt > 0
        if use[lev] > 0:
            _gather(d, 0, 0, nd, m, start[lev], use[lev], off[lev], dec)
        c = min(nx - q * m, lim[lev]) if want[lev] else 0
        c = max(c, 0)
        nu = nxt if more else 0
        blk = min(m, B)  # (a block's writes and its reads m, 2m further do not overlap)
        for b0 in range(0, max(c, nu), blk):
            n = min(blk, max(c, nu) - b0)
            ns = max(0, min(n, c - b0))
            nw = max(0, min(n, nu - b0))
            a = d[b0:b0 + n]
            c3 = d[b0 + 2 * m:b0 + 2 * m + ns] if q == 3 else a
            sums[lev] += _lag_inplace(a, d[b0 + m:b0 + m + n], c3, q, ns, nw)
        if not more:
            break
        nd = nxt
        m *= 2
    return sums
