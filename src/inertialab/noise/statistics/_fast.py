"""Compiled kernels of the Allan family (optional ``[fast]`` extra, numba).

The numpy paths (:mod:`inertialab.noise.statistics._octave`, :mod:`inertialab.noise.statistics.identify`,
:mod:`inertialab.noise.statistics.edf`) stay the reference and the fallback; these kernels compute
the same quantities with the same difference formulas in one fused loop per octave or
per tau (no temporaries, no per-block Python calls), so results differ from numpy only in
the order of summation (tested to 1e-12 relative, ``tests/noise/test_fast.py``).

Use is decided by :func:`inertialab.noise.statistics._octave.fast_kernels`: this module when numba
imports and ``INERTIALAB_FAST`` is not ``0``, else None (numpy). Every kernel is compiled
once per machine (``cache=True``: numba's cache beside this file, or in
``NUMBA_CACHE_DIR``); a fresh process loads the cache. The kernels allocate nothing of
the record's size (their work arrays come from the caller, so ``tracemalloc`` sees them).

Floating-point reductions are compiled with ``fastmath={"reassoc", "contract"}`` so that
the compiler may vectorise them (re-association and fused multiply-adds only; NaN and
infinity semantics are kept). The per-m kernels, the Greenhall EDF and the kernels that
call no other (``octave_b``, ``gather_increments``, ``combine_taps``) live in
:mod:`inertialab.noise.statistics._fast_any` and the B1/R(n) identification in
:mod:`inertialab.noise.statistics._fast_ident` (both re-exported here); no kernel calls one in another
module (numba's cache tracks only a kernel's own file).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from inertialab.noise.statistics._fast_any import (  # noqa: F401 - part of this module's interface
    combine_taps,
    dense_mod,
    dense_overlap,
    dense_strided,
    dense_totdev,
    gather_increments,
    greenhall_many,
    octave_b,
)
from inertialab.noise.statistics._fast_ident import (  # noqa: F401 - part of this module's interface
    b1_rn_rows,
    finish_identification,
)

_jit = nb.njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})


# ----------------------------------------------------------------------------- octave


@_jit
def octave_d(d, nx, want, q, dec_use, dec_start, dec_off, dec, tmp, acf, lim):
    """Lag-doubling sums of OADEV/TOTDEV (``q = 2``) or OHDEV (``q = 3``) over the
    working array ``d`` of first differences (overwritten): level l (m = 2^l) sums the
    squared second (third) lag-m differences of ``D(m)``, then ``D(2m)_i = D(m)_i +
    D(m)_{i+m}``, in the same loop over blocks of ``tmp.size`` entries (the block's new
    values go to ``tmp`` first: later blocks read only entries not yet updated).
    ``dec_use[l] > 0`` gathers the increments ``x_{s + (k+1) m} - x_{s + k m}`` (``k <
    dec_use[l] - 1``, ``s = dec_start[l]``) of the central decimated points into
    ``dec[dec_off[l]:]`` (the frequency averages the noise identification tests; no
    running sum, which is latency-bound: ~4 ns a point). Rows of at least ``acf.min``
    frequency averages are instead tested in place (:func:`_acf_level`) and not
    gathered. At most ``lim[l]`` summands are taken at level l (the out-of-core path
    runs the kernel on windows of the record, each contributing its own summands)."""
    L = want.size
    sums = np.zeros(L)
    nd = d.size
    B = tmp.size
    m = 1
    # the lag-1 rows as a chain: from the first level whose row is the whole decimated
    # record, each next row is made from the last (phase: every other point; frequency
    # averages: sums of neighbours, D(2m)_{2km} = D(m)_{2km} + D(m)_{2km+m}, the
    # kernel's own addition) in a contiguous buffer, instead of strided reads of the
    # record at every level (one cache line per point from m = 8)
    phase = acf[4].size > 1
    chain = np.empty(dec_use.max() if acf[2] > 0 and dec_use.size else 0)
    cn = 0
    for lev in range(L):
        cnt = nx - q * m
        nxt = nd - m
        more = lev + 1 < L and nxt > 0
        if cn > 0:  # this level's row from the last one
            cn = _halve_row(chain, cn, phase)
        u = dec_use[lev]
        if u > 0:
            o = dec_off[lev]
            st = dec_start[lev]
            if cn == 0 and st == 0 and u == (nx - 1) // m + 1 and chain.size >= u:
                cn = _start_row(chain, acf[4] if phase else d, u if phase else u - 1, m)
            if cn > 0 and cn == (u if phase else u - 1):
                if not _acf_row(chain[:cn], lev, acf) and not phase:
                    dec[o:o + u - 1] = chain[:u - 1]
            elif not _acf_level(d, st, m, u - 1, lev, acf):
                dec[o:o + u - 1] = d[st:st + (u - 1) * m:m]  # (a slice copy: vectorised)
        c = min(cnt, lim[lev]) if (want[lev] and cnt >= 1) else 0
        s = 0.0
        top = max(c, nxt if more else 0)
        if m >= 128:  # blocks of at most m: D(2m) written in place (no overlap, vectorised)
            s = _level_inplace(d, m, q, c, nxt if more else 0, min(m, B))
            top = 0
        for b0 in range(0, top, B):
            n = min(B, top - b0)
            ns = max(0, min(n, c - b0))  # summands in this block
            nu = max(0, min(n, nxt - b0)) if more else 0  # updates in this block
            a = d[b0:b0 + n]
            b = d[b0 + m:b0 + m + n]
            if q == 2:
                if nu == ns:
                    for i in range(ns):
                        ai = a[i]
                        bi = b[i]
                        t = bi - ai
                        s += t * t
                        tmp[i] = ai + bi
                else:
                    for i in range(ns):
                        t = b[i] - a[i]
                        s += t * t
                    for i in range(nu):
                        tmp[i] = a[i] + b[i]
            else:
                if ns > 0:
                    cc = d[b0 + 2 * m:b0 + 2 * m + ns]
                    for i in range(ns):
                        bi = b[i]
                        t = (cc[i] - bi) - (bi - a[i])
                        s += t * t
                for i in range(nu):
                    tmp[i] = a[i] + b[i]
            for i in range(nu):
                a[i] = tmp[i]
        sums[lev] = s
        if not more:
            break
        nd = nxt
        m *= 2
    return sums


@_jit
def _start_row(chain, v, n, m):
    """Copy ``v[j m]``, ``j < n``, to ``chain`` (the first row of :func:`octave_d`'s
    chain); its length."""
    chain[:n] = v[0:(n - 1) * m + 1:m]
    return n


@_jit
def _halve_row(chain, n, phase):
    """The next level's row of :func:`octave_d`'s chain in place: phase points
    ``chain[2j]`` (``(n - 1) // 2 + 1`` of them) or frequency averages ``chain[2j] +
    chain[2j + 1]`` (``n // 2``); its length."""
    if phase:
        h = (n - 1) // 2 + 1
        for j in range(1, h):
            chain[j] = chain[2 * j]
    else:
        h = n // 2
        for j in range(h):
            chain[j] = chain[2 * j] + chain[2 * j + 1]
    return h


@_jit
def _acf_row(row, lev, acf):
    """:func:`_acf_level` of a contiguous row (the chain's): phase points or frequency
    averages; True if taken."""
    out, dmax, mn, buf, x = acf
    if mn <= 0 or row.size < mn:
        return False
    out[lev] = _lag1_contiguous(row, buf, dmax, 2 if x.size > 1 else 0)
    return True


@_jit
def _acf_level(v, st, step, count, lev, acf):
    """The lag-1 test of level ``lev`` into ``acf.out[lev]``; True if taken. ``acf =
    (out, dmax, min, buf, x)`` (built by :func:`inertialab.noise.statistics._octave.octave_sums`;
    ``min`` 0: never). Frequency data (``x`` empty): :func:`lag1_strided` with ``theta =
    0`` on the ``count`` increments ``v[st + j step]`` themselves, where ``count >=
    min``. Phase data: on the ``count + 1`` points ``x[st + j step]`` of the angle
    ``x`` (``theta = 2``), where ``count + 1 >= min``."""
    out, dmax, mn, buf, x = acf
    phase = x.size > 1
    n = count + 1 if phase else count
    if mn <= 0 or n < mn:
        return False
    one = np.empty(1)
    lag1_strided(x if phase else v, np.full(1, st, dtype=np.int64),
                 np.full(1, step, dtype=np.int64), np.full(1, n, dtype=np.int64), dmax, one,
                 buf, 2 if phase else 0, False)
    out[lev] = one[0]
    return True


@_jit
def _level_inplace(d, m, q, c, nu, blk):
    """One level of :func:`octave_d` for m >= ``blk``: the sum of the squared second
    (``q = 2``) or third (3) lag-m differences of the first ``c`` entries and ``D(2m)_i =
    D(m)_i + D(m)_{i+m}`` written in place over the first ``nu``, in blocks of ``blk``
    entries (a block and the entries it reads, m and 2m further, do not overlap)."""
    s = 0.0
    for b0 in range(0, max(c, nu), blk):
        n = min(blk, max(c, nu) - b0)
        ns = max(0, min(n, c - b0))
        nw = max(0, min(n, nu - b0))
        a = d[b0:b0 + n]
        b = d[b0 + m:b0 + m + n]
        if q == 2:
            k = min(ns, nw)
            for i in range(k):
                ai = a[i]
                bi = b[i]
                t = bi - ai
                s += t * t
                a[i] = ai + bi
            for i in range(k, ns):
                t = b[i] - a[i]
                s += t * t
        else:
            k = min(ns, nw)
            if ns > 0:
                cc = d[b0 + 2 * m:b0 + 2 * m + ns]
                for i in range(k):
                    ai = a[i]
                    bi = b[i]
                    t = (cc[i] - bi) - (bi - ai)
                    s += t * t
                    a[i] = ai + bi
                for i in range(k, ns):
                    bi = b[i]
                    t = (cc[i] - bi) - (bi - a[i])
                    s += t * t
        for i in range(k, nw):
            a[i] = a[i] + b[i]
    return s


@_jit
def octave_e(e, want, hdev, dec_use, dec_start, dec_off, dec, acf):
    """Non-overlapping ADEV (``hdev`` False) / HDEV sums at m = 2^l from ``E(m)_k =
    x_{(k+1)m} - x_{km}`` (``e``, overwritten): the squared second (third) differences of
    E(m), then ``E(2m)_k = E(m)_{2k} + E(m)_{2k+1}`` in place; decimated increments as
    :func:`octave_d` (at stride 1 of E)."""
    L = want.size
    sums = np.zeros(L)
    ne = e.size
    for lev in range(L):
        cnt = ne - (2 if hdev else 1)
        if want[lev] and cnt >= 1:
            s = 0.0
            if hdev:
                for i in range(cnt):
                    b = e[i + 1]
                    t = (e[i + 2] - b) - (b - e[i])
                    s += t * t
            else:
                for i in range(cnt):
                    t = e[i + 1] - e[i]
                    s += t * t
            sums[lev] = s
        u = dec_use[lev]
        if u > 0:
            o = dec_off[lev]
            st = dec_start[lev]
            if not _acf_level(e, st, 1, u - 1, lev, acf):
                dec[o:o + u - 1] = e[st:st + u - 1]
        h = ne // 2
        if lev + 1 >= L or h < 1:
            break
        for k in range(h):
            e[k] = e[2 * k] + e[2 * k + 1]
        ne = h
    return sums


@_jit
def _level_pairs(v, n, order, out):
    """One level of :func:`octave_strided`: the sum of the squared second (``order = 2``)
    or third (3) differences of ``v[:n]`` (``v_j = x_{jm}``), and ``out[j] = v_{2j}``
    (the next level's points, ``(n - 1) // 2 + 1`` of them), in one pass over the pairs
    ``(v_{2j}, v_{2j+1})``: a loop that reads both members of a pair is vectorised by the
    compiler (15 us for the 1e5 points of level 0 with the compaction; a loop over the
    even points alone, stride 2, is scalar and 3x slower)."""
    c = max(n - order, 0)
    J = c // 2
    s = 0.0
    if order == 2:
        for j in range(J):
            i = 2 * j
            e0 = v[i]
            o0 = v[i + 1]
            e1 = v[i + 2]
            o1 = v[i + 3]
            t0 = (e1 - o0) - (o0 - e0)
            t1 = (o1 - e1) - (e1 - o0)
            s += t0 * t0 + t1 * t1
            out[j] = e0
        for i in range(2 * J, c):
            b = v[i + 1]
            t = (v[i + 2] - b) - (b - v[i])
            s += t * t
    else:
        for j in range(J):
            i = 2 * j
            e0 = v[i]
            o0 = v[i + 1]
            e1 = v[i + 2]
            o1 = v[i + 3]
            e2 = v[i + 4]
            t0 = ((o1 - e1) - (e1 - o0)) - ((e1 - o0) - (o0 - e0))
            t1 = ((e2 - o1) - (o1 - e1)) - ((o1 - e1) - (e1 - o0))
            s += t0 * t0 + t1 * t1
            out[j] = e0
        for i in range(2 * J, c):
            a1 = v[i + 1]
            a2 = v[i + 2]
            t = ((v[i + 3] - a2) - (a2 - a1)) - ((a2 - a1) - (a1 - v[i]))
            s += t * t
    for j in range(J, (n - 1) // 2 + 1):
        out[j] = v[2 * j]
    return s


@_jit
def octave_strided(x, want, order, w, id_use, id_start, idp, alphas, best, buf):
    """ADEV (``order = 2``) / HDEV (3) sums at m = 2^l of the angle ``x`` itself: level 0
    from ``x``, then each level's points ``x_{k m}`` compacted from the last level's by
    :func:`_level_pairs` in the same pass as the level's sum, alternately into the two
    halves of ``w`` (``(x.size - 1) // 2 + 1`` and ``(x.size - 1) // 4 + 1`` entries;
    the caller sizes ``w`` so, no bounds checks here); every level reads contiguous
    memory. Where ``id_use[l] > 0`` the noise type of level l is identified by the lag-1
    test (:func:`identify_rows`, ``idp = (dmax, min_points, lo, hi)``) from its central
    ``id_use[l]`` points, which start at ``x_{id_start[l] m}``, read in place:
    ``alphas[l]``, ``best[l]``."""
    L = want.size
    sums = np.zeros(L)
    n1 = (x.size - 1) // 2 + 1
    halves = (w[:n1], w[n1:])
    one = np.ones(1, dtype=np.int64)
    v = x
    n = x.size
    for lev in range(L):
        if id_use[lev] > 0:
            identify_rows(v, id_start[lev:lev + 1], one, id_use[lev:lev + 1], idp[0], idp[1],
                          idp[2], idp[3], alphas[lev:lev + 1], best[lev:lev + 1], buf)
        if lev + 1 < L:
            out = halves[lev % 2]
            s = _level_pairs(v, n, order, out)
            v = out
            n = (n - 1) // 2 + 1
        else:
            s = _level_sum(v, n, order)
        if want[lev]:
            sums[lev] = s
    return sums


@_jit
def _level_sum(v, n, order):
    """The last level of :func:`octave_strided`: its sum alone (no compaction)."""
    s = 0.0
    if order == 2:
        c = n - 2
        if c > 0:
            v0 = v[:c]
            v1 = v[1:c + 1]
            v2 = v[2:c + 2]
            for i in range(c):
                b = v1[i]
                t = (v2[i] - b) - (b - v0[i])
                s += t * t
    else:
        c = n - 3
        if c > 0:
            v0 = v[:c]
            v1 = v[1:c + 1]
            v2 = v[2:c + 2]
            v3 = v[3:c + 3]
            for i in range(c):
                a1 = v1[i]
                a2 = v2[i]
                t = ((v3[i] - a2) - (a2 - a1)) - ((a2 - a1) - (a1 - v0[i]))
                s += t * t
    return s


# ----------------------------------------------------------------------------- noise type


@_jit
def _lag1_rounds(buf, n, tot, d, dmax, theta):
    """The rounds of :func:`lag1_strided` from round ``d`` on the row ``buf[:n]`` (sum
    ``tot``): per round one pass for the lag-0 and lag-1 sums of the centred row, its
    differences (in place) and their sum (used if the round goes on); the alpha."""
    while True:
        mean = tot / n
        den = 0.0
        r1 = 0.0
        tot = 0.0
        for j in range(n - 1):
            b0 = buf[j]
            b1 = buf[j + 1]
            c0 = b0 - mean
            den += c0 * c0
            r1 += c0 * (b1 - mean)
            v = b1 - b0
            buf[j] = v
            tot += v
        c0 = buf[n - 1] - mean
        den += c0 * c0
        r1 = r1 / den * ((n - 1) / n) if den > 0 else 0.0
        delta = r1 / (1.0 + r1)
        if delta < 0.25 or d >= dmax or n < 4:
            return -2.0 * (delta + d) + theta
        n -= 1
        d += 1


@_jit
def lag1_strided(x, starts, steps, counts, dmax, out, buf, theta=2, diff=True):
    """Unrounded lag-1 ACF alpha (SP 1065 §5.6.6) of the rows ``x[s + j p]``, ``j <
    count``, the algorithm of :func:`inertialab.noise.statistics.identify.lag1_alpha` (``r1`` with
    Stable32's ``(n - 1)/n`` factor; ``buf``: scratch of the largest count): ``theta = 2``
    phase rows; ``theta = 0`` the rows' first differences (frequency averages) are tested,
    or with ``diff=False`` the rows themselves (they hold the frequency averages).
    A contiguous row is tested in place (:func:`_lag1_contiguous`); a strided row is
    copied to ``buf`` (a slice copy), frequency rows as their differences, then
    :func:`_lag1_rounds`."""
    for r in range(starts.size):
        n = counts[r]
        st = starts[r]
        sp = steps[r]
        if theta == 0 and diff:  # frequency data: the m-averages (phase row differences)
            tot = 0.0
            for j in range(n - 1):
                v = x[st + (j + 1) * sp] - x[st + j * sp]
                buf[j] = v
                tot += v
            out[r] = _lag1_rounds(buf, n - 1, tot, 0, dmax, theta)
        elif sp == 1:
            out[r] = _lag1_contiguous(x[st:st + n], buf, dmax, theta)
        else:
            buf[:n] = x[st:st + (n - 1) * sp + 1:sp]  # (a slice copy: vectorised)
            tot = 0.0
            for j in range(n):
                tot += buf[j]
            out[r] = _lag1_rounds(buf, n, tot, 0, dmax, theta)


#: Longest row whose first lag-1 round :func:`_lag1_contiguous` takes in one pass.
ONE_PASS_MAX = 1 << 20


@_jit
def _lag1_contiguous(v, buf, dmax, theta):
    """:func:`lag1_strided` of one contiguous row ``v``: the first round read-only, in one
    pass for rows up to ``ONE_PASS_MAX`` points (the sums of ``y = v - c``, ``y^2`` and
    ``y_j y_{j+1}``, ``c`` the median of the first, middle and last points, give the
    centred lag-0 and lag-1 sums; ``c`` being a point of the row, ``n (mean - c)^2`` is at
    most n times the centred sum, so their relative error stays below ~n 1e-16; two
    passes beyond), the row's differences to ``buf`` only when it needs differencing."""
    n = v.size
    a = v[:n - 1]
    b = v[1:]
    last = v[n - 1]
    p, q = v[0], v[n // 2]
    c = max(min(p, q), min(max(p, q), last))
    s1 = 0.0
    s2 = 0.0
    s11 = 0.0
    for j in range(n - 1):
        y0 = a[j] - c
        s1 += y0
        s2 += y0 * y0
        s11 += y0 * (b[j] - c)
    yl = last - c
    s1 += yl
    s2 += yl * yl
    mean = s1 / n
    den = s2 - s1 * mean
    if n <= ONE_PASS_MAX:
        r1 = s11 - mean * (2.0 * s1 - (v[0] - c) - yl) + (n - 1) * mean * mean
    else:  # two passes: the mean, then the centred sums
        mean = (s1 / n) + c
        den = 0.0
        r1 = 0.0
        for j in range(n - 1):
            c0 = a[j] - mean
            den += c0 * c0
            r1 += c0 * (b[j] - mean)
        c0 = last - mean
        den += c0 * c0
    r1 = r1 / den * ((n - 1) / n) if den > 0 else 0.0
    delta = r1 / (1.0 + r1)
    if delta < 0.25 or dmax <= 0 or n < 4:
        return -2.0 * delta + theta
    tot = 0.0
    for j in range(n - 1):
        t = b[j] - a[j]
        buf[j] = t
        tot += t
    return _lag1_rounds(buf, n - 1, tot, 1, dmax, theta)


@_jit
def identify_rows(x, starts, steps, counts, dmax, min_points, lo, hi, alphas, best, buf):
    """Noise type per row by the lag-1 ACF (the rule of :func:`inertialab.noise.statistics.identify.
    identify_alpha` for rows of at least ``min_points`` points; rounded, clipped to [lo,
    hi]; ``best = -2``); shorter rows are left to the caller (B1 and R(n) at the
    statistic's summand count: :func:`inertialab.noise.statistics._fast_ident.finish_identification`)."""
    one = np.empty(1)
    for r in range(starts.size):
        if counts[r] >= min_points:
            lag1_strided(x, starts[r:r + 1], steps[r:r + 1], counts[r:r + 1], dmax, one, buf, 2)
            alphas[r] = min(max(int(np.rint(one[0])), lo), hi)
            best[r] = -2
