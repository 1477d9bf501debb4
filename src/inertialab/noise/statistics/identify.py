"""Power-law noise identification per averaging factor, as Stable32 does it.

The rules of W. J. Riley's *Handbook of Frequency Stability Analysis* (NIST SP 1065,
2008, §5.6) and of Stable32, which applies them per averaging factor m of a run:

1. **Lag-1 ACF** (Riley & Greenhall, "Power law noise identification using the lag 1
   autocorrelation", EFTF 2004; SP 1065 §5.6.6) where at least ``MIN_POINTS`` = 30
   analysis points remain: the phase decimated to every m-th point (phase data), or the
   frequency averaged over m (frequency data: the differences of the decimated phase),
   differenced until ``delta = r1/(1 + r1) < 0.25`` (at most d = 2 times, 3 for the
   Hadamard family), ``alpha = -round(2 delta) - 2 d`` (+2 for phase data). ``r1`` is the
   lag-1 autocorrelation with the ``(n - 1)/n`` factor Stable32 applies to it. At most
   ``MAX_POINTS`` (the central ones) are used per m.
2. **B1 ratio** (Barnes; Howe, Beard, Greenhall & Riley, PTTI 2000; SP 1065 §5.6.4) below
   30 points: the standard variance of the m-averages over their Allan variance, compared
   with its expected value for each tau-exponent mu at the geometric means between
   neighbours. The expected values are taken at the statistic's number of summands at m
   (the ``#`` column of a Stable32 table), which is what reproduces Stable32's verdicts.
3. **R(n) = MVAR/AVAR** (SP 1065 §5.6.5) where B1 says phase noise (mu = -2): above the
   geometric mean of its white-PM (``1/m``) and flicker-PM (``3.37 / (1.04 + 3 ln(pi m))``,
   NIST TN 1337 Table A-6) values it is flicker PM (alpha = 1), below white PM (2). The
   two variances are summed over subsequences starting every ``max(1, m // 16)`` points
   (the overlapping estimates' information is in overlaps far below m) from one
   cumulative sum of the phase in blocks that divide those strides, computed once per
   call for every R(n) tau.
4. **Carried** where too few points remain: Stable32 identifies up to half its largest
   averaging factor, that is while ``N/m >= MIN_SPAN[statistic]`` phase points per m
   (OADEV/MDEV/TDEV/OHDEV 8, ADEV/HDEV 10, TOTDEV 4, MTOT/TTOT/HTOT 6: its largest m is
   N/4, N/5, N/2, N/3), and carries the type of the nearest shorter identified m beyond.
   A run whose every m lies beyond takes the type identified at the largest identifiable
   m; a record too short for any is ``"none"`` (white FM assumed).

5. **No angle noise after rate noise** (rate records, ``data="freq"``; a departure from
   Stable32): an angle-noise verdict (alpha >= +1) at a longer tau than a rate-noise
   verdict (alpha <= 0) takes the nearest shorter rate-noise type, source
   ``"rate-carried"`` (:func:`_no_angle_after_rate`). On the simulated ``allan-bi``
   gyro (10 h, 10 Hz, band-limited flicker) seed 1's B1 + R(n) called flicker angle at
   3,277 s (N/m = 11), carried to 13,107 s: OADEV EDF 237, 114, 47 where the flicker
   rate the curve carries has 11, 4.7, 1.5 (benchmarks/edf_coverage.py measures which
   EDF covers the long-tau scatter).

Measured against Stable32's own tables (1.5x-1.60; 70 tables, 7,120 rows of six records,
phase and frequency data; third-party data, not committed; docs/allan.md "Against
Stable32"): the identified alpha equals Stable32's on 99.8 % of the rows (rules 1-4;
rule 5 came later and applies to rate records only).

The source of each verdict is reported per tau: ``"acf"``, ``"b1"``, ``"b1+rn"``,
``"carried"``, ``"rate-carried"`` or ``"none"``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from inertialab.noise.statistics._filters import _ALPHA_RANGE, _family

#: Analysis points (decimated phase or averaged frequency) from which the lag-1 ACF is used.
MIN_POINTS = 30

#: Decimated points used by the lag-1 test per tau (the central ones).
MAX_POINTS = 1 << 16

#: Largest record (phase points) materialised for R(n) when the phase is not in memory.
R_N_MAX = 1 << 22

#: Rows of at least this many points are tested one at a time, shorter ones stacked.
LONG_ROW = 512

#: Phase points per averaging factor (N/m) down to which Stable32 identifies the noise
#: type (half its largest m); beyond, the type is carried.
MIN_SPAN = {"adev": 10, "hdev": 10, "oadev": 8, "ohdev": 8, "mdev": 8, "tdev": 8,
            "totdev": 4, "mtotdev": 6, "ttotdev": 6, "htotdev": 6}

#: Verdicts that count as identified with confidence (a bias correction is applied).
CONFIDENT = ("acf", "b1", "b1+rn", "carried", "rate-carried", "user", "model")

_MUS = (1.0, 0.0, -1.0, -2.0)  # B1 tau-exponents, largest first (alpha = -mu - 1)


@dataclass(frozen=True)
class NoiseIdentification:
    """Noise type per tau: ``alpha`` (int) and ``source`` (see the module docstring)."""

    m: np.ndarray
    alpha: np.ndarray
    source: tuple


def _r1(z: np.ndarray) -> float:
    zc = z - np.add.reduce(z) / z.size
    den = float(np.dot(zc, zc))
    if den <= 0:
        return 0.0
    return float(np.dot(zc[:-1], zc[1:])) / den * ((z.size - 1) / z.size)


def lag1_alpha(z: np.ndarray, *, dmax: int = 2, data_type: str = "phase") -> float:
    """Lag-1 ACF noise estimate (SP 1065 §5.6.6), unrounded ``alpha``.

    ``z`` is decimated phase (``data_type="phase"``) or averaged frequency ("freq").
    """
    z = np.asarray(z, dtype=float)
    theta = 2.0 if data_type == "phase" else 0.0
    d = 0
    while True:
        r1 = _r1(z)
        delta = r1 / (1.0 + r1)
        if delta < 0.25 or d >= dmax or z.size < 4:
            return -2.0 * (delta + d) + theta
        z = z[1:] - z[:-1]
        d += 1


def lag1_alpha_many(rows, *, dmax: int = 2, data_type: str = "phase") -> np.ndarray:
    """:func:`lag1_alpha` of each 1-D array in ``rows`` (unrounded alphas).

    Rows of similar length (same power-of-two band) are stacked zero-padded into one 2-D
    array; the mean, lag-0 and lag-1 sums are taken over each row's valid points only, so
    every row's value is that of :func:`lag1_alpha` up to the order of summation.
    """
    k = len(rows)
    out = np.empty(k)
    if k == 0:
        return out
    theta = 2.0 if data_type == "phase" else 0.0
    lens = np.array([r.size for r in rows], dtype=np.int64)
    for i in np.flatnonzero(lens >= LONG_ROW):  # long rows: one at a time (no padding)
        out[i] = lag1_alpha(rows[i], dmax=dmax, data_type=data_type)
    band = np.floor(np.log2(np.maximum(lens, 1))).astype(np.int64)
    for b in np.unique(band[lens < LONG_ROW]):
        idx = np.flatnonzero((band == b) & (lens < LONG_ROW))
        n = lens[idx]
        L = int(n.max())
        Z = np.zeros((idx.size, L))
        for r, i in enumerate(idx):
            Z[r, :n[r]] = rows[i]
        res = np.full(idx.size, np.nan)
        for d in range(dmax + 1):
            nd = n - d
            Ld = L - d
            valid = np.arange(Ld)[None, :] < nd[:, None]
            with np.errstate(invalid="ignore", divide="ignore"):
                mean = Z.sum(axis=1) / np.maximum(nd, 1)
                zc = (Z - mean[:, None]) * valid
                den = np.einsum("ij,ij->i", zc, zc)
                r1 = np.einsum("ij,ij->i", zc[:, :-1], zc[:, 1:])
                r1 = np.where(den > 0, r1 / np.where(den > 0, den, 1.0), 0.0)
                r1 = r1 * (nd - 1) / np.maximum(nd, 1)
            delta = r1 / (1.0 + r1)
            stop = np.isnan(res) & ((delta < 0.25) | (d >= dmax) | (nd < 4))
            res[stop] = -2.0 * (delta[stop] + d) + theta
            if not np.isnan(res).any():
                break
            Z = (Z[:, 1:] - Z[:, :-1]) * valid[:, 1:]
        out[idx] = res
    return out


def b1_theory(n: float, mu: float) -> float:
    """Expected B1 ratio for ``n`` frequency values and AVAR tau-exponent ``mu``
    (Howe et al. 2000, Table 3; SP 1065 §5.6.4)."""
    if mu == 0:
        return n * math.log(n) / (2.0 * (n - 1) * math.log(2.0))
    return n * (1.0 - n**mu) / (2.0 * (n - 1) * (1.0 - 2.0**mu))


def b1_mu(b1: float, n_theory: float) -> float:
    """The tau-exponent mu whose expected B1 (at ``n_theory``) is nearest on the log scale:
    the largest mu whose boundary (geometric mean with the next lower) ``b1`` exceeds."""
    n = max(float(n_theory), 2.0)
    for hi, lo in zip(_MUS[:-1], _MUS[1:]):
        if b1 > math.sqrt(b1_theory(n, hi) * b1_theory(n, lo)):
            return hi
    return _MUS[-1]


def rn_flicker_pm(m: int) -> float:
    """Expected R(n) = MVAR/AVAR of flicker PM at m, measurement bandwidth 1/(2 tau0)
    (NIST TN 1337, Sullivan et al. 1990, Table A-6)."""
    return 3.37 / (1.04 + 3.0 * math.log(math.pi * m))


def _b1_ratio(z: np.ndarray) -> float:
    """Standard variance of the m-averages over their (non-overlapping) Allan variance,
    from the decimated phase ``z`` (every m-th point)."""
    y = z[1:] - z[:-1]
    if y.size < 3:
        return 1.0
    d2 = y[1:] - y[:-1]
    avar = 0.5 * float(np.dot(d2, d2)) / d2.size
    yc = y - np.add.reduce(y) / y.size
    return float(np.dot(yc, yc)) / (y.size - 1) / avar if avar > 0 else 1.0


class _Shared:
    """What the identification branches share per call: the source's phase (in memory or
    read once) and one blockwise cumulative sum of it for R(n)."""

    def __init__(self, src):
        self.src = src
        self.n = int(src.n)
        x = getattr(src, "x", None)
        self.x = None if x is None else np.asarray(x, dtype=np.float64)
        self._csum = {}

    def row(self, start: int, count: int, step: int) -> np.ndarray:
        if self.x is not None:
            return self.x[start:start + (count - 1) * step + 1:step]
        return np.asarray(self.src.window(start, count, step), dtype=np.float64)

    def phase(self):
        if self.x is None and self.n <= R_N_MAX:
            self.x = np.asarray(self.src.window(0, self.n), dtype=np.float64)
        return self.x

    def block_phase(self, block: int):
        """``(xb, C)``: the phase at every ``block``-th point and :meth:`csum` (what R(n)
        reads); from the rate in one pass where the source offers it (a rate record in
        memory: no running sum of the whole phase), else from the phase; None where the
        phase is neither in memory nor small enough to read."""
        if self.x is None and self.n <= R_N_MAX and hasattr(self.src, "block_phase"):
            got = self.src.block_phase(block)
            if got is not None:
                return got
        if self.phase() is None:
            return None
        return self.x[::block], self.csum(block)

    def csum(self, block: int) -> np.ndarray:
        """``C[k] = sum(x[:k block])``, k = 0 .. n // block (one pass, cached)."""
        if block not in self._csum:
            x = self.phase()
            nb = x.size // block
            # (a matrix-vector product: one pass, 2-8x cheaper than a per-row sum)
            sums = x[:nb * block].reshape(nb, block) @ np.ones(block) if block > 1 else x
            c = np.zeros(nb + 1)
            np.cumsum(sums, out=c[1:])
            self._csum[block] = c
        return self._csum[block]


def _stride(m: int) -> int:
    """Start spacing of the R(n) subsequences at m: the largest power of two that divides
    m and is at most m/16 (1 for odd m)."""
    s = m & -m
    while s > 1 and 16 * s > m:
        s //= 2
    return max(s, 1)


def _rn_alpha_many(sh: _Shared, ms) -> tuple:
    """White (2) or flicker (1) PM per m by R(n) (module docstring, item 3); sources
    ``"b1+rn"`` (``"b1"`` where the phase of a record above ``R_N_MAX`` points is not in
    memory: white PM assumed, or where 3m exceeds the record)."""
    ms = [int(m) for m in ms]
    out = np.full(len(ms), 2, dtype=np.int64)
    how = ["b1"] * len(ms)
    ok = [i for i, m in enumerate(ms) if 3 * m <= sh.n - 1]
    if not ok:
        return out, how
    block = 0
    for i in ok:
        block = math.gcd(block, _stride(ms[i]))
    got = sh.block_phase(block)
    if got is None:
        return out, how
    xb, c = got  # xb[k] = x[k block]
    for i in ok:
        m = ms[i]
        s = _stride(m)
        q, mb = s // block, m // block
        # MVAR: sums of m points at starts k s: C[(k s + m)/block] - C[k s/block]
        kk = np.arange(0, (sh.n - 3 * m) // s + 1) * q
        w = c[kk + 3 * mb] - 3.0 * c[kk + 2 * mb] + 3.0 * c[kk + mb] - c[kk]
        mvar = float(np.dot(w, w)) / (2.0 * m**4 * w.size)
        j = np.arange(0, (sh.n - 2 * m - 1) // s + 1) * q  # starts k s, in blocks
        d = xb[j + 2 * mb] - 2.0 * xb[j + mb] + xb[j]
        avar = float(np.dot(d, d)) / (2.0 * m * m * d.size)
        rn = mvar / avar if avar > 0 else 1.0 / m
        out[i] = 1 if rn > math.sqrt(rn_flicker_pm(m) / m) else 2
        how[i] = "b1+rn"
    return out, how


def _compiled(sh: _Shared):
    """The compiled kernels where the phase is in memory (B1 and R(n) read it in place),
    else None (the numpy rules)."""
    from inertialab.noise.statistics import _octave

    return _octave.fast_kernels() if sh.x is not None else None


def _acf_compiled(sh, ms, own, decimated, freq, dmax, max_points, min_points,
                  alphas) -> np.ndarray:
    """The lag-1 rows by the compiled kernel (read in place, strided, from the in-memory
    phase; alphas set); which m it did (none without the kernels, without the
    phase in memory, or where the caller gathered the points); the caller sets the
    sources."""
    from inertialab.noise.statistics import _octave

    done = np.zeros(ms.size, dtype=bool)
    K = _octave.fast_kernels()
    if K is None:
        return done
    count = (sh.n - 1) // ms + 1
    sel = np.flatnonzero(own & (count - freq >= min_points))
    if sel.size == 0:
        return done
    m = ms[sel]
    use = np.minimum(count[sel], max_points)
    if isinstance(decimated, _octave.Decimated) and decimated.rows(m) is not None:
        base = decimated.flat  # the rows the caller gathered, contiguous
        starts, got = decimated.rows(m)
        if not np.array_equal(got, use):
            return done
        steps = np.ones(m.size, dtype=np.int64)
    elif sh.x is not None and not decimated:
        base, starts, steps = sh.x, ((count[sel] - use) // 2) * m, m
    else:
        return done
    out = np.empty(sel.size)
    incr = bool(getattr(decimated, "increments", False))  # rows of frequency averages
    K.lag1_strided(base, starts, steps, use - 1 if incr else use, dmax, out,
                   np.empty(int(use.max())), 0 if freq else 2, not incr)
    alphas[sel] = np.rint(out).astype(np.int64)
    done[sel] = True
    return done


def acf_rules(statistic: str, min_points: int = MIN_POINTS) -> tuple:
    """``(dmax, min_points, lo, hi)`` of ``statistic``'s lag-1 test: the most differencing
    rounds and the alpha range (what the compiled kernels take to identify in place)."""
    hadamard = _family(statistic) == "hadamard" or statistic == "htotdev"
    lo, hi = _ALPHA_RANGE.get(statistic, (-4, 2) if hadamard else (-2, 2))
    return (3 if hadamard else 2), int(min_points), lo, hi


def identify_alpha(src, ms, *, statistic: str = "oadev", data: str = "phase",
                   n_terms=None, max_points: int = MAX_POINTS, min_points: int = MIN_POINTS,
                   decimated: dict | None = None, acf=None) -> NoiseIdentification:
    """Noise type per averaging factor from a phase source (module docstring).

    ``src`` offers ``n`` (phase points) and ``window(start, length, step)`` (and ``x``,
    the phase array, when it is in memory). ``data``: ``"phase"`` (phase/angle data) or
    ``"freq"`` (frequency/rate data: the lag-1 test runs on the m-averages). ``n_terms``:
    the statistic's number of summands per m (B1's expected values are taken there;
    default: overlapping Allan's ``N - 2m``). ``decimated`` maps m to its decimated
    points already gathered by the caller (the central ones when more than
    ``max_points``, e.g. from a lag-doubling kernel). ``acf = (done, alphas)``: per m,
    whether the caller already took the lag-1 test (phase data, :func:`acf_rules`, on
    the same central points) and its rounded alpha.
    """
    dmax, _, lo, hi = acf_rules(statistic)
    ms = np.atleast_1d(np.asarray(ms, dtype=np.int64))
    sh = _Shared(src)
    N = sh.n
    nt = np.asarray(n_terms, dtype=np.int64) if n_terms is not None else N - 2 * ms
    if nt.shape != ms.shape:
        nt = np.broadcast_to(nt, ms.shape).copy()
    freq = data != "phase"
    alphas = np.zeros(ms.size, dtype=np.int64)
    codes = np.zeros(ms.size, dtype=np.int8)  # index into _SOURCES: "carried"
    if acf is not None and decimated is None and (fast := _compiled(sh)) is not None:
        # a kernel took the lag-1 rows: the rest in one compiled call where it can
        if fast.finish_identification(sh.x, ms, nt, MIN_SPAN.get(statistic, 8), min_points,
                                      int(freq), np.asarray(acf[0], dtype=np.bool_),
                                      np.asarray(acf[1], dtype=np.int64), lo, hi, alphas,
                                      codes):
            if freq:
                _no_angle_after_rate(ms, alphas, codes)
            return NoiseIdentification(ms, alphas, tuple(_SOURCES[c] for c in codes.tolist()))
        alphas[:], codes[:] = 0, 0
    own = ms * MIN_SPAN.get(statistic, 8) <= N
    lagged = own & ((N - 1) // ms + 1 - freq >= min_points)  # rows of the lag-1 test
    done = np.zeros(ms.size, dtype=bool)
    if acf is not None:  # the lag-1 verdicts the caller's kernel took
        done = lagged & np.asarray(acf[0], dtype=bool)
        alphas[done] = np.asarray(acf[1], dtype=np.int64)[done]
    if (lagged & ~done).any():
        done |= _acf_compiled(sh, ms, own & ~done, decimated, freq, dmax, max_points,
                              min_points, alphas)
    codes[done] = _ACF
    left = own & ~done
    if left.any():
        _identify_left(sh, ms, np.flatnonzero(left), lagged, nt, freq, dmax, max_points,
                       decimated, alphas, codes)
    np.minimum(np.maximum(alphas, lo, out=alphas), hi, out=alphas)
    if not own.all():
        _carry(src, ms, own, alphas, codes, statistic, data, max_points, min_points)
    if freq:
        _no_angle_after_rate(ms, alphas, codes)
    return NoiseIdentification(ms, alphas, tuple(_SOURCES[c] for c in codes.tolist()))


#: Source names by code (:func:`identify_alpha`'s bookkeeping).
_SOURCES = ("carried", "acf", "b1", "b1+rn", "none", "rate-carried")
_ACF, _B1, _B1RN, _NONE, _RATE = 1, 2, 3, 4, 5


def _no_angle_after_rate(ms, alphas, codes) -> None:
    """Rule 5 (rate records): an angle-noise verdict (alpha >= +1) at a longer tau than a
    rate-noise verdict (alpha <= 0) takes the type of the nearest shorter rate-noise
    verdict (source ``"rate-carried"``). The dominant type of a sum of power-law rate
    noises only falls with tau, and a band-limited one (Gauss–Markov) rolls off to white
    rate, never steeper; an angle verdict there is the scatter of a statistic read on a
    few points (B1 on ~10 averages, R(n)), and its EDF (flicker angle ~240, white angle
    ~10^5 at N/m = 11) would be ~20-10^4 times that of the rate noise the curve carries."""
    last = None
    for i in np.argsort(ms, kind="stable").tolist():
        if codes[i] == _NONE:
            continue
        if alphas[i] <= 0:
            last = int(alphas[i])
        elif last is not None:
            alphas[i], codes[i] = last, _RATE


def _identify_left(sh, ms, rows, lagged, nt, freq, dmax, max_points, decimated, alphas,
                   codes) -> None:
    """The rows no kernel took: lag-1 on numpy (``lagged``), else B1 and, where B1 says
    phase noise, R(n) (compiled where the phase is in memory and nothing was gathered)."""
    N = sh.n
    kind = "freq" if freq else "phase"
    fast = _compiled(sh)
    lag_rows, lag_idx, rn_idx, b1_idx = [], [], [], []
    for i in rows.tolist():
        m = int(ms[i])
        count = (N - 1) // m + 1  # decimated phase points
        z = decimated.get(m) if decimated is not None else None
        if lagged[i]:
            use = min(count, max_points)
            if z is None or z.size != use:
                z = sh.row(((count - use) // 2) * m, use, m)
            z = np.diff(z) if freq else z
            codes[i] = _ACF
            if z.size >= LONG_ROW:  # long rows at once (no list of copies)
                alphas[i] = int(np.rint(lag1_alpha(z, dmax=dmax, data_type=kind)))
            else:
                lag_rows.append(z)
                lag_idx.append(i)
            continue
        if z is None and fast is not None:  # B1 and R(n) of these rows in one call
            b1_idx.append(i)
            continue
        if z is None or z.size != count:
            z = sh.row(0, count, m)
        mu = b1_mu(_b1_ratio(np.asarray(z, dtype=np.float64)), float(nt[i]))
        codes[i] = _B1
        if mu > -2:
            alphas[i] = int(-mu - 1)
        else:
            rn_idx.append(i)
    if lag_idx:
        a = lag1_alpha_many(lag_rows, dmax=dmax, data_type=kind)
        alphas[lag_idx] = np.rint(a).astype(np.int64)
    if b1_idx:
        got = np.zeros(len(b1_idx), dtype=np.int64)
        how = np.zeros(len(b1_idx), dtype=np.int64)
        fast.b1_rn_rows(sh.x, ms[b1_idx], nt[b1_idx], got, how)
        alphas[b1_idx] = got
        codes[b1_idx] = np.where(how == 2, _B1RN, _B1)
    if rn_idx:
        a, how = _rn_alpha_many(sh, ms[rn_idx])
        alphas[rn_idx] = a
        codes[rn_idx] = [_B1RN if h == "b1+rn" else _B1 for h in how]


def _carry(src, ms, own, alphas, codes, statistic, data, max_points, min_points) -> None:
    """Beyond Stable32's range (``~own``): the type of the nearest shorter identified m
    (rule 4); where every m is beyond, the type at the largest identifiable m; ``none``
    (white FM) where the record is too short for any."""
    order = np.argsort(ms, kind="stable")
    last = None
    if not own.any():
        top = int(src.n) // MIN_SPAN.get(statistic, 8)
        if top >= 1:
            r = identify_alpha(src, [top], statistic=statistic, data=data,
                               n_terms=[max(int(src.n) - 2 * top, 2)],
                               max_points=max_points, min_points=min_points)
            last = int(r.alpha[0])
    for i in order.tolist():
        if own[i]:
            last = int(alphas[i])
        elif last is None:
            alphas[i], codes[i] = 0, _NONE
        else:
            alphas[i] = last


__all__ = ["CONFIDENT", "MAX_POINTS", "MIN_POINTS", "MIN_SPAN", "NoiseIdentification",
           "acf_rules",
           "R_N_MAX", "b1_mu", "b1_theory", "identify_alpha", "lag1_alpha",
           "lag1_alpha_many", "rn_flicker_pm"]
