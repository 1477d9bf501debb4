"""The numerics of the drone-IMU thermal fit: bins, de-quantised temperature, the lag
term, held-out folds, order and lag selection, hysteresis, and PX4's own method as its
script does it (the baseline).

Steps for one sensor stream (:func:`bin_stream`, :func:`select_axis`):

1. **Bins** of ``bin_s`` seconds (default 5 s): the mean reading and the mean reported
   temperature per bin (a 5-s mean is the low-pass both autopilots apply before their
   fits: ArduPilot's 2-s moving average, PX4's 31-sample median).
2. **De-quantised temperature**: the binned reported temperature smoothed by a Gaussian
   of ``sigma_s`` = half the median time the reading stays on one value (at least two
   bins, at most 300 s). A 1 °C staircase at 1 °C/min then leaves < 0.01 °C of ripple,
   and the symmetric kernel adds no lag.
3. **Lag**: the element runs ahead of the die sensor; with a first-order sensor lag the
   element temperature is exactly ``T + tau dT/dt``. ``tau`` is chosen with the order.
4. **Folds** (:func:`folds`): the interior blocks of ``n_blocks`` equal temperature
   blocks, each left out in turn (edge blocks would test extrapolation, which the
   firmware clamps away), plus heating -> cooling and cooling -> heating when the log
   has both directions over at least 10 °C each.
5. **Selection**: polynomial orders 1..``max_order`` in the normalised ``T + tau dT/dt``
   and ``tau`` on a grid 0..300 s; one ``tau`` per sensor (its three axes share the
   die's temperature sensor) minimising the axes' summed held-out mean square, each
   relative to the axis's own minimum; then per axis the smallest order whose held-out
   RMS is within :data:`ORDER_TOLERANCE` of the axis's minimum at that ``tau``. Without
   the heating/cooling folds ``tau`` is 0: on a heating-only ramp the held-out score is
   flat in ``tau`` to 0.5 % (it moves the temperature by a near-constant ``tau`` times
   the heating rate), so the minimum lands anywhere up to 300 s and then fails on a
   ramp at another rate (measured in ``benchmarks/thermal_imu.py``: 1.9x PX4's residual
   with the free ``tau``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter1d

__all__ = ["Binned", "bin_stream", "folds", "hysteresis", "px4_script_fit", "scale_columns", "select_axes", "subset",
           "with_orientations",
           "vander"]

#: Least temperature change per direction (°C) for the heating/cooling folds.
MIN_DIRECTION_SPAN_C = 10.0
#: Relative held-out RMS within which a lower order is preferred (0.1 %: the held-out RMS
#: of a drone log is mostly white noise, so a model error of a tenth of the noise moves it
#: by only 0.5 %; a coarser guard picks too low an order).
ORDER_TOLERANCE = 0.001
#: Order of the scale factor's temperature model (a linear and a quadratic term, as
#: MEMS data sheets give a sensitivity tempco and its curvature).
SCALE_ORDER = 2
#: Slope below which a bin counts as neither heating nor cooling (°C/s; 0.05 °C/min).
STILL_C_PER_S = 0.05 / 60.0


@dataclass
class Binned:
    """One stream in bins: ``t`` (s), ``temp_raw`` (mean reported °C), ``temp`` (smoothed
    °C), ``dtdt`` (°C/s), ``y`` (nb, 3), ``n`` samples per bin, ``sigma_s``,
    ``direction`` (+1 heating, -1 cooling, 0 still) and, for an accelerometer logged in
    several orientations (:func:`with_orientations`), ``grav`` (nb, 3): the nominal
    gravity per bin and axis, already removed from ``y``."""

    t: np.ndarray
    temp_raw: np.ndarray
    temp: np.ndarray
    dtdt: np.ndarray
    y: np.ndarray
    n: np.ndarray
    sigma_s: float
    bin_s: float
    grav: np.ndarray | None = None

    @property
    def direction(self) -> np.ndarray:
        return np.where(self.dtdt > STILL_C_PER_S, 1, np.where(self.dtdt < -STILL_C_PER_S,
                                                                -1, 0))


def _sigma_s(t: np.ndarray, temp: np.ndarray, bin_s: float) -> float:
    """Half the median time the reading needs to move one quantum (the smallest step
    between its distinct values) at the log's rate of change (moving parts only)."""
    levels = np.unique(temp)
    q = float(np.min(np.diff(levels))) if levels.size > 1 else 1.0
    span = float(t[-1] - t[0]) if t.size > 1 else 0.0
    step = min(600.0, span / 10.0) if span > 0 else 0.0
    if step <= 0:
        return 2.0 * bin_s
    coarse = np.interp(np.arange(float(t[0]), float(t[-1]) + 1e-9, step), t, temp)
    rate = np.abs(np.diff(coarse)) / step  # the reading's rate of change on a 600-s grid
    moving = rate[rate > STILL_C_PER_S]
    if moving.size == 0:
        return 2.0 * bin_s
    return float(np.clip(0.5 * q / np.median(moving), 2.0 * bin_s, 300.0))


def smooth_temperature(t_bins, temp_bins, sigma_s: float, bin_s: float):
    """Gaussian-smoothed temperature and its time derivative (°C/s) on uniform bins."""
    temp = gaussian_filter1d(np.asarray(temp_bins, float), sigma_s / bin_s, mode="nearest")
    return temp, np.gradient(temp, t_bins)


def bin_stream(t_s, temp_c, values, *, bin_s: float = 5.0, sigma_s: float | None = None
               ) -> Binned:
    """Bin a stream (steps 1-2 of the module docstring). ``sigma_s``: the smoothing of a
    fitted model (None: chosen from the data)."""
    t = np.asarray(t_s, float)
    k = np.floor((t - t[0]) / bin_s).astype(np.int64)
    nb = int(k[-1]) + 1
    n = np.bincount(k, minlength=nb).astype(float)
    ok = n > 0
    tb = (np.arange(nb) + 0.5) * bin_s + t[0]
    mean = lambda v: np.bincount(k, weights=v, minlength=nb)[ok] / n[ok]  # noqa: E731
    temp_raw = np.interp(tb, tb[ok], mean(np.asarray(temp_c, float)))
    y = np.column_stack([mean(values[:, a]) for a in range(values.shape[1])])
    sig = _sigma_s(t, np.asarray(temp_c, float), bin_s) if sigma_s is None else float(sigma_s)
    temp, dtdt = smooth_temperature(tb, temp_raw, sig, bin_s)
    return Binned(tb[ok], temp_raw[ok], temp[ok], dtdt[ok], y, n[ok], sig, float(bin_s))


def subset(b: Binned, mask) -> Binned:
    """The bins of ``b`` where ``mask`` holds (smoothing and slope kept as computed on
    the whole log)."""
    from dataclasses import replace

    return replace(b, t=b.t[mask], temp_raw=b.temp_raw[mask], temp=b.temp[mask],
                   dtdt=b.dtdt[mask], y=b.y[mask], n=b.n[mask],
                   grav=None if b.grav is None else b.grav[mask])


def with_orientations(b: Binned, *, min_share: float = 0.1):
    """An accelerometer's bins with their orientation: ``(bins, scaled)``. When at least
    one axis sees two or more gravity levels (-g, 0, +g; each in ``min_share`` of the
    clean bins), the bins are kept where the board rested (reading within 5 % of g, one
    axis within 5 % of the whole) and the nominal gravity ``grav`` is removed from ``y``;
    ``scaled`` says per axis whether its scale factor can be fitted. Otherwise ``b``
    unchanged and no axis scaled."""
    norm = np.linalg.norm(b.y, axis=1)
    g = float(np.median(norm))
    level = np.round(b.y / g)
    clean = (np.abs(norm - g) < 0.05 * g) & (np.max(np.abs(b.y), axis=1) > 0.95 * norm) & \
        (np.sum(np.abs(level), axis=1) == 1)
    if clean.sum() < 20:
        return b, np.zeros(b.y.shape[1], bool)
    scaled = np.array([sum(np.mean(level[clean, a] == v) >= min_share for v in (-1, 0, 1)) >= 2
                       and np.any(level[clean, a] != 0) for a in range(b.y.shape[1])])
    if not scaled.any():
        return b, scaled
    out = subset(b, clean)
    out.grav = g * level[clean]
    out.y = out.y - out.grav
    return out, scaled


def vander(temp_eff, center: float, half: float, order: int) -> np.ndarray:
    """Powers 0..order of ``u = (T_eff - center) / half`` (n, order + 1)."""
    u = (np.asarray(temp_eff, float) - center) / half
    return np.vander(u, order + 1, increasing=True)


def folds(b: Binned, n_blocks: int = 6) -> list:
    """Held-out folds ``(label, train mask, test mask)`` (step 4)."""
    lo, hi = float(b.temp.min()), float(b.temp.max())
    edges = np.linspace(lo, hi, n_blocks + 1)
    blk = np.clip(np.searchsorted(edges, b.temp, side="right") - 1, 0, n_blocks - 1)
    out = [(f"block {j + 1}/{n_blocks}", blk != j, blk == j) for j in range(1, n_blocks - 1)]
    d = b.direction
    spans = [np.ptp(b.temp[d == s]) if np.any(d == s) else 0.0 for s in (1, -1)]
    if min(spans) >= MIN_DIRECTION_SPAN_C:
        out += [("heating -> cooling", d == 1, d == -1), ("cooling -> heating", d == -1, d == 1)]
    return out


def _cv_rms_orders(V: np.ndarray, Y: np.ndarray, fold_list, orders, W=None) -> np.ndarray:
    """Held-out RMS per order (len(orders), n_axes) from Gram matrices: the training
    Gram of a fold is the whole Gram minus the left-out part, so one pass per fold.
    ``W``: columns every order keeps (the scale-factor terms of one axis)."""
    if W is not None:
        top, m = V.shape[1], W.shape[1]
        V = np.hstack([V, W])
        cols = [np.r_[0:p + 1, top:top + m] for p in orders]
    else:
        cols = [np.arange(p + 1) for p in orders]
    G, B = V.T @ V, V.T @ Y
    sse = np.zeros((len(orders), Y.shape[1]))
    cnt = 0
    for _, tr, te in fold_list:
        if tr.sum() <= V.shape[1] or not te.any():
            continue
        Vt, Yt = V[te], Y[te]
        Gtr = G - Vt.T @ Vt
        Btr = B - Vt.T @ Yt
        for j, k in enumerate(cols):
            Gk = Gtr[np.ix_(k, k)]
            try:
                c = np.linalg.solve(Gk, Btr[k])
            except np.linalg.LinAlgError:
                c = np.linalg.lstsq(Gk, Btr[k], rcond=None)[0]
            r = Yt - Vt[:, k] @ c
            sse[j] += np.sum(r * r, axis=0)
        cnt += int(te.sum())
    return np.sqrt(sse / cnt) if cnt else np.full_like(sse, np.inf)


@dataclass
class AxisChoice:
    """Selection of one axis: ``order``, ``tau_s``, ``coef`` (powers of u, lowest first),
    ``rms_in``/``rms_cv`` (reading units), the CV table ``grid`` [tau][order-1] and, for a
    scaled axis, ``scale_coef`` (powers 0..:data:`SCALE_ORDER` of u of the scale error)."""

    order: int
    tau_s: float
    coef: np.ndarray
    rms_in: float
    rms_cv: float
    grid: np.ndarray
    taus: np.ndarray
    scale_coef: np.ndarray | None = None


def scale_columns(b: Binned, a: int, t_eff, center: float, half: float):
    """The scale-factor columns of axis ``a`` (powers of u times the nominal gravity)."""
    return vander(t_eff, center, half, SCALE_ORDER) * b.grav[:, a:a + 1]


def select_axes(b: Binned, fold_list, *, center: float, half: float, max_order: int = 7,
                taus=None, orders=None, scaled=None) -> list:
    """Order and lag of each axis of ``b.y`` by held-out RMS (step 5), one
    :class:`AxisChoice` per axis. ``orders``: restrict the orders tried (e.g. ``(3,)``);
    ``taus``: the lag grid (s; default 0..300 s every 5 s)."""
    taus = np.arange(0.0, 301.0, 5.0) if taus is None else np.asarray(taus, float)
    if not any(label.startswith("heating") for label, _, _ in fold_list):
        taus = np.zeros(1)  # no heating/cooling folds: the lag is not identifiable
    orders = tuple(range(1, max_order + 1)) if orders is None else tuple(orders)
    top = max(orders)
    n_ax = b.y.shape[1]
    grid = np.full((taus.size, len(orders), n_ax), np.inf)
    scaled = np.zeros(n_ax, bool) if scaled is None or b.grav is None else np.asarray(scaled)
    for i, tau in enumerate(taus):
        t_eff = b.temp + tau * b.dtdt
        V = vander(t_eff, center, half, top)
        grid[i] = _cv_rms_orders(V, b.y, fold_list, orders)
        for a in np.flatnonzero(scaled):
            grid[i, :, a] = _cv_rms_orders(V, b.y[:, a:a + 1], fold_list, orders,
                                           scale_columns(b, a, t_eff, center, half))[:, 0]
    # one lag per sensor (its axes share the die's temperature sensor): the tau that
    # minimises the sum over axes of each axis's best held-out MS relative to its minimum
    rel = np.min(grid, axis=1) ** 2 / np.min(grid, axis=(0, 1)) ** 2
    i = int(np.argmin(rel.sum(axis=1)))
    out = []
    for a in range(n_ax):
        g = grid[:, :, a]
        best = float(np.min(g[i]))
        j = next(j for j in range(len(orders)) if g[i, j] <= (1.0 + ORDER_TOLERANCE) * best)
        order, tau = orders[j], float(taus[i])
        t_eff = b.temp + tau * b.dtdt
        V = vander(t_eff, center, half, order)
        if scaled[a]:
            V = np.hstack([V, scale_columns(b, a, t_eff, center, half)])
        coef = np.linalg.lstsq(V, b.y[:, a], rcond=None)[0]
        rms_in = float(np.sqrt(np.mean((b.y[:, a] - V @ coef) ** 2)))
        out.append(AxisChoice(order, tau, coef[:order + 1], rms_in, float(g[i, j]), g, taus,
                              coef[order + 1:] if scaled[a] else None))
    return out


def hysteresis(b: Binned, resid: np.ndarray) -> float | None:
    """Mean residual heating minus cooling over the temperatures both cover (reading
    units); None when the log does not have both directions over 10 °C."""
    d = b.direction
    h, c = d == 1, d == -1
    if not (h.any() and c.any()) or min(np.ptp(b.temp[h]), np.ptp(b.temp[c])) < \
            MIN_DIRECTION_SPAN_C:
        return None
    lo = max(b.temp[h].min(), b.temp[c].min())
    hi = min(b.temp[h].max(), b.temp[c].max())
    inside = (b.temp >= lo) & (b.temp <= hi)
    return float(np.mean(resid[h & inside]) - np.mean(resid[c & inside]))


# --------------------------------------------------------------- PX4's method (baseline)

def px4_script_fit(temp_c, values, *, relative: bool, kernel: int = 31, n_bins: int = 2000):
    """PX4's ``process_sensor_caldata.py`` on one sensor: a 31-sample median filter of
    each axis, TMIN/TMAX the extremes of the reported temperature and TREF their middle,
    the samples averaged in 2000 equal temperature bins, an order-3 ``polyfit`` of the
    reading (an accelerometer's minus its median) in ``T - TREF``. Returns ``t_min,
    t_max, t_ref, x`` with ``x`` (4, 3): rows X0..X3."""
    from scipy.signal import medfilt

    t = np.asarray(temp_c, float)
    t_min, t_max = float(t.min()), float(t.max())
    t_ref = 0.5 * (t_min + t_max)
    rel = t - t_ref
    x = np.zeros((4, 3))
    width = (rel.max() - rel.min()) / n_bins
    idx = np.clip(((rel - rel.min()) / width).astype(np.int64), 0, n_bins - 1)
    cnt = np.bincount(idx, minlength=n_bins)
    ok = cnt > 0
    tx = np.bincount(idx, weights=rel, minlength=n_bins)[ok] / cnt[ok]
    for a in range(3):
        v = medfilt(np.asarray(values[:, a], float), kernel)
        if relative:
            v = v - np.median(v)
        vy = np.bincount(idx, weights=v, minlength=n_bins)[ok] / cnt[ok]
        x[:, a] = np.polyfit(tx, vy, 3)[::-1]
    return t_min, t_max, t_ref, x
