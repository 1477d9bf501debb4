"""How well a record of given length can determine its noise terms: the Cramér–Rao bound
of a latent rate model under Whittle's likelihood.

A static rate record of ``n`` samples at ``tau0 = 1/rate_hz`` is modelled as

    y_k = w_k + sum_i g_i,k + r_k

with ``w`` white (variance ``sw2`` per sample), ``g_i`` first-order Gauss–Markov
processes (stationary variance ``s_i^2``, ``phi_i = exp(-tau0/Tc_i)``) and ``r`` a
random walk (increment variance ``sr2 = K^2 tau0``). Its first difference is stationary,
with spectrum (radians per sample)

    S(w) = |1 - e^{-iw}|^2 [ sw2 + sum_i s_i^2 (1 - phi_i^2) / |1 - phi_i e^{-iw}|^2 ] + sr2.

Whittle's approximation treats the periodogram ordinates at the Fourier frequencies
``w_j = 2 pi j / n`` (``j = 1 .. n/2 - 1``) as independent exponentials of mean
``S(w_j)``, so the Fisher information of the log-parameters ``theta`` is

    I_ab = sum_j d_a log S(w_j) d_b log S(w_j),

and ``sqrt((I^-1)_aa)`` bounds the standard deviation of any unbiased estimator of
``theta_a`` (asymptotically). For K: ``sd(log K) = sd(log sr2) / 2``; for a term that
is a function of several parameters (K of a Gauss–Markov random walk, B of a band or of
Gauss–Markov processes) the delta method on its gradient (:func:`processes_bounds`).
Two bounds are returned: every other parameter known (an oracle; the least any method can reach) and
every parameter free (what a method that must also estimate the Gauss–Markov sum faces).
A method with a more rigid model than the truth (the Allan fit's band-limited B) may
beat the all-free bound at the cost of a bias; no method beats the oracle bound.

A linear ramp (R) is a constant in the first difference and asymptotically orthogonal
to these parameters; a sensor's internal low-pass filter and its rate quantisation act
on the short taus only and are left out (quantisation adds ``LSB^2/12`` to ``sw2``).

Written here because no maintained Python package computes Whittle Fisher information
for a sum of latent processes (R's ``gmwm``/``simts`` give GMWM's asymptotic covariance,
not the likelihood bound).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from inertialab.errors import InputError

#: Fourier frequencies summed per block (bounds the memory to a few MB per parameter)
BLOCK = 1 << 18
#: median |x| / sd of a normal variable: turns a bound on sd(log K) into a bound on the
#: median |relative error| (for small errors, |K_hat/K - 1| ~ |log K_hat - log K|)
MEDIAN_ABS_NORMAL = 0.6744897501960817


@dataclass(frozen=True)
class KBound:
    """Cramér–Rao bounds on ``log`` of a term (1-sigma; ``term`` is ``"K"``, the default,
    or ``"B"``) for one record: ``known`` (every parameter the term does not depend on
    known), ``free`` (every parameter estimated); ``n`` samples. Their ``*_median_err``
    are the implied floors on the median |relative error| of the term."""

    n: int
    known: float
    free: float
    term: str = "K"

    @property
    def known_median_err(self) -> float:
        return MEDIAN_ABS_NORMAL * self.known

    @property
    def free_median_err(self) -> float:
        return MEDIAN_ABS_NORMAL * self.free

    def to_dict(self) -> dict:
        t = self.term.lower()
        return {"n": self.n, f"sd_log_{t}_known": self.known, f"sd_log_{t}_free": self.free,
                "median_err_known": self.known_median_err,
                "median_err_free": self.free_median_err}


def whittle_information(n: int, sw2: float, gm=(), sr2: float = 0.0) -> tuple:
    """Fisher information matrix of the log-parameters under Whittle's likelihood of the
    first-differenced record (module docstring).

    Parameters
    ----------
    n : int
        Samples in the record.
    sw2 : float
        White-noise variance per sample (> 0).
    gm : sequence of (s2, tc_samples)
        Gauss–Markov processes: stationary variance and correlation time in samples.
    sr2 : float
        Random-walk increment variance per sample (0: no random walk, not a parameter).

    Returns
    -------
    (names, I) : list of str, ndarray (p, p)
        ``names`` in order ``log_sw2``, then ``log_s2_i``, ``log_tc_i`` per process, then
        ``log_sr2`` where ``sr2 > 0``.
    """
    n = int(n)
    if n < 8:
        raise InputError(f"information bound needs at least 8 samples, got {n}")
    if not sw2 > 0:
        raise InputError(f"white-noise variance must be > 0, got {sw2}")
    gm = [(float(s2), float(tc)) for s2, tc in gm]
    if any(not (s2 > 0 and tc > 0) for s2, tc in gm):
        raise InputError(f"Gauss-Markov variances and correlation times must be > 0: {gm}")
    names = ["log_sw2"]
    for i in range(len(gm)):
        names += [f"log_s2_{i}", f"log_tc_{i}"]
    if sr2 > 0:
        names.append("log_sr2")
    p = len(names)
    info = np.zeros((p, p))
    for j, wt in _frequencies(n):
        c = np.cos(2.0 * np.pi * j / n)
        d = 2.0 - 2.0 * c
        grads = [d * sw2]
        s = d * sw2 + sr2
        for s2, tc in gm:
            phi = math.exp(-1.0 / tc)
            den = 1.0 - 2.0 * phi * c + phi * phi
            g = d * s2 * (1.0 - phi * phi) / den
            s = s + g
            # d g / d log tc = d g / d phi * phi / tc
            dg_dphi = d * s2 * (-2.0 * phi * den - (1.0 - phi * phi) * (2.0 * phi - 2.0 * c)) \
                / den**2
            grads += [g, dg_dphi * phi / tc]
        if sr2 > 0:
            grads.append(np.full_like(c, sr2))
        G = np.stack(grads) / s
        info += (G * wt) @ G.T
    return names, info


#: Fourier frequencies summed one by one below this index; above, the sum is the
#: integral of the (smooth) summand on a log grid of :data:`SUM_GRID` points (a
#: 1e10-sample record costs as much as a 1e4-sample one; agreement with the full sum
#: 1e-4 at n = 2^22, test)
SUM_EXACT = 1 << 11
SUM_GRID = 4000


def _frequencies(n: int):
    """Blocks ``(j, weight)`` of Fourier indices ``1 .. n/2 - 1`` for the Whittle sum."""
    last = n // 2 - 1
    top = last if last <= 4 * SUM_EXACT else SUM_EXACT
    for j0 in range(1, top + 1, BLOCK):
        j = np.arange(j0, min(j0 + BLOCK, top + 1), dtype=float)
        yield j, np.ones(j.size)
    if top < last:
        # trapezoid rule in j on a geometric grid from top + 1/2 to last + 1/2
        e = np.geomspace(top + 0.5, last + 0.5, SUM_GRID + 1)
        jm = np.sqrt(e[1:] * e[:-1])
        yield jm, np.diff(e)


#: largest record for :func:`exact_information` (O(n^3) time, ~8 n^2 p bytes of memory)
EXACT_MAX_N = 6000


def exact_information(n: int, sw2: float, gm=(), sr2: float = 0.0) -> tuple:
    """Exact Gaussian Fisher information of the first-differenced record, the check on
    :func:`whittle_information` (same arguments and parameter order):
    ``I_ab = tr(S^-1 dS_a S^-1 dS_b) / 2`` with ``S`` the Toeplitz covariance of the
    differences (white: lags 0, 1 = ``2 sw2, -sw2``; Gauss–Markov: ``2 a(h) - a(h-1) -
    a(h+1)``, ``a(h) = s2 phi^|h|``; random walk: ``sr2`` at lag 0) and analytic
    derivatives. For ``n`` up to :data:`EXACT_MAX_N`; a record of the same length in time
    at a lower rate gives the same K bound once the rate is well above ``1/t_lo``."""
    from scipy.linalg import toeplitz

    n = int(n)
    if not 8 <= n <= EXACT_MAX_N:
        raise InputError(f"exact information needs 8 <= n <= {EXACT_MAX_N}, got {n}")
    lags = np.arange(n + 1, dtype=float)

    def diff_acov(a):  # autocovariance of the first difference from that of the process
        ext = np.concatenate([[a[1]], a])  # a(-1) = a(1)
        return 2.0 * ext[1:n + 1] - ext[:n] - ext[2:n + 2]

    white = np.zeros(n)
    white[:2] = [2.0 * sw2, -sw2]
    comps = [white]
    total = white.copy()
    for s2, tc in gm:
        phi = math.exp(-1.0 / tc)
        g = diff_acov(s2 * phi**lags)
        comps += [g, diff_acov(s2 * lags * phi**lags / tc)]  # d/dlog s2, d/dlog tc
        total += g
    if sr2 > 0:
        rw = np.zeros(n)
        rw[0] = sr2
        comps.append(rw)
        total += rw
    inv = np.linalg.inv(toeplitz(total))
    mats = [inv @ toeplitz(c) for c in comps]
    info = np.array([[0.5 * float(np.sum(a * b.T)) for b in mats] for a in mats])
    names = ["log_sw2"] + [f"log_{k}_{i}" for i in range(len(gm)) for k in ("s2", "tc")]
    return names + (["log_sr2"] if sr2 > 0 else []), info


def k_bound(n: int, sw2: float, gm=(), sr2: float = 0.0, *, exact: bool = False) -> KBound:
    """Cramér–Rao bounds on ``log K`` for a record of ``n`` samples of the model in the
    module docstring (arguments as :func:`whittle_information`; ``sr2 > 0``); ``exact``:
    from :func:`exact_information` instead of Whittle's approximation.

    Examples
    --------
    A random walk seen without white noise: its ``n`` increments are independent, so the
    bound on ``log K`` is ``1 / sqrt(2 n)`` (Fisher information ``n/2`` of ``log sr2``);
    with white noise to separate it from, the bound is wider:

    >>> b = k_bound(4000, 1e-10, sr2=1.0)
    >>> round(b.known * (2 * 4000) ** 0.5, 3)
    1.0
    >>> bool(k_bound(4000, 1.0, sr2=1e-4).known > 20 * b.known), bool(b.free >= b.known)
    (True, True)
    """
    if not sr2 > 0:
        raise InputError("K bound needs a random walk (sr2 > 0)")
    names, info = (exact_information if exact else whittle_information)(n, sw2, gm, sr2)
    k = names.index("log_sr2")
    known = 0.5 / math.sqrt(info[k, k])
    free = 0.5 * math.sqrt(float(np.linalg.inv(info)[k, k]))
    return KBound(n=int(n), known=known, free=free)


def preset_k_bound(preset, hours: float, rate_hz: float | None = None, *,
                   exact: bool = False) -> KBound:
    """:func:`k_bound` of a :class:`inertialab.sim.mems_presets.MemsPreset` logged for
    ``hours`` at ``rate_hz`` (default its own rate): white ``n_white^2 fs + LSB^2/12``,
    its Gauss–Markov processes and its random walk."""
    fs = float(rate_hz or preset.rate_hz)
    n = int(round(hours * 3600.0 * fs))
    sw2 = preset.n_white**2 * fs + preset.lsb**2 / 12.0
    gm = [(s * s, tc * fs) for s, tc in preset.gm]
    return k_bound(n, sw2, gm, preset.k_rw**2 / fs, exact=exact)


def processes_k_bound(processes, tau0: float, n: int, *, k_gm=()) -> KBound:
    """The K bound of :func:`processes_bounds` (an :class:`InputError` where the model
    has no random walk)."""
    k = processes_bounds(processes, tau0, n, k_gm=k_gm)["K"]
    if k is None:
        raise InputError("the model has no random walk: K has no bound to give")
    return k


def processes_bounds(processes, tau0: float, n: int, *, k_gm=(),
                     tau_range_s=None) -> dict:
    """Cramér–Rao bounds on ``log K`` and ``log B`` of a fitted latent model for a record
    of ``n`` samples at ``tau0`` s: how well a record of that length determines K and B
    if the fitted model is the truth (``n`` larger than the record's: the length needed
    for a target). ``{"K": KBound or None, "B": KBound or None}`` (None: the model has
    no such term).

    ``processes``: the latent processes of a :class:`inertialab.noise.gmwm.fit.GmwmFit` or
    of the five-term fit (WN, GM, BL, RW; QN, DR and FL are left out, module docstring).
    The fitted parameters are ``log sw2``, per GM ``log s2`` and ``log tc``, per BL its
    common log amplitude ``log c0`` (its corners held: with every sampled member's
    variance and correlation time free, the information matrix of a band is singular)
    and ``log sr2``. A term that is a function ``f`` of them has the delta-method bound
    ``sd(log f) = sqrt(g' I^-1 g)``, ``g`` the gradient of ``log f`` (``free``); with
    every parameter that ``f`` does not depend on known, ``sqrt(g_s' (I_ss)^-1 g_s)``
    over its support ``s`` (``known``).

    * **K** (rate unit/sqrt(s)): ``K^2 = sr2/tau0 + sum 2 s2_i/tc_i`` over the random
      walk and the GMs whose indices in ``processes`` are listed in ``k_gm`` (a random
      walk held by a Gauss–Markov correlation time: below ``tc`` it is a random walk of
      driving density ``2 s2/tc``), the same K as the Allan fit's ``K^2 = 3 c_1`` and
      GMWM's (:func:`inertialab.noise.gmwm.fit.k_of`).
    * **B**: IEEE 952's flat-region value ``max_tau sigma(tau) / 0.6643`` of the other
      GMs and the BL processes, the B of both fits. A lone BL process (the Allan fit's
      band-limited flicker) has ``B`` proportional to ``sqrt(c0)``: ``g = 1/2`` on
      ``log c0``, independent of where the band peaks. With GMs, the gradient is that
      of ``log AVAR / 2`` at the maximising tau (envelope theorem: the maximiser's own
      shift is second order), over ``tau_range_s`` when given (GMWM reads B on the
      fitted scales), else ``[tau0, 1e3 max tc]``.
    """
    from inertialab.noise.gmwm.covariance import _bl_as_gm

    k_gm = {int(i) for i in k_gm}
    sw2, sr2, gm = 0.0, 0.0, []
    # reduced parameters: (name, columns of the expanded information matrix)
    red_cols, b_procs, k_parts = [("log_sw2", [0])], [], []
    for i, p in enumerate(processes):
        q = p.params
        if p.kind == "WN":
            sw2 += q["sigma2"]
        elif p.kind == "RW":
            sr2 += q["gamma2"]
        elif p.kind == "GM":
            j = len(red_cols)
            red_cols += [(f"log_s2_{i}", [1 + 2 * len(gm)]), (f"log_tc_{i}", [2 + 2 * len(gm)])]
            gm.append((q["s2"], q["tc_s"] / tau0))
            if i in k_gm:
                k_parts.append((2.0 * q["s2"] / q["tc_s"], j))
            else:
                b_procs.append((p, j))
        elif p.kind == "BL":
            members = [(s2, tc / tau0) for s2, tc in _bl_as_gm(q["c0"], q["t_lo_s"],
                                                              q["t_hi_s"], tau0)]
            b_procs.append((p, len(red_cols)))
            red_cols.append((f"log_c0_{i}", [1 + 2 * (len(gm) + m)
                                             for m in range(len(members))]))
            gm += members
    if sr2 > 0:
        red_cols.append(("log_sr2", [1 + 2 * len(gm)]))
    names, info = whittle_information(n, sw2, gm, sr2)
    J = np.zeros((len(names), len(red_cols)))
    for c, (_, rows) in enumerate(red_cols):
        J[rows, c] = 1.0
    red = J.T @ info @ J
    out = {"K": None, "B": None}
    if sr2 > 0 or k_parts:
        g = np.zeros(len(red_cols))
        k2 = sr2 / tau0 + sum(v for v, _ in k_parts)
        if sr2 > 0:
            g[-1] = 0.5 * sr2 / tau0 / k2
        for v, j in k_parts:
            g[j] += 0.5 * v / k2
            g[j + 1] -= 0.5 * v / k2
        out["K"] = _delta_bound(red, g, n, "K")
    if b_procs:
        out["B"] = _delta_bound(red, _b_gradient(b_procs, len(red_cols), tau0, tau_range_s),
                                n, "B")
    return out


def _b_gradient(b_procs, p: int, tau0: float, tau_range_s) -> np.ndarray:
    """Gradient of ``log B`` in the reduced parameters (:func:`processes_bounds`)."""
    g = np.zeros(p)
    if len(b_procs) == 1 and b_procs[0][0].kind == "BL":
        g[b_procs[0][1]] = 0.5
        return g
    if tau_range_s is None:
        hi = 1e3 * max(q.params.get("tc_s", q.params.get("t_hi_s", tau0)) for q, _ in b_procs)
        lo = tau0
    else:
        lo, hi = tau_range_s
    m = np.geomspace(max(lo / tau0, 1.0), max(hi / tau0, 2.0), 1024)
    parts = [q.avar(m, tau0) for q, _ in b_procs]
    k = int(np.argmax(sum(parts)))
    mk = m[k:k + 1]
    tot = float(sum(v[k] for v in parts))
    step = 1e-4
    for (q, j), v in zip(b_procs, parts):
        g[j] = 0.5 * float(v[k]) / tot  # AVAR is linear in s2 (GM) and c0 (BL)
        if q.kind == "GM":
            up, dn = (type(q)("GM", {"s2": q.params["s2"], "tc_s": q.params["tc_s"] * f})
                      for f in (math.exp(step), math.exp(-step)))
            g[j + 1] = 0.5 * float(up.avar(mk, tau0)[0] - dn.avar(mk, tau0)[0]) \
                / (2.0 * step) / tot
    return g


def _delta_bound(red: np.ndarray, g: np.ndarray, n: int, term: str) -> KBound:
    """Delta-method bounds on ``log f`` with gradient ``g`` (:func:`processes_bounds`);
    ``inf`` where the information matrix is singular."""
    s = np.flatnonzero(g)

    def quad(mat, v):
        try:
            return math.sqrt(max(float(v @ np.linalg.solve(mat, v)), 0.0))
        except np.linalg.LinAlgError:
            return math.inf

    return KBound(n=int(n), known=quad(red[np.ix_(s, s)], g[s]), free=quad(red, g),
                  term=term)


__all__ = ["KBound", "exact_information", "k_bound", "preset_k_bound", "processes_bounds",
           "processes_k_bound", "whittle_information"]
