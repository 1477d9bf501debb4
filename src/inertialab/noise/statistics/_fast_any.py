"""Compiled per-m kernels of the Allan family and the Greenhall EDF (optional ``[fast]``
extra, numba), re-exported by :mod:`inertialab.noise.statistics._fast` (see there
for the switch, the equality tests and the cache). Any set of averaging factors: one
loop per m over the in-memory angle; the EDF: the branches of
:func:`inertialab.noise.statistics.edf.edf_greenhall` per m. Also the octave kernels that call no
other kernel (the modified family's ``octave_b``, ``gather_increments``, the out-of-core
``combine_taps``): numba's cache tracks a kernel's own file, so kernels that call each
other share one.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

_jit = nb.njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
_jit_exact = nb.njit(cache=True, nogil=True)  # sequential sums (running recurrences)


# ----------------------------------------------------------------------------- any m


@_jit
def dense_overlap(x, ms, q):
    """Sums of squared overlapping second (``q = 2``, OADEV) or third (``q = 3``, OHDEV)
    lag-m differences of the angle ``x`` at each m."""
    nx = x.size
    out = np.zeros(ms.size)
    for k in range(ms.size):
        m = ms[k]
        cnt = nx - q * m
        if cnt < 1:
            continue
        s = 0.0
        x0 = x[:cnt]
        x1 = x[m:m + cnt]
        x2 = x[2 * m:2 * m + cnt]
        if q == 2:
            for i in range(cnt):
                b = x1[i]
                t = (x2[i] - b) - (b - x0[i])
                s += t * t
        else:
            x3 = x[3 * m:3 * m + cnt]
            for i in range(cnt):
                a1 = x1[i]
                a2 = x2[i]
                t = ((x3[i] - a2) - (a2 - a1)) - ((a2 - a1) - (a1 - x0[i]))
                s += t * t
        out[k] = s
    return out


@_jit
def _restart_z(x, i, m):
    """``sum_{j<m} (x_{i+j+2m} - 2 x_{i+j+m} + x_{i+j})``: the modified sum at i."""
    z = 0.0
    for j in range(i, i + m):
        b = x[j + m]
        z += (x[j + 2 * m] - b) - (b - x[j])
    return z


@_jit_exact
def dense_mod(x, ms, restart, inc, avar):
    """MDEV sums ``sum_i z_i^2``, ``z_i = sum_{j<m}`` (second difference at lag m)
    ``_{i+j}``, by the recurrence ``z_{i+1} = z_i + x_{i+3m} - 3 x_{i+2m} + 3 x_{i+m} -
    x_i``: per block of ``inc.size`` summands the increments are formed first (one
    vectorised pass), their quarter sums give z at four points, and the four quarters
    run as independent chains (the recurrence's latency hidden). z is recomputed from
    its definition every ``max(restart, m)`` summands (rounded up to whole blocks; for
    m > 2^16 only at the start), which bounds the accumulated rounding. ``avar[k]``
    receives the OADEV sum at the same m from the same reads (R(n) needs both)."""
    nx = x.size
    out = np.zeros(ms.size)
    B = inc.size
    for k in range(ms.size):
        m = ms[k]
        cnt = nx - 3 * m + 1
        av = 0.0
        for i in range(max(nx - 3 * m, 0), nx - 2 * m):  # Allan summands past the last z
            e = (x[i + 2 * m] - x[i + m]) - (x[i + m] - x[i])
            av += e * e
        avar[k] = av
        if cnt < 1:
            continue
        # (above 2^16 the numpy kernel, too, carries the sum across the whole record)
        every = ((max(restart, m) + B - 1) // B) * B if m <= 65536 else cnt + B
        s = 0.0
        z = 0.0
        for i in range(0, cnt, B):
            if i % every == 0:
                z = _restart_z(x, i, m)
            n = min(B, cnt - i)
            av += _mod_incs(x, i, m, n, inc)  # inc[t] = z_{i+t+1} - z_{i+t}, t < n
            q = n // 4
            zb = z
            za = zb + _sum(inc, 0, q)
            zc = za + _sum(inc, q, 2 * q)
            zd = zc + _sum(inc, 2 * q, 3 * q)
            s0 = 0.0
            s1 = 0.0
            s2 = 0.0
            s3 = 0.0
            for t in range(q):
                s0 += zb * zb
                s1 += za * za
                s2 += zc * zc
                s3 += zd * zd
                zb += inc[t]
                za += inc[q + t]
                zc += inc[2 * q + t]
                zd += inc[3 * q + t]
            for t in range(4 * q, n):
                s3 += zd * zd
                zd += inc[t]
            s += (s0 + s1) + (s2 + s3)
            z = zd  # z_{i+n} (unused past the last summand)
        out[k] = s
        avar[k] = av
    return out


@_jit
def _mod_incs(x, i, m, n, inc):
    """``inc[t] = x_{j+3m} - 3 x_{j+2m} + 3 x_{j+m} - x_j`` (as differences), j = i + t;
    the last one only where it stays inside the record. Returns the sum of the squared
    second differences ``x_{j+2m} - 2 x_{j+m} + x_j`` over the same j (Allan summands)."""
    nx = x.size
    c = min(n, nx - 3 * m - i)
    a0 = x[i:i + c]
    a1 = x[i + m:i + m + c]
    a2 = x[i + 2 * m:i + 2 * m + c]
    a3 = x[i + 3 * m:i + 3 * m + c]
    sq = 0.0
    for t in range(c):
        b1 = a1[t]
        b2 = a2[t]
        e0 = (b2 - b1) - (b1 - a0[t])
        inc[t] = ((a3[t] - b2) - (b2 - b1)) - e0
        sq += e0 * e0
    for t in range(c, n):
        inc[t] = 0.0
    return sq


@_jit
def _sum(v, a, b):
    s = 0.0
    for t in range(a, b):
        s += v[t]
    return s


@_jit
def dense_strided(x, ms, order):
    """ADEV (``order = 2``) / HDEV (3) sums: squared differences of ``x[::m]``."""
    nx = x.size
    out = np.zeros(ms.size)
    for k in range(ms.size):
        m = ms[k]
        n = (nx - 1) // m + 1
        s = 0.0
        if order == 2:
            for i in range(n - 2):
                b = x[(i + 1) * m]
                t = (x[(i + 2) * m] - b) - (b - x[i * m])
                s += t * t
        else:
            for i in range(n - 3):
                x1 = x[(i + 1) * m]
                x2 = x[(i + 2) * m]
                e0 = (x2 - x1) - (x1 - x[i * m])
                e1 = (x[(i + 3) * m] - x2) - (x2 - x1)
                t = e1 - e0
                s += t * t
        out[k] = s
    return out


@_jit
def _edges(x, m, a, b):
    """TOTDEV summands of the centres [a, b) (reflected taps), in segments on which
    each tap is either inside the record or reflected (cuts at m and n - 1 - m)."""
    nx = x.size
    n1 = nx - 1
    x0 = 2.0 * x[0]
    xn = 2.0 * x[n1]
    s = 0.0
    c0 = a
    while c0 < b:
        c1 = b
        if c0 < m:
            c1 = min(c1, m)
        if c0 + m <= n1:
            c1 = min(c1, n1 - m + 1)
        n = c1 - c0
        xc = x[c0:c1]
        if c0 < m and c0 + m > n1:  # both taps reflected
            for i in range(n):
                bb = xc[i]
                t = ((xn - x[2 * n1 - m - c0 - i]) - bb) - (bb - (x0 - x[m - c0 - i]))
                s += t * t
        elif c0 < m:  # left tap reflected: x*_{c-m} = 2 x_0 - x_{m-c}
            xr = x[c0 + m:c1 + m]
            for i in range(n):
                bb = xc[i]
                t = (xr[i] - bb) - (bb - (x0 - x[m - c0 - i]))
                s += t * t
        elif c0 + m > n1:  # right tap reflected: x*_{c+m} = 2 x_{n-1} - x_{2(n-1)-c-m}
            xl = x[c0 - m:c1 - m]
            for i in range(n):
                bb = xc[i]
                t = ((xn - x[2 * n1 - m - c0 - i]) - bb) - (bb - xl[i])
                s += t * t
        else:
            xl = x[c0 - m:c1 - m]
            xr = x[c0 + m:c1 + m]
            for i in range(n):
                bb = xc[i]
                t = (xr[i] - bb) - (bb - xl[i])
                s += t * t
        c0 = c1
    return s


@_jit
def dense_totdev(x, ms, interior):
    """TOTDEV sums over the centres c = 1 .. n-2 of ``(x*_{c+m} - x_c) - (x_c - x*_{c-m})``
    squared, ``x*`` the reflected extension (taken by index, never built); with
    ``interior`` False only the centres whose taps reach into the extension."""
    nx = x.size
    out = np.zeros(ms.size)
    for k in range(ms.size):
        m = ms[k]
        lo = max(1, m)  # interior centres: c - m >= 0 and c + m <= nx - 1
        hi = min(nx - 1, nx - 1 - m + 1)
        s = 0.0
        n = hi - lo if interior else 0
        if n > 0:
            xl = x[lo - m:lo - m + n]
            xc = x[lo:lo + n]
            xr = x[lo + m:lo + m + n]
            for i in range(n):
                b = xc[i]
                t = (xr[i] - b) - (b - xl[i])
                s += t * t
        s += _edges(x, m, 1, min(lo, nx - 1))
        s += _edges(x, m, max(hi, lo), nx - 1)
        out[k] = s
    return out


# ----------------------------------------------------------------------------- Greenhall EDF


@_jit_exact
def _sw(t, alpha):
    a = abs(t)
    if alpha == 2:
        return -a
    a2 = a * a
    if alpha == 0 or alpha == -2 or alpha == -4:
        p = a2 * a
        for _ in range((-alpha) // 2):
            p = p * a2
        return p
    lg = math.log(a) if a > 0 else 0.0
    p = a2
    for _ in range((1 - alpha) // 2):
        p = p * a2
    return p * lg


@_jit_exact
def _sw_d2(a, alpha):
    """``(sw'', sw'''', sw'''''')`` at ``|t| = a``, as ``edf._sw_derivs``."""
    if alpha == 2:
        return 0.0, 0.0, 0.0
    if alpha == 0:
        return 6 * a, 0.0, 0.0
    if alpha == -2:
        return 20 * a ** 3, 120 * a, 0.0
    if alpha == -4:
        return 42 * a ** 5, 840 * a ** 3, 5040 * a
    lg = math.log(a) if a > 0 else 0.0
    inv2 = 1.0 / (a * a) if a > 0 else 0.0
    if alpha == 1:
        return 2 * lg + 3, -2 * inv2, -12 * inv2 * inv2
    if alpha == -1:
        return 12 * a ** 2 * lg + 7 * a ** 2, 24 * lg + 50, -24 * inv2
    return (30 * a ** 4 * lg + 11 * a ** 4, 360 * a ** 2 * lg + 342 * a ** 2,
            720 * lg + 1764)  # alpha == -3


@_jit_exact
def _sx(t, F, alpha):
    a = abs(t)
    if math.isinf(F):
        return -_sw_d2(a, alpha)[0]
    h = 1.0 / F
    if a * F >= 64.0:
        g2, g4, g6 = _sw_d2(a, alpha)
        return -(g2 + h * h * g4 / 12.0 + h ** 4 * g6 / 360.0)
    return F * F * (2.0 * _sw(t, alpha) - _sw(t - h, alpha) - _sw(t + h, alpha))


@_jit_exact
def _sz(t, F, alpha, d, c):
    out = c[0] * _sx(t, F, alpha)
    for k in range(1, d + 1):
        out = out + c[k] * (_sx(t - k, F, alpha) + _sx(t + k, F, alpha))
    return out


@_jit
def _inv_sum(J, M, S, F, alpha, d, c):
    """Greenhall's basic sum (eq. 10) / (sz(0)^2 M), as ``edf._inv_edf_sum``."""
    s0 = _sz(0.0, F, alpha, d, c)
    s0 = s0 * s0
    if J == 0:
        return s0 / (s0 * M)
    tot = s0
    for j in range(1, J):
        v = _sz(j / S, F, alpha, d, c)
        tot += 2.0 * (1.0 - j / M) * (v * v)
    v = _sz(J / S, F, alpha, d, c)
    tot += (1.0 - J / M) * (v * v)
    return tot / (s0 * M)


@_jit
def greenhall_many(N, ms, alphas, d, overlapping, modified, t1, t2, t3, c, jmax, out):
    """EDF of Greenhall & Riley (2003) per (m, alpha): the branches of
    :func:`inertialab.noise.statistics.edf.edf_greenhall` (tables ``t1``/``t2`` indexed
    ``[2 - alpha, d - 1, :]``, NaN where not allowed; ``t3[d - 1]``; ``c`` the binomial
    difference coefficients of order d)."""
    inf = np.inf
    for i in range(ms.size):
        m = ms[i]
        alpha = alphas[i]
        out[i] = np.nan
        if alpha + 2 * d <= 1 or alpha > 2 or m < 1:
            continue
        F = 1.0 if modified else float(m)
        S = float(m) if overlapping else 1.0
        L = m / F + m * d
        M = 1.0 + math.floor(S * (N - L) / m)
        if M < 1:
            continue
        J = min(M, (d + 1) * S)
        r = M / S
        ai = 2 - alpha
        if modified:
            if J <= jmax:
                inv = _inv_sum(int(J), M, S, 1.0, alpha, d, c)
            elif r > d + 1:
                inv = (t1[ai, d - 1, 0] - t1[ai, d - 1, 1] / r) / r
            else:
                inv = _inv_sum(jmax, float(jmax), jmax / r, 1.0, alpha, d, c)
        elif alpha <= 0:
            if J <= jmax:
                inv = _inv_sum(int(J), M, S, float(m) if m * (d + 1) <= jmax else inf,
                               alpha, d, c)
            elif r > d + 1:
                inv = (t2[ai, d - 1, 0] - t2[ai, d - 1, 1] / r) / r
            else:
                inv = _inv_sum(jmax, float(jmax), jmax / r, inf, alpha, d, c)
        elif alpha == 1:
            b0 = t3[d - 1, 0]
            b1 = t3[d - 1, 1]
            if J <= jmax:
                inv = _inv_sum(int(J), M, S, float(m), 1, d, c)
            elif r > d + 1:
                inv = ((t2[ai, d - 1, 0] - t2[ai, d - 1, 1] / r)
                       / ((b0 + b1 * math.log(m)) ** 2 * r))
            else:
                mp = jmax / r
                v = _sz(0.0, mp, 1, d, c)
                tot = v * v
                for j in range(1, jmax):
                    v = _sz(j / mp, mp, 1, d, c)
                    tot += 2.0 * (1.0 - j / jmax) * (v * v)
                inv = tot / ((b0 + b1 * math.log(m)) ** 2 * jmax)
        else:  # alpha == 2, unmodified
            if math.ceil(r) <= d:
                Si = int(S)
                v = _sz(0.0, float(m), 2, d, c)
                s0 = v * v
                tot = s0
                Ji = int(J)
                for j in range(Si, Ji + 1, Si):
                    v = _sz(j / S, float(m), 2, d, c)
                    w = (1.0 - J / M) if j == Ji else 2.0 * (1.0 - j / M)
                    tot += w * (v * v)
                inv = tot / (s0 * M)
            else:
                a0 = 1.0
                if d == 1:
                    a0 = 6.0 / 4.0
                elif d == 2:
                    a0 = 70.0 / 36.0
                else:
                    a0 = 924.0 / 400.0
                inv = (a0 - (d / 2.0) / r) / M
        if inv > 0:
            out[i] = 1.0 / inv


# ----------------------------------------------------------------------------- octave (self-contained)


@_jit
def octave_b(d, nx, want, tmp):
    """MDEV/TDEV sums at m = 2^l from ``B(m)_i = sum_{j<m} D(m)_{i+j}`` (``d``, the first
    differences at m = 1, overwritten): the squared ``B_{i+m} - B_i``, then ``B(2m)_i =
    B_i + 2 B_{i+m} + B_{i+2m}``, in blocks as :func:`octave_d`."""
    L = want.size
    sums = np.zeros(L)
    nb_ = d.size
    B = tmp.size
    m = 1
    for lev in range(L):
        cnt = nx - 3 * m + 1
        nxt = nb_ - 2 * m
        more = lev + 1 < L and nxt > 0
        c = cnt if (want[lev] and cnt >= 1) else 0
        s = 0.0
        top = max(c, nxt if more else 0)
        for b0 in range(0, top, B):
            n = min(B, top - b0)
            ns = max(0, min(n, c - b0))
            nu = max(0, min(n, nxt - b0)) if more else 0
            a = d[b0:b0 + n]
            b = d[b0 + m:b0 + m + n]
            for i in range(ns):
                t = b[i] - a[i]
                s += t * t
            if nu > 0:
                cc = d[b0 + 2 * m:b0 + 2 * m + nu]
                for i in range(nu):
                    bi = b[i]
                    tmp[i] = ((bi + bi) + a[i]) + cc[i]
                for i in range(nu):
                    a[i] = tmp[i]
        sums[lev] = s
        if not more:
            break
        nb_ = nxt
        m *= 2
    return sums


@_jit
def gather_increments(d, ms, starts, uses, offs, dec, pre, g):
    """Decimated points ``x_{s + k m} - x_s`` (k < use) of the increments ``d`` (``x_{i+1}
    = x_i + d_i``) for each m, into ``dec[offs[r]:]``. ``pre`` (``(d.size) // g + 1``
    entries) receives ``x_{g j}``; every m that is a multiple of ``g`` reads its points
    from it, smaller m sum their increments directly."""
    acc = 0.0
    pre[0] = 0.0
    for j in range(d.size // g):
        p = 0.0
        blk = d[g * j:g * j + g]
        for i in range(g):
            p += blk[i]
        acc += p
        pre[j + 1] = acc
    for r in range(ms.size):
        m = ms[r]
        st = starts[r]
        o = offs[r]
        dec[o] = 0.0
        if m % g == 0:
            base = pre[st // g]
            step = m // g
            for k in range(1, uses[r]):
                dec[o + k] = pre[st // g + k * step] - base
            continue
        acc = 0.0
        for k in range(1, uses[r]):
            p = 0.0
            blk = d[st + (k - 1) * m:st + k * m]
            for j in range(m):
                p += blk[j]
            acc += p
            dec[o + k] = acc


@_jit
def combine_taps(t0, t1, t2, t3, q, n):
    """Sum over i < n of the squared second (``q = 2``: ``t2 - 2 t1 + t0``) or third
    (``q = 3``: ``t3 - 3 t2 + 3 t1 - t0``) differences of the taps ``x_i, x_{i+m},
    ...`` (equal-length windows; ``t3`` unused for q = 2), with the difference formulas
    of the numpy path (:func:`inertialab.noise.statistics._stream._combine_sumsq`)."""
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
