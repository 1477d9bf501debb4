"""Compiled B1 and R(n) noise identification and the finish of a kernel-started
identification (optional ``[fast]`` extra, numba; re-exported by
:mod:`inertialab.noise.statistics._fast`).

The rules are :func:`inertialab.noise.statistics.identify.identify_alpha`'s (Stable32's: W. J. Riley,
*Handbook of Frequency Stability Analysis*, NIST SP 1065, 2008, §5.6.4-5.6.5; B1's expected
values from Howe, Beard, Greenhall & Riley, PTTI 2000; R(n)'s flicker-PM value from NIST
TN 1337), compiled so that the rows the lag-1 test cannot take (fewer than 30 points) and
the carrying of types to the longest m cost one call instead of per-row numpy work: with
the lag-1 rows taken by the octave kernel in :mod:`inertialab.noise.statistics._fast`, the noise
identification of an octave ADEV/HDEV run costs about a fifth of the deviation itself.
Results equal the numpy rules' up to the order of summation (tested:
``tests/noise/test_fast.py``). Self-contained: numba's cache tracks a kernel's own file.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

_jit = nb.njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})


@_jit
def _b1_theory(n, mu):
    if mu == 0.0:
        return n * math.log(n) / (2.0 * (n - 1) * math.log(2.0))
    return n * (1.0 - n ** mu) / (2.0 * (n - 1) * (1.0 - 2.0 ** mu))


@_jit
def _rn_stride(m):
    """:func:`inertialab.noise.statistics.identify._stride`: the largest power of two that divides m
    and is at most m/16 (1 for odd m)."""
    s = m & -m
    while s > 1 and 16 * s > m:
        s //= 2
    return max(s, 1)


@_jit
def b1_rn_rows(x, ms, nts, alphas, codes):
    """B1 then, where B1 says phase noise, R(n) per m of ``ms`` from the in-memory phase
    ``x`` (:func:`inertialab.noise.statistics.identify.identify_alpha`'s rules 2 and 3, the
    algorithms of ``_b1_ratio``, ``b1_mu`` and ``_rn_alpha_many``): B1 on the decimated
    points ``x[k m]``, its expected values at ``nts`` (the statistic's summands at m);
    R(n) from one blockwise running sum of ``x`` shared by every m (block: the largest
    power of two dividing every m's subsequence stride). ``alphas`` (unclipped) and
    ``codes`` (1 ``b1``, 2 ``b1+rn``) are written."""
    n = x.size
    R = ms.size
    rn = np.zeros(R, dtype=np.bool_)
    block = 0
    mus = np.array([1.0, 0.0, -1.0, -2.0])
    for r in range(R):
        m = ms[r]
        k = (n - 1) // m  # frequency averages
        b1 = 1.0
        if k >= 3:
            ysum = 0.0
            for j in range(k):
                ysum += x[(j + 1) * m] - x[j * m]
            ymean = ysum / k
            var = 0.0
            av = 0.0
            for j in range(k):
                y0 = x[(j + 1) * m] - x[j * m]
                t = y0 - ymean
                var += t * t
                if j + 1 < k:
                    t = (x[(j + 2) * m] - x[(j + 1) * m]) - y0
                    av += t * t
            avar = 0.5 * av / (k - 1)
            if avar > 0:
                b1 = var / (k - 1) / avar
        nt = max(float(nts[r]), 2.0)
        mu = mus[3]
        for i in range(3):
            if b1 > math.sqrt(_b1_theory(nt, mus[i]) * _b1_theory(nt, mus[i + 1])):
                mu = mus[i]
                break
        codes[r] = 1
        if mu > -2.0:
            alphas[r] = int(-mu - 1.0)
            continue
        alphas[r] = 2
        if 3 * m <= n - 1:
            rn[r] = True
            s = _rn_stride(m)
            a, b = block, s
            while b:
                a, b = b, a % b
            block = a
    if block == 0:
        return
    nb = n // block
    c = np.zeros(nb + 1)
    acc = 0.0
    for j in range(nb):
        v = x[j * block:(j + 1) * block]  # (a slice: the inner sum vectorises, 5x)
        t = 0.0
        for i in range(block):
            t += v[i]
        acc += t
        c[j + 1] = acc
    for r in range(R):
        if not rn[r]:
            continue
        m = ms[r]
        s = _rn_stride(m)
        q = s // block
        mb = m // block
        cnt = (n - 3 * m) // s + 1
        mv = 0.0
        for k in range(cnt):
            i = k * q
            w = c[i + 3 * mb] - 3.0 * c[i + 2 * mb] + 3.0 * c[i + mb] - c[i]
            mv += w * w
        mvar = mv / (2.0 * float(m) ** 4 * cnt)
        cnt = (n - 2 * m - 1) // s + 1
        av = 0.0
        for k in range(cnt):
            i = k * s
            t = x[i + 2 * m] - 2.0 * x[i + m] + x[i]
            av += t * t
        avar = av / (2.0 * float(m) * m * cnt)
        ratio = mvar / avar if avar > 0 else 1.0 / m
        flicker = 3.37 / (1.04 + 3.0 * math.log(math.pi * m))
        alphas[r] = 1 if ratio > math.sqrt(flicker / m) else 2
        codes[r] = 2


@_jit
def finish_identification(x, ms, nts, span, min_points, freq, acf_done, acf_alpha, lo, hi,
                          alphas, codes):
    """:func:`inertialab.noise.statistics.identify.identify_alpha` in one call where a kernel took
    every lag-1 row (``acf_done``, ``acf_alpha``) and the phase ``x`` is in memory: the
    rows Stable32 identifies (``m span <= N``) and too short for the lag-1 test by B1 and
    R(n) (:func:`b1_rn_rows`), every alpha clipped to ``[lo, hi]``, then carried to the
    longer m beyond (``ms`` ascending). ``codes``: 0 carried, 1 acf, 2 b1, 3 b1+rn.
    False (nothing to trust in ``alphas``/``codes``) where a lag-1 row was not taken, ``ms``
    is not ascending or no m is identifiable: the caller's general rules then apply."""
    n = x.size
    R = ms.size
    short = np.zeros(R, dtype=np.bool_)
    for r in range(R):
        if r > 0 and ms[r] <= ms[r - 1]:
            return False
        m = ms[r]
        if m * span > n:
            continue
        if (n - 1) // m + 1 - freq >= min_points:
            if not acf_done[r]:
                return False
            alphas[r] = acf_alpha[r]
            codes[r] = 1
        else:
            short[r] = True
    if R == 0 or ms[0] * span > n:
        return False
    idx = np.flatnonzero(short)
    if idx.size:
        got = np.zeros(idx.size, dtype=np.int64)
        how = np.zeros(idx.size, dtype=np.int64)
        b1_rn_rows(x, ms[idx], nts[idx], got, how)
        for k in range(idx.size):
            alphas[idx[k]] = got[k]
            codes[idx[k]] = 1 + how[k]
    last = 0
    for r in range(R):
        if ms[r] * span <= n:
            last = min(max(alphas[r], lo), hi)
        else:
            codes[r] = 0
        alphas[r] = last
    return True
