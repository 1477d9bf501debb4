"""The profiled shapes of the noise-term least squares (:mod:`inertialab.noise.terms.least_squares`):
the B term as band-limited flicker with its corners on a grid, the K term as a random
walk or one held by a Gauss–Markov correlation time, the grid of both, the design with
a grid point's columns, and the test of a significant rise after the curve's minimum
(split from ``_terms_ls`` to keep each module small)."""

from __future__ import annotations

import math

import numpy as np

from inertialab.noise.terms.band import rw_gm_shape
from inertialab.noise.terms.base import BAND_LO_MAX, K_TIME_MIN, band_shape


def _corner_grid(taus):
    """Corners ``(t_lo, t_hi)`` of the band-limited B term searched by the fit: ``t_lo``
    in {0, 1, 4, 16, 64} x the shortest tau (:data:`BAND_LO_MAX`), ``t_hi`` on a
    quarter-decade grid from 16x the shortest tau to 4x the longest, or infinite, and
    ``t_hi >= 4 t_lo``: the band's flat part lies inside the fitted taus (a band below
    them falls like white noise there and was measured to take up to 14 % of N on
    white + filter data). The first corner pair ``(0, inf)`` is pure flicker."""
    tmin, tmax = float(np.min(taus)), float(np.max(taus))
    los = [0.0] + [tmin * f for f in (1.0, 4.0, 16.0, 64.0) if f <= BAND_LO_MAX]
    start = 16.0 * tmin
    n_hi = max(int(math.floor(4 * math.log10(4.0 * tmax / start))) + 1, 0)
    his = [math.inf] + [start * 10 ** (0.25 * i) for i in range(n_hi)]
    return [(lo, hi) for lo in los for hi in his if hi >= 4.0 * lo]


def _band_table(taus, grid):
    """B-term shape of every corner pair at ``taus``, shape (n_grid, k)."""
    return np.array([band_shape(taus, lo, hi) for lo, hi in grid])


def _k_time_grid(taus, avar, edf_tab):
    """Correlation times searched for the K term (:func:`rw_gm_shape`): infinite (the
    random walk; first, so it wins every tie) and a quarter-decade grid from the longest
    fitted tau down to :data:`K_TIME_MIN` of it, the curve's minimum and 16x the shortest
    tau, searched only where the curve rises significantly after its minimum. A finite
    time makes the K term rise like a random walk and fall like white noise past
    ``~1.9 t_c``: the rise-then-fall of a real MEMS accelerometer's long taus (a
    temperature-driven wander), which a pure random walk holds only by passing far above
    the longest taus. A shorter time would make K a hump inside the curve, which is the B
    band's (a mixture of Gauss–Markov processes) and would leave K a random-walk density
    that holds over no tau a user integrates over."""
    tmin, tmax = float(np.min(taus)), float(np.max(taus))
    t_rise = _rise_start(taus, avar, edf_tab)
    if t_rise is None:
        return [math.inf]
    low = max(K_TIME_MIN * tmax, 16.0 * tmin, t_rise)
    n = max(int(math.floor(4 * math.log10(tmax / low) + 1e-9)) + 1, 0)
    return [math.inf] + [tmax * 10 ** (-0.25 * i) for i in range(n)]


def _rise_start(taus, avar, edf_tab, dom=None):
    """The tau of the curve's minimum when the curve rises significantly after it (some
    later tau's 95 % lower limit above the minimum's upper limit, each with the least EDF
    of the five noise types, or with that of the fitted model's dominant term ``dom``),
    else None: only a significant rise has a K to time."""
    from scipy.stats import chi2

    edf = np.min(edf_tab, axis=0) if dom is None else edf_tab[dom, np.arange(avar.size)]
    i = int(np.argmin(avar))
    if i >= avar.size - 1:
        return None
    hi_min = avar[i] * edf[i] / chi2.ppf(0.025, edf[i])
    lo = avar[i + 1:] * edf[i + 1:] / chi2.ppf(0.975, edf[i + 1:])
    return float(taus[i]) if np.any(lo > hi_min) else None



#: chi-square a finite K correlation time must gain to be chosen over the random walk:
#: the 99 % point of chi2 with one degree of freedom (a likelihood-ratio test of the one
#: added parameter at 1 %: the time is the best of up to six on a grid and neighbouring
#: octaves are correlated, so the nominal 5 % test (3.84) is passed more often under a
#: pure random walk: measured gains on simulated random walks (MEMS presets, 26 seeds)
#: 0-5.4, on the ADIS16405 accelerometers with a rise that turns over 5.3-21.8,
#: docs/noise-terms.md §10)
K_TIME_PENALTY = 6.635


def _n_shape_params(shapes, i_band, c) -> int:
    """Profiled shape parameters of the chosen grid point that count: the B corners when
    B is in the model, the K correlation time when K is."""
    if shapes is None or i_band == 0:
        return 0
    lo, hi, t_k = shapes.grid[i_band]
    n = (int(lo > 0) + int(math.isfinite(hi))) if c[2] > 0 else 0
    return n + (int(math.isfinite(t_k)) if c[3] > 0 else 0)


class _Shapes(np.ndarray):
    """B and K columns of every grid point, shape (n_grid, k, 2), with the grid
    ``(t_lo, t_hi, t_k)`` (``.grid``) and each point's chi-square penalty (``.penalty``)."""


#: A candidate rule scored by ``benchmarks.method_choice`` (``band-below-rise``), off by
#: default: where the curve rises significantly after its minimum, B bands made only of
#: Gauss–Markov times at or above the minimum's tau (``t_lo >= t_rise``: the band rises
#: after the minimum) are left out of the grid, the rise being K's (GMWM's
#: ``is_slow_process`` reads such processes as K). It named the one rise the default
#: leaves unnamed on the ADIS16405 logs (imu3's first half, ay) and changed no other case,
#: but leave-one-log-out and halves chose it only with that case in training
#: (docs/noise-terms.md §10), so it is not the default.
BAND_BELOW_RISE = False


def _shapes_for(taus, band: bool, avar=None, edf_tab=None):
    """The profiled B and K columns (None without ``band``: IEEE 952's five-term model,
    flat flicker and a pure random walk)."""
    if not band:
        return None
    corners = _corner_grid(taus)
    if BAND_BELOW_RISE and avar is not None:
        t_rise = _rise_start(taus, avar, edf_tab)
        if t_rise is not None:
            corners = [(lo, hi) for lo, hi in corners if lo < t_rise]
    times = [math.inf] if avar is None else _k_time_grid(taus, avar, edf_tab)
    b = _band_table(taus, corners)
    k = np.array([rw_gm_shape(taus, t) for t in times])
    sh = np.stack([np.repeat(b, len(times), axis=0), np.tile(k, (len(corners), 1))],
                  axis=2).view(_Shapes)
    sh.grid = [(lo, hi, t) for lo, hi in corners for t in times]
    sh.penalty = np.array([K_TIME_PENALTY if math.isfinite(t) else 0.0 for _, _, t in sh.grid])
    return sh


def _cross(shapes, i_band):
    """The grid points that share the chosen point's B corners or its K time (and the
    first point, pure flicker and random walk, which wins ties): what each bootstrap
    replicate profiles, at the cost of the two one-dimensional profiles rather than
    their product."""
    if shapes is None:
        return None
    lo, hi, t_k = shapes.grid[i_band]
    keep = [i for i, (a, b, t) in enumerate(shapes.grid)
            if i == 0 or (a, b) == (lo, hi) or t == t_k]
    sub = np.asarray(shapes)[keep].view(_Shapes)
    sub.grid = [shapes.grid[i] for i in keep]
    sub.penalty = shapes.penalty[keep]
    return sub


def _design(X, shapes, i_band):
    if shapes is None:
        return X
    Xc = X.copy()
    Xc[:, 2] = shapes[i_band, :, 0]
    Xc[:, 3] = shapes[i_band, :, 1]
    return Xc
