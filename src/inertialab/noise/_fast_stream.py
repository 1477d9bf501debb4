"""Compiled kernels of the out-of-core octave path (optional ``[fast]`` extra, numba).

Used by :mod:`inertialab.noise._stream` when :func:`inertialab.noise._octave.fast_kernels`
is on; the out-of-core numpy path (:class:`inertialab.noise._phase._PhaseFromRate`, the
angle spilled to a temporary file) stays the fallback. The angle of a rate record ``y``
is never stored: the pass that converts ``y`` to the working array of the lag-doubling
kernel also sums it in runs of ``S`` samples, the running (compensated) sum of those run
sums is the angle at every ``S``-th point, and any stretch of the angle is recomputed
from the checkpoint at or below it, one run at a time (:func:`angle_block`).

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


@_jit
def convert_runs(y, mean, d, own, S, runsum, r0):
    """``d[i] = y[i] - mean`` in float64 for every ``i < d.size`` (the working array of
    the lag-doubling kernel, the same values as ``np.subtract(y, mean, dtype=float64)``)
    and ``runsum[r0 + k] = sum(d[k S:(k + 1) S])`` over the first ``own`` entries (runs
    of ``S``; the last may be shorter). ``y`` and ``d`` have the same length."""
    nr = (own + S - 1) // S
    for k in range(nr):
        a = k * S
        b = min(a + S, own)
        s = 0.0
        for i in range(a, b):
            v = np.float64(y[i]) - mean
            d[i] = v
            s += v
        runsum[r0 + k] = s
    for i in range(own, d.size):
        d[i] = np.float64(y[i]) - mean


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
