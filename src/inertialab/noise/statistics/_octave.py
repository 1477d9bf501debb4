"""Lag-doubling kernels of the Allan family at octave averaging factors m = 1, 2, 4, ...
.

Every statistic is computed from one float64 working array ``d`` of first differences of
the angle (phase), ``d_i = x_{i+1} - x_i`` (for rate input ``y_i - mean``, the same up to
the factor tau0), updated in place from one octave to the next, so the extra memory is
one copy of the input and no statistic re-reads the record from scratch per tau:

* overlapping Allan / Hadamard / total (``oadev ohdev totdev``): ``D(m)_i = x_{i+m} - x_i``;
  the second difference at m is ``D_{i+m} - D_i``, the third ``D_{i+2m} - 2 D_{i+m} + D_i``,
  and ``D(2m)_i = D(m)_i + D(m)_{i+m}`` (one pass per octave; the overlapping sums have
  ``N - 2m`` summands, so O(N) per octave is their floor).
* non-overlapping Allan / Hadamard (``adev hdev``): only the points ``x_{km}`` matter, so
  ``E(m)_k = D(m)_{km}`` is kept and ``E(2m)_k = E(m)_{2k} + E(m)_{2k+1}`` (pairwise sums:
  O(N/m) per octave, O(2N) in all).
* modified Allan / time deviation (``mdev tdev``): ``B(m)_i = sum_{j<m} D(m)_{i+j}``; the
  m-average of the second differences at m is ``B_{i+m} - B_i`` and ``B(2m)_i = B_i +
  2 B_{i+m} + B_{i+2m}`` (one pass per octave, no cumulative sum of the whole record).
* total deviation: the summands whose centre is at least m from both ends are the
  overlapping Allan ones (returned here); the ``2(m-1)`` others reach into the reflected
  extension and are added by the caller from the first and last 2m angle points
  (:func:`totdev_edge_sum`, after the working array is freed), so the 3N-point extension
  is never built.

Updates run over ascending blocks of ``OCT_BLOCK`` entries; a block's results are read
before they are written and later blocks read only entries not yet updated. The sums are
taken in ``BLOCK``-sized dot products (single-threaded BLAS, see
:data:`inertialab.noise.statistics._phase.BLOCK`). Returned sums are in the unit of ``d`` squared;
:mod:`inertialab.noise.statistics.allan` applies tau. With numba installed (the ``[fast]`` extra)
the same algorithms run compiled (:func:`fast_kernels`; ``INERTIALAB_FAST=0`` keeps
these numpy ones, the reference).
"""

from __future__ import annotations

import os

import numpy as np

from inertialab.noise.statistics._octave_numpy import (  # noqa: F401 - this module's interface too
    B_STATS,
    D_STATS,
    E_STATS,
    OCT_BLOCK,
    gather_indices,
    n_terms,
    octave_sums_numpy,
)
from inertialab.noise.statistics._phase import _sumsq

_FAST = None  # the compiled-kernel module once imported; False: unavailable


def fast_kernels():
    """The compiled kernels (:mod:`inertialab.noise.statistics._fast`, the ``[fast]`` extra) or None.

    None when the environment variable ``INERTIALAB_FAST`` is ``0`` (read at every call,
    so it can be switched at run time) or numba does not import; then every statistic
    runs on the numpy kernels of this module, which give the same numbers to ~1e-12
   . The first use in a process imports numba (~0.3 s) and loads the
    kernels from numba's cache (compiled once per machine: a few seconds)."""
    global _FAST
    if os.environ.get("INERTIALAB_FAST", "1").strip() == "0":
        return None
    if _FAST is None:
        try:
            from inertialab.noise.statistics import _fast
        except ImportError:  # numba not installed: numpy kernels
            _FAST = False
        else:
            _FAST = _fast
    return _FAST or None


class Decimated:
    """Decimated angle points per m, all in one flat array: the row of ``ms[r]`` is
    ``flat[offs[r]:offs[r] + uses[r]]`` (built by the compiled octave kernels, so that
    the compiled identification reads them without per-tau Python work). Offers the
    mapping interface (``get``, ``in``, ``[m]``) the numpy identification uses.

    With ``increments=True`` a row holds the ``uses[r] - 1`` increments of its points
    (the frequency averages at m, what the lag-1 test of a rate record reads); ``[m]``
    then returns the points ``0, cumsum(increments)`` (the running sum the kernels
    would have formed, in the same order: equal bit for bit)."""

    def __init__(self, ms, uses, offs, flat, increments: bool = False):
        self.ms, self.uses, self.offs, self.flat = ms, uses, offs, flat
        self.increments = increments
        self._row = {int(m): r for r, m in enumerate(ms)}
        self.acf = None  # (done, alpha) per m where the kernel took the lag-1 test
        self.skip = set()  # m whose rows were not gathered (tested in place)

    def __len__(self) -> int:
        return len(self._row)

    def __contains__(self, m) -> bool:
        return int(m) in self._row and int(m) not in self.skip

    def __getitem__(self, m) -> np.ndarray:
        r = self._row[int(m)]
        row = self.flat[self.offs[r]:self.offs[r] + self.uses[r]]
        if not self.increments:
            return row
        z = np.empty(row.size)
        z[0] = 0.0
        np.cumsum(row[:-1], out=z[1:])
        return z

    def get(self, m, default=None):
        return self[m] if m in self else default

    def rows(self, ms: np.ndarray):
        """``(offsets, uses)`` of the rows of ``ms`` (int64 arrays), or None where one of
        them is missing."""
        r = np.searchsorted(self.ms, ms)  # (ms ascending, as the kernels take them)
        if np.any(r >= self.ms.size) or not np.array_equal(self.ms[np.minimum(
                r, self.ms.size - 1)], ms) or any(int(m) in self.skip for m in ms):
            return None
        return self.offs[r], self.uses[r]


def _decimated_layout(nx: int, ms: np.ndarray, max_points: int, tested=None):
    """``(uses, starts, offs, flat)`` of :class:`Decimated` rows for the m of ``ms``
    (:func:`inertialab.noise.statistics._octave_numpy._central_span` of each, vectorised; starts in
    angle-point units); rows marked in ``tested`` (a kernel takes their lag-1 test in
    place) get no room in ``flat``."""
    count = (nx - 1) // ms + 1
    uses = np.minimum(count, max_points)
    starts = ((count - uses) // 2) * ms
    room = uses if tested is None else np.where(tested, 0, uses)
    offs = np.zeros(ms.size, dtype=np.int64)
    offs[1:] = np.cumsum(room)[:-1]
    return uses, starts, offs, np.empty(max(int(room.sum()), 1))


def is_octave(ms: np.ndarray) -> bool:
    """True when every m is a power of two (the lag-doubling kernels apply)."""
    ms = np.asarray(ms)
    if ms.size <= 64:  # a tau grid: a loop over Python ints is 5x cheaper than numpy here
        return ms.size > 0 and all(v >= 1 and v & (v - 1) == 0 for v in ms.tolist())
    return bool(np.all(ms >= 1) and np.all((ms & (ms - 1)) == 0))


def n_terms_many(statistic: str, nx: int, ms: np.ndarray) -> np.ndarray:
    """:func:`n_terms` of every m of ``ms`` (int64 array)."""
    ms = np.asarray(ms, dtype=np.int64)
    if statistic == "oadev":
        return nx - 2 * ms
    if statistic == "adev":
        return (nx - 1) // ms - 1
    if statistic == "ohdev":
        return nx - 3 * ms
    if statistic == "hdev":
        return (nx - 1) // ms - 2
    if statistic in ("mdev", "tdev"):
        return nx - 3 * ms + 1
    return np.full(ms.size, nx - 2, dtype=np.int64)  # totdev


def dense_sums_fast(K, x: np.ndarray, statistic: str, ms: np.ndarray) -> np.ndarray:
    """The sums of :func:`dense_sums` by the compiled kernels (``K``), one loop per m."""
    x = np.asarray(x, dtype=np.float64)
    if statistic in E_STATS:
        order = 2 if statistic == "adev" else 3
        if is_octave(ms) and ms.size > 1:  # contiguous halvings (half a copy)
            return octave_strided_sums(K, x, statistic, ms)[0]
        return K.dense_strided(x, ms, order)
    if statistic == "totdev":
        return K.dense_totdev(x, ms, True)
    if statistic in ("oadev", "ohdev"):
        return K.dense_overlap(x, ms, 2 if statistic == "oadev" else 3)
    return K.dense_mod(x, ms, MOD_RESTART, np.empty(FAST_BLOCK), np.empty(ms.size))


def octave_strided_sums(K, x: np.ndarray, statistic: str, ms: np.ndarray,
                        rules=None, max_points: int = 0):
    """ADEV/HDEV sums at octave ``ms`` of the in-memory angle ``x`` by the compiled
    halving kernel and the summand counts; with ``rules = (dmax, min_points, lo, hi)``
    also each m's noise type from its central ``max_points`` decimated points, read in
    place from the level's contiguous copy (strided reads of a large record miss the
    cache at every point): ``(alphas, best)`` as :func:`inertialab.noise.statistics._fast.
    identify_rows` gives them (lag-1 rows only), else None."""
    ms = np.asarray(ms, dtype=np.int64)
    lev = np.log2(ms).astype(np.int64)
    L = int(lev.max()) + 1
    want = np.zeros(L, dtype=np.bool_)
    want[lev] = True
    use = np.zeros(L, dtype=np.int64)
    start = np.zeros(L, dtype=np.int64)
    alphas = np.zeros(L, dtype=np.int64)
    best = np.zeros(L, dtype=np.int64)
    if rules is not None:  # the lag-1 rows (B1's are left to the identification)
        count = (x.size - 1) // ms + 1
        u = np.minimum(count, max_points) * (count >= rules[1])
        use[lev], start[lev] = u, (count - u) // 2  # starts in units of m
    size = (x.size - 1) // 2 + 1 + (x.size - 1) // 4 + 1  # x_{2k}, x_{4k}, ... alternately
    sums = K.octave_strided(x, want, 2 if statistic == "adev" else 3, np.empty(size), use, start,
                            np.asarray(rules if rules is not None else (0, 0, 0, 0),
                                       dtype=np.int64),
                            alphas, best, np.empty(max(int(use.max()), 1)))
    ident = (alphas[lev], best[lev]) if rules is not None else None
    return sums[lev], n_terms_many(statistic, x.size, ms), ident


#: Block (entries) of the compiled lag-doubling updates (their scratch buffer).
FAST_BLOCK = 4096

#: Stride of the coarse angle the compiled gather of decimated points reads (a 1/256
#: copy: at 1/16 it made MDEV/TDEV of a rate record 1.07x the input, over the bound
#: of one copy of extra memory; m below it sum their increments, at most 8192 x 255 additions).
GATHER_STRIDE = 256

#: Summands between recomputations of the running modified sum (compiled kernel).
MOD_RESTART = 4096


def octave_sums(d: np.ndarray, statistic: str, ms: np.ndarray, *, decimate: int = 0,
                acf: tuple | None = None, x: np.ndarray | None = None):
    """Sums of squares of ``statistic``'s filter outputs at each m of ``ms`` (powers of 2).

    Parameters
    ----------
    d : float64 ndarray, shape (nx - 1,)
        First differences of the angle; overwritten (the working array).
    statistic : str
    ms : ndarray of int
        Ascending powers of two.
    decimate : int, default 0
        When > 0, also return per m the central ``decimate`` (at most) decimated angle
        points ``x_{start + k m}`` (up to a constant) for the noise identification,
        gathered from ``D(m)``/``E(m)`` (not for mdev/tdev: empty dict).
    acf : (dmax, min_points) or None
        With ``decimate`` and the compiled kernels (not mdev/tdev): rows of at least
        ``min_points`` frequency averages (the increments of the decimated points) get
        the lag-1 noise test (frequency data, at most ``dmax`` differencing rounds) in
        place instead of being gathered; ``dec.acf = (done, alpha)`` per m of ``ms``
        (rounded, unclipped alpha), and ``m in dec`` is False for those rows.
    x : float64 ndarray, shape (nx,), optional
        The angle itself (phase data): with ``acf`` the lag-1 test reads its central
        decimated points at stride m (``theta = 2``) instead, and no row is gathered
        (``m in dec`` is False for every m; the shorter rows are read from ``x``).

    Returns
    -------
    sums : ndarray, shape (k,)
    nt : ndarray of int, shape (k,)
    dec : dict m -> ndarray
    """
    K = fast_kernels()
    if K is not None:
        return _octave_sums_fast(K, d, statistic, ms, decimate, acf, x)
    return octave_sums_numpy(d, statistic, ms, decimate)


def _octave_sums_fast(K, d, statistic, ms, decimate, acf=None, x=None):
    """:func:`octave_sums` by the compiled kernels (one fused loop per octave)."""
    nx = d.size + 1
    ms = np.asarray(ms, dtype=np.int64)
    levels = np.log2(ms).astype(np.int64)
    L = int(levels.max()) + 1
    want = np.zeros(L, dtype=np.bool_)
    want[levels] = True
    nt = n_terms_many(statistic, nx, ms)
    use = np.zeros(L, dtype=np.int64)
    start = np.zeros(L, dtype=np.int64)
    off = np.zeros(L, dtype=np.int64)
    flat = np.empty(1)
    dec = {}
    test = decimate and acf is not None and statistic not in B_STATS
    if decimate:
        tested = None
        if test and int(acf[1]) > 0:  # the kernels' own test (phase: points; else averages)
            count = (nx - 1) // ms + 1
            tested = np.minimum(count, decimate) - (0 if x is not None else 1) >= int(acf[1])
        u, st, o, flat = _decimated_layout(nx, ms, decimate, tested)
        use[levels], start[levels], off[levels] = u, st, o
        # the D/E kernels gather increments (no running sum); the B one points
        dec = Decimated(ms, u, o, flat, increments=statistic not in B_STATS)
    out = np.full(L, np.nan)
    acf_args = (out, int(acf[0]) if test else 0, int(acf[1]) if test else 0,
                np.empty(int(use.max()) if test else 1),
                x if (test and x is not None) else np.empty(1))
    if statistic in E_STATS:
        ustart = start // (1 << np.arange(L))  # in units of E(m)
        lev_sums = K.octave_e(d, want, statistic == "hdev", use, ustart, off, flat, acf_args)
    elif statistic in B_STATS:
        if decimate:
            g = GATHER_STRIDE
            K.gather_increments(d, 1 << np.arange(L, dtype=np.int64), start, use, off, flat,
                                np.empty(d.size // g + 1), g)
        lev_sums = K.octave_b(d, nx, want, np.empty(FAST_BLOCK))
    else:
        q = 3 if statistic == "ohdev" else 2
        lev_sums = K.octave_d(d, nx, want, q, use, start, off, flat, np.empty(FAST_BLOCK),
                              acf_args, np.full(L, nx, dtype=np.int64))
    if test:
        done = ~np.isnan(out[levels])
        dec.acf = (done, np.rint(np.where(done, out[levels], 0.0)).astype(np.int64))
        # (phase data: the rows left to B1 are read from the angle, none gathered)
        dec.skip = {int(m) for m in (ms if x is not None else ms[done])}
    return lev_sums[levels], nt, dec


def totdev_edge_sum(window, nx: int, m: int) -> float:
    """Sum of the squared TOTDEV summands (centre c = 1 .. nx-2, lag m) whose neighbours
    ``c - m`` or ``c + m`` fall outside 0 .. nx-1 and are taken from the reflected
    extension ``x*_{-j} = 2 x_0 - x_j``, ``x*_{nx-1+j} = 2 x_{nx-1} - x_{nx-1-j}``
    (NIST SP 1065 §5.2.11). ``window(start, length)`` returns angle points; the summands
    are taken in blocks of ``OCT_BLOCK`` centres from contiguous (reversed) windows, so
    the extension is never built and the temporaries stay block-sized."""
    x0 = float(window(0, 1)[0])
    xn = float(window(nx - 1, 1)[0])
    total = 0.0
    lo_end = min(m, nx - 1)  # left-reflected centres: 1 .. m-1
    hi_start = max(nx - m, 1)  # right-reflected centres: nx-m .. nx-2
    ranges = [(1, lo_end), (max(hi_start, lo_end), nx - 1)]
    for c0, c1 in ranges:
        cuts = sorted({c0, c1, min(max(m, c0), c1), min(max(nx - m, c0), c1)})
        for a0, b0 in zip(cuts[:-1], cuts[1:]):
            for a in range(a0, b0, OCT_BLOCK):
                total += _edge_terms(window, x0, xn, nx, m, a, min(a + OCT_BLOCK, b0))
    return total


def _edge_terms(window, x0: float, xn: float, nx: int, m: int, a: int, b: int) -> float:
    """Sum over centres c in [a, b) of ``(x*_{c-m} - 2 x_c + x*_{c+m})^2``, the centres on
    one side of both reflection points (``a < m`` iff ``b - 1 < m``, likewise for
    ``nx - 1 - m``), from contiguous (reversed) windows."""
    if b <= a:
        return 0.0
    lref, rref = a < m, b - 1 > nx - 1 - m
    v = np.multiply(window(a, b - a), -2.0)
    if lref:  # x*_{c-m} = 2 x_0 - x_{m-c}
        v -= window(m - b + 1, b - a)[::-1]
    else:
        v += window(a - m, b - a)
    if rref:  # x*_{c+m} = 2 x_{nx-1} - x_{2(nx-1)-c-m}
        q = 2 * (nx - 1) - m
        v -= window(q - b + 1, b - a)[::-1]
    else:
        v += window(a + m, b - a)
    const = (2.0 * x0 if lref else 0.0) + (2.0 * xn if rref else 0.0)
    if const:
        v += const
    return _sumsq(v)


# ----------------------------------------------------------------------------- any m


#: Largest record (angle points) for which the dense TOTDEV path builds the reflected
#: extension once (3 x 8 bytes per point, at most 6 MiB); above it the summands reaching
#: into the extension are taken from the record's ends (:func:`totdev_edge_sum`).
EXT_MAX = 1 << 18

#: Below this many points per tau the non-overlapping statistics are evaluated for all
#: averaging factors of equal point count at once (one 2-D gather).
GROUP_POINTS = 64


class _Buffers:
    """Three reused work buffers (fresh large arrays cost page faults on every
    allocation: measured 4x the arithmetic for 1e5-point second differences)."""

    def __init__(self, size: int):
        self.size = size
        self.b = [np.empty(size) for _ in range(3)]

    def get(self, k: int, n: int) -> np.ndarray:
        return self.b[k][:n] if n <= self.size else np.empty(n)


def dense_sums(x: np.ndarray, statistic: str, ms: np.ndarray, *, compiled: bool = True):
    """Sums of squares of ``statistic`` at any averaging factors ``ms`` of the in-memory
    angle ``x`` (float64), and the summand counts. Per m and block of summands: the lag-m
    increments ``D_i = x_{i+m} - x_i``, their differences at lag m (second differences;
    twice for Hadamard; a cumulative sum for the modified variance), one dot product:
    2-4 passes over the summands in reused buffers. The non-overlapping statistics use
    strided views; at large m (few points per tau) they are stacked by point count into
    2-D gathers."""
    nx = x.size
    ms = np.asarray(ms, dtype=np.int64)
    nt = n_terms_many(statistic, nx, ms)
    K = fast_kernels() if compiled else None  # (compiled=False: the numpy kernels)
    if K is not None:
        return dense_sums_fast(K, x, statistic, ms), nt
    sums = np.zeros(ms.size)
    if statistic in E_STATS:
        order = 2 if statistic == "adev" else 3
        pts = (nx - 1) // ms + 1
        small = pts < GROUP_POINTS
        bufs = _Buffers(min(nx, OCT_BLOCK) + 2)
        for k in np.flatnonzero(~small):
            sums[k] = _strided_sum(x[::int(ms[k])], order, bufs)
        ks = np.flatnonzero(small)
        for c in np.unique(pts[ks]):
            sel = ks[pts[ks] == c]
            e = x[ms[sel][:, None] * np.arange(int(c))[None, :]]
            for _ in range(order):
                e = e[:, 1:] - e[:, :-1]
            sums[sel] = np.einsum("ij,ij->i", e, e)
        return sums, nt
    if statistic == "totdev":
        if nx <= EXT_MAX:  # the extension once (at most 6 MiB), then two passes per m
            ext = np.concatenate([2.0 * x[0] - x[nx - 2:0:-1], x, 2.0 * x[-1] - x[-2:0:-1]])
            bufs = _Buffers(2 * nx)
            c0 = nx - 1  # extension index of the first centre (x_1)
            for k, m in enumerate(int(v) for v in ms):
                D = bufs.get(0, nx - 2 + m)
                np.subtract(ext[c0:c0 + nx - 2 + m], ext[c0 - m:c0 + nx - 2], out=D)
                t = bufs.get(1, nx - 2)
                np.subtract(D[m:], D[:-m], out=t)
                sums[k] = _sumsq(t)
            return sums, nt
        bufs = _Buffers(3 * OCT_BLOCK)
        for k, m in enumerate(int(v) for v in ms):
            s = _overlap_sum(x, m, 2, bufs) if nx - 2 * m > 0 else 0.0
            sums[k] = s + totdev_edge_sum(lambda a, n: x[a:a + n], nx, m)
        return sums, nt
    order = {"oadev": 2, "ohdev": 3, "mdev": 0, "tdev": 0}[statistic]
    bufs = _Buffers(min(3 * OCT_BLOCK, nx + 1))
    for k, m in enumerate(int(v) for v in ms):
        sums[k] = _overlap_sum(x, m, order, bufs) if nt[k] > 0 else 0.0
    return sums, nt


def _strided_sum(v: np.ndarray, order: int, bufs: _Buffers) -> float:
    """Sum of squared differences of order 2 or 3 of ``v`` (a strided view), in blocks."""
    cnt = v.size - order
    total = 0.0
    for b0 in range(0, cnt, OCT_BLOCK):
        L = min(OCT_BLOCK, cnt - b0)
        w = v[b0:b0 + L + order]
        e = bufs.get(0, L + order - 1)
        np.subtract(w[1:], w[:-1], out=e)
        f = bufs.get(1, L + order - 2)
        np.subtract(e[1:], e[:-1], out=f)
        if order == 3:
            g = bufs.get(2, L)
            np.subtract(f[1:], f[:-1], out=g)
            f = g
        total += _sumsq(f)
    return total


def _overlap_sum(x: np.ndarray, m: int, order: int, bufs: _Buffers) -> float:
    """Overlapping sum of squares at lag m over blocks of summands: second (order 2) or
    third (3) differences, or (order 0) the m-sums of second differences (modified).

    For m up to a block length the block's window is differenced at lag m twice (the
    increments ``D`` are shared by the taps); for larger m the taps are read at their
    offsets (no window of length m per block), and the modified sums are carried as a
    running sum ``z_{i+1} = z_i + (third difference at lag m)_i`` across blocks."""
    nx = x.size
    cnt = nx - 2 * m if order == 2 else (nx - 3 * m if order == 3 else nx - 3 * m + 1)
    reach = {2: 2 * m, 3: 3 * m, 0: 3 * m - 1}[order]
    B = OCT_BLOCK
    total = 0.0
    if m <= B:
        for b0 in range(0, cnt, B):
            L = min(B, cnt - b0)
            seg = x[b0:b0 + L + reach]
            D = bufs.get(0, seg.size - m)
            np.subtract(seg[m:], seg[:-m], out=D)
            e = bufs.get(1, D.size - m)
            np.subtract(D[m:], D[:-m], out=e)
            if order == 3:
                f = bufs.get(2, e.size - m)
                np.subtract(e[m:], e[:-m], out=f)
                e = f
            elif order == 0:  # z_i = sum_{j<m} e_{i+j} (e has L + m - 1 entries)
                cs = bufs.get(2, e.size + 1)
                cs[0] = 0.0
                np.cumsum(e, out=cs[1:])
                z = bufs.get(0, L)  # D is no longer needed
                np.subtract(cs[m:m + L], cs[:L], out=z)
                e = z
            total += _sumsq(e[:L])
        return total
    z_prev = 0.0
    if order == 0:  # z_0 = sum_{j<m} (x_{j+2m} - 2 x_{j+m} + x_j), in blocks
        for b0 in range(0, m, B):
            b1 = min(b0 + B, m)
            z_prev += float(np.sum((x[b0 + 2 * m:b1 + 2 * m] - x[b0 + m:b1 + m])
                                   - (x[b0 + m:b1 + m] - x[b0:b1])))
    for b0 in range(0, cnt, B):
        L = min(B, cnt - b0)
        u, v = bufs.get(0, L), bufs.get(1, L)
        if order == 2:
            np.subtract(x[b0 + 2 * m:b0 + 2 * m + L], x[b0 + m:b0 + m + L], out=u)
            np.subtract(x[b0 + m:b0 + m + L], x[b0:b0 + L], out=v)
            u -= v
            total += _sumsq(u)
            continue
        # third differences at lag m: (x3 - x2) - 2 (x2 - x1) + (x1 - x0)
        n3 = L if order == 3 else L - 1  # order 0: increments z_i -> z_{i+1}
        w = bufs.get(2, L)
        np.subtract(x[b0 + 3 * m:b0 + 3 * m + n3], x[b0 + 2 * m:b0 + 2 * m + n3], out=u[:n3])
        np.subtract(x[b0 + 2 * m:b0 + 2 * m + n3], x[b0 + m:b0 + m + n3], out=v[:n3])
        np.subtract(x[b0 + m:b0 + m + n3], x[b0:b0 + n3], out=w[:n3])
        u[:n3] -= v[:n3]
        u[:n3] -= v[:n3]
        u[:n3] += w[:n3]
        if order == 3:
            total += _sumsq(u)
            continue
        z = w
        z[0] = z_prev
        np.cumsum(u[:n3], out=z[1:L])
        z[1:L] += z_prev
        total += _sumsq(z[:L])
        z_prev = float(z[L - 1]) + (float(np.sum(
            (x[b0 + L - 1 + 3 * m] - x[b0 + L - 1 + 2 * m])
            - 2.0 * (x[b0 + L - 1 + 2 * m] - x[b0 + L - 1 + m])
            + (x[b0 + L - 1 + m] - x[b0 + L - 1]))) if b0 + L < cnt else 0.0)
    return total
