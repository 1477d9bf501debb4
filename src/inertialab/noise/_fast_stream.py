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
    (``ck[r] = x_{r S}``) plus the run's own running sum of ``y - mean`` (the same
    order for every window, so a point has one value whichever window asks)."""
    r = p0 // S
    base = r * S
    s = 0.0
    for i in range(base, p0):  # into the run where the window starts
        s += np.float64(y[i]) - mean
    c = ck[r]
    j = 0
    i = p0
    ny = y.size
    while j < n:
        if i - base == S:  # the next run starts at its own checkpoint
            base = i
            r += 1
            c = ck[r]
            s = 0.0
        out[j] = c + s
        if i < ny:
            s += np.float64(y[i]) - mean
        i += 1
        j += 1


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

    Blocks of ``L = ring.shape[1]`` angle points (``L`` a multiple of ``S``) of class
    ``r`` modulo ``Q`` (blocks ``r, r + Q, r + 2Q, ...``) are computed once each, in
    order (:func:`angle_block`), into a ring of the last ``ring.shape[0]`` blocks. Tau
    ``j`` has ``m_j = steps[j] Q L``: its summands in the block ``k`` sweep steps back
    read the blocks ``k``, ``k + steps[j]``, ... ``k + q steps[j]``, all in the ring
    when block ``k + q steps[j]`` arrives. Adds into ``sums[j]`` the squared
    differences of the summands ``i < cnts[j]`` of this class (in angle-point units)."""
    R = ring.shape[0]
    L = ring.shape[1]
    k = 0
    while True:
        p0 = (r + k * Q) * L
        if p0 >= nx:
            break
        n = min(L, nx - p0)
        angle_block(y, ck, mean, S, p0, n, ring[k % R])
        for j in range(steps.size):
            st = steps[j]
            k0 = k - q * st
            if k0 < 0:
                continue
            b0 = (r + k0 * Q) * L
            c = min(L, cnts[j] - b0)
            if c <= 0:
                continue
            t0 = ring[k0 % R]
            t1 = ring[(k0 + st) % R]
            t2 = ring[(k0 + 2 * st) % R]
            t3 = ring[(k0 + 3 * st) % R] if q == 3 else t2
            sums[j] += _taps(t0, t1, t2, t3, q, c)
        k += 1
