"""The numpy lag-doubling kernels of the Allan family at octave m (the reference that
the compiled ones in :mod:`inertialab.noise.statistics._fast` reproduce; ``INERTIALAB_FAST=0`` runs
them), the summand counts, and the gathering of decimated angle points for the noise
identification.

The algorithms (one working array ``d`` of first differences of the angle, updated in
place from one octave to the next) are described in :mod:`inertialab.noise.statistics._octave`:
``E(m)`` for the non-overlapping statistics (:func:`e_sums`), ``B(m)`` for the modified
ones (:func:`b_sums`) and ``D(m)`` for the overlapping and total ones (:func:`d_sums`,
one or two octaves per pass). Reference: NIST SP 1065 (Riley 2008) §5.2.
"""

from __future__ import annotations

import numpy as np

from inertialab.noise.statistics._phase import _sumsq

#: Entries per block of the in-place updates (below L2 size; temporaries of this size).
OCT_BLOCK = 1 << 16

#: Statistics by the working array they use.
D_STATS = ("oadev", "ohdev", "totdev")
E_STATS = ("adev", "hdev")
B_STATS = ("mdev", "tdev")



def n_terms(statistic: str, nx: int, m: int) -> int:
    """Summands of ``statistic`` at m for ``nx`` angle points."""
    if statistic == "oadev":
        return nx - 2 * m
    if statistic == "adev":
        return (nx - 1) // m - 1
    if statistic == "ohdev":
        return nx - 3 * m
    if statistic == "hdev":
        return (nx - 1) // m - 2
    if statistic in ("mdev", "tdev"):
        return nx - 3 * m + 1
    return nx - 2  # totdev




def octave_sums_numpy(d: np.ndarray, statistic: str, ms, decimate: int = 0):
    """``(sums, nt, dec)`` of :func:`inertialab.noise.statistics._octave.octave_sums` by the numpy
    kernels: per m of ``ms`` (ascending powers of two) the sum of squared filter outputs
    in the unit of ``d`` squared, the summand count, and (``decimate > 0``) the central
    decimated angle points per m (a dict)."""
    nx = d.size + 1
    sums = np.zeros(len(ms))
    nt = np.array([n_terms(statistic, nx, int(m)) for m in ms], dtype=np.int64)
    pos = {int(m): k for k, m in enumerate(ms)}
    if statistic in E_STATS:
        dec = e_sums(d, statistic, pos, sums, decimate)
    elif statistic in B_STATS:
        dec = b_sums(d, pos, sums, decimate)
    else:
        dec = d_sums(d, statistic, pos, sums, decimate)
    return sums, nt, dec


def e_sums(e: np.ndarray, statistic: str, pos: dict, sums: np.ndarray, decimate: int) -> dict:
    """ADEV/HDEV: the squared second (third) differences of ``E(m)_k = x_{(k+1)m} -
    x_{km}`` (``e``, overwritten) into ``sums[pos[m]]``, then ``E(2m)_k = E(m)_{2k} +
    E(m)_{2k+1}`` in place over ascending blocks; returns the decimated points."""
    B = OCT_BLOCK
    buf, tmp = np.empty(B), np.empty(B)
    top = max(pos)
    dec = {}
    ne = e.size  # valid length of E(m): (nx - 1) // m
    m = 1
    while m <= top:
        cnt = ne - (1 if statistic == "adev" else 2)
        if m in pos and cnt >= 1:
            s = 0.0
            for b0 in range(0, cnt, B):
                b1 = min(b0 + B, cnt)
                t = buf[:b1 - b0]
                np.subtract(e[b0 + 1:b1 + 1], e[b0:b1], out=t)
                if statistic == "hdev":
                    u = tmp[:b1 - b0]
                    np.subtract(e[b0 + 2:b1 + 2], e[b0 + 1:b1 + 1], out=u)
                    np.subtract(u, t, out=t)
                s += _sumsq(t)
            sums[pos[m]] = s
            if decimate:
                dec[m] = _central_cumsum(e, ne, 1, decimate)
        h = ne // 2
        if 2 * m > top or h < 1:
            break
        for b0 in range(0, h, B):
            b1 = min(b0 + B, h)
            np.add(e[2 * b0:2 * b1:2], e[2 * b0 + 1:2 * b1:2], out=tmp[:b1 - b0])
            e[b0:b1] = tmp[:b1 - b0]
        ne = h
        m *= 2
    return dec


def b_sums(d: np.ndarray, pos: dict, sums: np.ndarray, decimate: int) -> dict:
    """MDEV/TDEV: the squared ``B_{i+m} - B_i`` of ``B(m)_i = sum_{j<m} D(m)_{i+j}``
    (``d``, the first differences at m = 1, overwritten) into ``sums[pos[m]]``, then
    ``B(2m)_i = B_i + 2 B_{i+m} + B_{i+2m}`` in place; B(m) holds no point samples, so
    the decimated points are gathered from ``d`` first."""
    nx = d.size + 1
    B = OCT_BLOCK
    buf, tmp = np.empty(B), np.empty(B)
    top = max(pos)
    dec = decimated_points(d, sorted(pos), decimate) if decimate else {}
    nb = d.size  # valid B(m) entries: nx - 2m + 1
    m = 1
    while m <= top:
        cnt = nx - 3 * m + 1
        nxt = nb - 2 * m  # valid B(2m) entries
        more = 2 * m <= top and nxt > 0
        s = 0.0
        cnt_s = cnt if m in pos else 0
        for b0 in range(0, max(cnt_s, nxt if more else 0), B):
            if b0 < cnt_s:
                b1 = min(b0 + B, cnt)
                t = buf[:b1 - b0]
                np.subtract(d[b0 + m:b1 + m], d[b0:b1], out=t)
                s += _sumsq(t)
            if more and b0 < nxt:
                b1 = min(b0 + B, nxt)
                u = tmp[:b1 - b0]
                np.add(d[b0 + m:b1 + m], d[b0 + m:b1 + m], out=u)
                u += d[b0:b1]
                u += d[b0 + 2 * m:b1 + 2 * m]
                d[b0:b1] = u
        if m in pos and cnt >= 1:
            sums[pos[m]] = s
        if not more:
            break
        nb = nxt
        m *= 2
    return dec


def d_sums(d: np.ndarray, statistic: str, pos: dict, sums: np.ndarray, decimate: int) -> dict:
    """OADEV/TOTDEV (second differences) and OHDEV (third) from ``D(m)_i = x_{i+m} -
    x_i`` (``d``, overwritten): two octaves per pass where m and 2m are both wanted and
    small (:func:`_d_two_octaves`), else one (:func:`_d_one_octave`); the larger m of
    TOTDEV have no interior summands (the caller adds the reflected ones)."""
    q = 3 if statistic == "ohdev" else 2
    work = (np.empty(OCT_BLOCK), np.empty(OCT_BLOCK), np.empty(2 * OCT_BLOCK))
    top = max(pos)
    dec = {}
    nd = d.size  # valid D(m) entries: nx - m
    m = 1
    while m <= top:
        if 2 * m in pos and 4 * q * m <= OCT_BLOCK:
            nd, more = _d_two_octaves(d, nd, m, q, pos, sums, dec, decimate, work)
            step = 4
        else:
            nd, more = _d_one_octave(d, nd, m, q, pos, sums, dec, decimate, work)
            step = 2
        if not more:
            break
        m *= step
    return dec


def _d_one_octave(d, nd, m, q, pos, sums, dec, decimate, work):
    """Level m of :func:`d_sums`: its sum and ``D(2m)_i = D(m)_i + D(m)_{i+m}`` in place
    over ascending blocks; returns ``(valid D(2m) entries, whether to go on)``."""
    nx = d.size + 1
    buf, tmp, _ = work
    B = OCT_BLOCK
    top = max(pos)
    cnt = nx - q * m
    nxt = nd - m  # valid D(2m) entries
    more = 2 * m <= top and nxt > 0
    if m in pos and decimate and cnt >= 1:
        dec[m] = _central_cumsum(d, nd, m, decimate)
    s = 0.0
    cnt_s = cnt if m in pos else 0
    for b0 in range(0, max(cnt_s, nxt if more else 0), B):
        if b0 < cnt_s:
            b1 = min(b0 + B, cnt)
            s += _sumsq(_diff_taps(d, b0, b1 - b0, m, q, buf, tmp))
        if more and b0 < nxt:
            b1 = min(b0 + B, nxt)
            np.add(d[b0:b1], d[b0 + m:b1 + m], out=d[b0:b1])
    if m in pos:
        sums[pos[m]] = s
    return nxt, more


def _d_two_octaves(d, nd, m, q, pos, sums, dec, decimate, work):
    """Levels m and 2m of :func:`d_sums` in one pass (half the memory traffic): the
    level-m sums from D(m), D(2m) of the block (plus its reach) into a buffer, the
    level-2m sums from it, then D(4m) written in place; the same operations as two
    single passes. Returns ``(valid D(4m) entries, whether to go on)``."""
    nx = d.size + 1
    buf, tmp, wbuf = work
    B = OCT_BLOCK
    top = max(pos)
    if decimate:
        if m in pos:
            dec[m] = _central_cumsum(d, nd, m, decimate)
        dec[2 * m] = _central_cumsum2(d, nd, m, decimate)
    cnt1, cnt2 = nx - q * m, nx - 2 * q * m
    nd2 = nd - m
    nd4 = nd2 - 2 * m
    more = 4 * m <= top and nd4 > 0
    c1 = cnt1 if m in pos else 0
    s1 = s2 = 0.0
    for b0 in range(0, max(c1, cnt2, nd4 if more else 0), B):
        if b0 < c1:
            b1 = min(b0 + B, cnt1)
            s1 += _sumsq(_diff_taps(d, b0, b1 - b0, m, q, buf, tmp))
        L2 = min(B, cnt2 - b0)
        L4 = min(B, nd4 - b0) if more else 0
        Lw = min(max(L2 + 2 * q * m, L4 + 2 * m), nd2 - b0)
        if Lw <= 0:
            continue
        W = wbuf[:Lw]
        np.add(d[b0:b0 + Lw], d[b0 + m:b0 + m + Lw], out=W)
        if L2 > 0:
            s2 += _sumsq(_diff_taps(W, 0, L2, 2 * m, q, buf, tmp))
        if L4 > 0:
            np.add(W[:L4], W[2 * m:2 * m + L4], out=d[b0:b0 + L4])
    if m in pos:
        sums[pos[m]] = s1
    sums[pos[2 * m]] = s2
    return nd4, more


def _diff_taps(w: np.ndarray, b0: int, L: int, m: int, q: int, buf, tmp) -> np.ndarray:
    """Second (q = 2: ``w_{i+m} - w_i``) or third (q = 3) lag-m differences of the
    increments ``w`` for i in [b0, b0 + L), into ``buf``."""
    t = buf[:L]
    np.subtract(w[b0 + m:b0 + m + L], w[b0:b0 + L], out=t)
    if q == 3:
        u = tmp[:L]
        np.subtract(w[b0 + 2 * m:b0 + 2 * m + L], w[b0 + m:b0 + m + L], out=u)
        np.subtract(u, t, out=t)
    return t


def _central_span(nx: int, lag: int, max_points: int) -> tuple[int, int]:
    """``(use, start)``: the central ``use`` (at most ``max_points``) of the angle points
    ``x_0, x_lag, ...`` of ``nx`` angle points begin at index ``start``."""
    count = (nx - 1) // lag + 1
    use = min(count, max_points)
    return use, ((count - use) // 2) * lag


def gather_indices(nx: int, ms, max_points: int) -> dict:
    """m -> indices of the central ``max_points`` (at most) decimated points at m (the
    points :func:`inertialab.noise.statistics.identify.identify_alpha` takes)."""
    out = {}
    for m in (int(v) for v in ms):
        use, start = _central_span(nx, m, max_points)
        out[m] = start + m * np.arange(use, dtype=np.int64)
    return out


def _central_cumsum2(w: np.ndarray, nvalid: int, m: int, max_points: int) -> np.ndarray:
    """:func:`_central_cumsum` at lag 2m from the lag-m increments ``w`` (``D(2m)_i =
    D(m)_i + D(m)_{i+m}``), without forming D(2m)."""
    lag = 2 * m
    use, start = _central_span(nvalid + m, lag, max_points)
    z = np.empty(use)
    z[0] = 0.0
    if use > 1:
        a = w[start:start + (use - 1) * lag:lag]
        b = w[start + m:start + m + (use - 1) * lag:lag]
        np.add(a, b, out=z[1:])
        np.cumsum(z[1:], out=z[1:])
    return z


def decimated_points(d: np.ndarray, ms, max_points: int, chunk: int = 1 << 16) -> dict:
    """For each m, the central ``max_points`` (at most) decimated angle points
    ``x_{start + k m} - x_start`` of the increments ``d`` (``x_0 = 0``, ``x_{i+1} = x_i +
    d_i``), gathered in one pass of chunked cumulative sums (no angle array)."""
    nx = d.size + 1
    want = gather_indices(nx, ms, max_points)
    got = {m: np.empty(idx.size) for m, idx in want.items()}
    for m, idx in want.items():  # x_0 = 0 (not produced by the chunks below)
        got[m][idx == 0] = 0.0
    prev = 0.0
    u = np.empty(min(chunk, max(d.size, 1)))
    for s in range(0, d.size, chunk):
        e = min(s + chunk, d.size)
        w = u[:e - s]
        w[:] = d[s:e]
        w[0] += prev
        np.cumsum(w, out=w)  # x_{s+1} .. x_e
        prev = float(w[-1])
        for m, idx in want.items():
            lo, hi = np.searchsorted(idx, [s + 1, e + 1])
            if hi > lo:
                got[m][lo:hi] = w[idx[lo:hi] - s - 1]
    return {m: got[m] - got[m][0] for m in ms}


def _central_cumsum(w: np.ndarray, nvalid: int, m: int, max_points: int) -> np.ndarray:
    """Central decimated angle points (up to a constant) from lag-m increments ``w``
    (``w_i = x_{i+m} - x_i``, ``nvalid`` entries): ``x_{start + k m} - x_start``."""
    use, start = _central_span(nvalid + m, m, max_points)
    z = np.empty(use)
    z[0] = 0.0
    if use > 1:
        np.cumsum(w[start:start + (use - 1) * m:m], out=z[1:])
    return z


