"""Virtual lab for spec 004: daily bias / scale-factor tests of stored quartz accelerometers.

:func:`simulate_storage_batch` draws a batch of units (presets ``paper`` and ``nav``,
spec 004 §7.1-7.2) and returns a record in the ``storage_drift`` schema (§2.1) with
ground-truth columns; :func:`benchmark_process` gives the synthetic series of known
order S1 = NLAR(2) and S2 = NAR(3) of §7.3 (plus the linear AR(2) of acceptance A7).

Model (per unit, t = 0..n_days-1 days)::

    bias [ug] = b0 + A (1 - exp(-t/tau)) + w(t) + kappa_b (T_lab - 20) + eta + nu
    sf [mA/g] = K1 [1 + 1e-6 (s(t) + kappa_k (T_lab - 20) + eta_k + nu_k)],
    s = S_max tanh(x / S_max)

w and x are stationary AR(1) processes (phi = exp(-1/tau_w), innovation std
sigma sqrt(1 - phi^2)); eta/nu (turn-on and measurement) are i.i.d. normal;
T_lab = 20 + 1.5 sin(2 pi (t + t_phi)/365) + AR(1)(0.7, std 0.7) + excursions.

Random streams: ``SeedSequence(seed).spawn(n_units)``, one per unit (spec §7). Within
a unit the draws come in this fixed order: constants (b0, A, sign of A, tau, K1,
kappa_b, kappa_k, t_phi), temperature AR(1) innovations, excursion flags and sizes,
bias wander, SF wander, eta, nu, eta_k, nu_k, missing-day flags, outlier flags and
signs for bias, then for SF.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.limits import bounded, bounded_int, check_budget
from inertialab.seeding import as_generator

GENERATOR_VERSION = "storage-drift/1"

__all__ = [
    "GENERATOR_VERSION",
    "PRESETS",
    "StorageBatch",
    "StoragePreset",
    "benchmark_process",
    "mackey_glass",
    "simulate_storage_batch",
]


@dataclass(frozen=True)
class StoragePreset:
    """Parameter values of spec 004 §7.2 (µg, ppm, days)."""

    a_mean_ug: float
    a_sd_ug: float
    tau_lo_d: float
    tau_hi_d: float
    sigma_w_ug: float
    tau_w_d: float
    sigma_eta_ug: float
    sigma_nu_ug: float
    s_max_ppm: float
    sigma_x_ppm: float
    tau_x_d: float
    sigma_etak_ppm: float
    sigma_nuk_ppm: float
    b0_sd_ug: float = 1500.0
    b0_clip_ug: float = 4000.0
    a_neg_prob: float = 0.3
    k1_lo: float = 1.20
    k1_hi: float = 1.46
    kappa_b_ug_per_c: float = 3.0
    kappa_k_ppm_per_c: float = 15.0
    missing_prob: float = 0.05
    outlier_prob: float = 0.005
    outlier_sigmas: float = 8.0


PRESETS: dict[str, StoragePreset] = {
    "paper": StoragePreset(a_mean_ug=300, a_sd_ug=100, tau_lo_d=10, tau_hi_d=20,
                           sigma_w_ug=20, tau_w_d=10, sigma_eta_ug=50, sigma_nu_ug=10,
                           s_max_ppm=80, sigma_x_ppm=40, tau_x_d=15, sigma_etak_ppm=20,
                           sigma_nuk_ppm=5),
    "nav": StoragePreset(a_mean_ug=30, a_sd_ug=15, tau_lo_d=10, tau_hi_d=30,
                         sigma_w_ug=5, tau_w_d=10, sigma_eta_ug=10, sigma_nu_ug=3,
                         s_max_ppm=40, sigma_x_ppm=15, tau_x_d=15, sigma_etak_ppm=8,
                         sigma_nuk_ppm=3),
}


@dataclass
class StorageBatch:
    """A simulated storage programme.

    Attributes
    ----------
    frame : the record (``storage_drift`` schema, long format, one row per test)
    meta : sidecar metadata (seed, preset, generator version, per-unit K1, tolerances)
    params : per-unit constants (``unit_id``, ``b0_ug``, ``a_ug``, ``tau_d``, ``k1_ma_per_g``,
        ``kappa_b_ug_per_c``, ``kappa_k_ppm_per_c``, ``t_phi_d``)
    """

    frame: pd.DataFrame
    meta: dict
    params: list[dict] = field(default_factory=list)


def _ar1(gen, n, phi, sd):
    """Stationary AR(1) of length n: stationary std ``sd``, innovation std sd sqrt(1-phi^2)."""
    e = gen.normal(0.0, 1.0, n)
    x = np.empty(n)
    x[0] = sd * e[0]
    s_inn = sd * np.sqrt(1.0 - phi * phi)
    for t in range(1, n):
        x[t] = phi * x[t - 1] + s_inn * e[t]
    return x


def _one_unit(gen, n_days, pre: StoragePreset, missing_prob, outliers, skip_weekends, start):
    t = np.arange(n_days, dtype=float)
    b0 = float(np.clip(gen.normal(0.0, pre.b0_sd_ug), -pre.b0_clip_ug, pre.b0_clip_ug))
    a = float(gen.normal(pre.a_mean_ug, pre.a_sd_ug))
    if gen.uniform() < pre.a_neg_prob:
        a = -a
    tau = float(gen.uniform(pre.tau_lo_d, pre.tau_hi_d))
    k1 = float(gen.uniform(pre.k1_lo, pre.k1_hi))
    kb = float(gen.uniform(-pre.kappa_b_ug_per_c, pre.kappa_b_ug_per_c))
    kk = float(gen.uniform(-pre.kappa_k_ppm_per_c, pre.kappa_k_ppm_per_c))
    t_phi = float(gen.uniform(0.0, 365.0))
    # lab temperature
    temp_ar = _ar1(gen, n_days, 0.7, 0.7)
    exc = gen.uniform(size=n_days) < 0.02
    exc_size = gen.uniform(2.0, 4.0, n_days)
    temp = 20.0 + 1.5 * np.sin(2 * np.pi * (t + t_phi) / 365.0) + temp_ar + exc * exc_size
    w = _ar1(gen, n_days, np.exp(-1.0 / pre.tau_w_d), pre.sigma_w_ug)
    x = _ar1(gen, n_days, np.exp(-1.0 / pre.tau_x_d), pre.sigma_x_ppm)
    s = pre.s_max_ppm * np.tanh(x / pre.s_max_ppm)
    eta = gen.normal(0.0, pre.sigma_eta_ug, n_days)
    nu = gen.normal(0.0, pre.sigma_nu_ug, n_days)
    eta_k = gen.normal(0.0, pre.sigma_etak_ppm, n_days)
    nu_k = gen.normal(0.0, pre.sigma_nuk_ppm, n_days)
    missing = gen.uniform(size=n_days) < missing_prob
    missing[0] = False  # day 0 defines t0
    out_b = gen.uniform(size=n_days) < (pre.outlier_prob if outliers else 0.0)
    sgn_b = np.where(gen.uniform(size=n_days) < 0.5, -1.0, 1.0)
    out_k = gen.uniform(size=n_days) < (pre.outlier_prob if outliers else 0.0)
    sgn_k = np.where(gen.uniform(size=n_days) < 0.5, -1.0, 1.0)
    dates = pd.Timestamp(start) + pd.to_timedelta(t, unit="D")
    if skip_weekends:
        missing |= np.asarray(dates.dayofweek >= 5)
        missing[0] = False
    aging = a * (1.0 - np.exp(-t / tau))
    thermal_b = kb * (temp - 20.0)
    outl_b = out_b * sgn_b * pre.outlier_sigmas * pre.sigma_eta_ug
    bias_true = b0 + aging + w + thermal_b
    bias = bias_true + eta + nu + outl_b
    thermal_k = kk * (temp - 20.0)
    outl_k = out_k * sgn_k * pre.outlier_sigmas * pre.sigma_etak_ppm
    sf_true_ppm = s + thermal_k
    sf_ppm = sf_true_ppm + eta_k + nu_k + outl_k
    cols = {
        "date": dates.strftime("%Y-%m-%d"),
        "day": t.astype(int),
        "bias_mg": bias * 1e-3,
        "sf_ma_per_g": k1 * (1.0 + 1e-6 * sf_ppm),
        "temp_c": temp,
        "test_method": "4pos_tumble",
        "true_bias_mg": bias_true * 1e-3,
        "true_sf_ma_per_g": k1 * (1.0 + 1e-6 * sf_true_ppm),
        "bias_aging_mg": aging * 1e-3, "bias_wander_mg": w * 1e-3,
        "bias_thermal_mg": thermal_b * 1e-3, "bias_turnon_mg": eta * 1e-3,
        "bias_meas_mg": nu * 1e-3, "bias_outlier_mg": outl_b * 1e-3,
        "sf_wander_ppm": s, "sf_thermal_ppm": thermal_k, "sf_turnon_ppm": eta_k,
        "sf_meas_ppm": nu_k, "sf_outlier_ppm": outl_k,
        "is_outlier_true": out_b | out_k,
    }
    df = pd.DataFrame(cols)[~missing].reset_index(drop=True)
    params = {"b0_ug": b0, "a_ug": a, "tau_d": tau, "k1_ma_per_g": k1,
              "kappa_b_ug_per_c": kb, "kappa_k_ppm_per_c": kk, "t_phi_d": t_phi}
    return df, params


def simulate_storage_batch(n_units: int = 12, n_days: int = 120, preset: str = "paper",
                           rng=0, *, outliers: bool = True, missing_prob: float | None = None,
                           skip_weekends: bool = False, start_date: str = "2025-01-06"):
    """Simulate a storage programme (spec 004 §7).

    Parameters
    ----------
    n_units : int, default=12
        Number of accelerometers.
    n_days : int, default=120
        Programme length; days 0..n_days-1.
    preset : {"paper", "nav"}, default="paper"
        Parameter set of §7.2.
    rng : int | numpy.random.SeedSequence | None, default=0
        Seed; unit u uses ``SeedSequence(seed).spawn(n_units)[u]``.
    outliers : bool, default=True
        Inject ±8 sigma outliers with probability 0.005 per quantity and day.
    missing_prob : float, optional
        Probability that a day is missing (preset default 0.05).
    skip_weekends : bool, default=False
        Also drop Saturdays and Sundays.
    start_date : str, default="2025-01-06"
        Calendar date of day 0 (a Monday).

    Returns
    -------
    StorageBatch

    Examples
    --------
    Two units over 30 days; each measured bias is its truth plus the turn-on, measurement
    and outlier parts the record also carries:

    >>> import numpy as np
    >>> batch = simulate_storage_batch(n_units=2, n_days=30, rng=0)
    >>> sorted(batch.frame["unit_id"].unique()), int(batch.frame["day"].max()) <= 29
    (['QA001', 'QA002'], True)
    >>> f = batch.frame
    >>> parts = f.true_bias_mg + f.bias_turnon_mg + f.bias_meas_mg + f.bias_outlier_mg
    >>> bool(np.allclose(f.bias_mg, parts))
    True
    >>> outlier = (f.bias_outlier_mg != 0) | (f.sf_outlier_ppm != 0)
    >>> bool(np.all(outlier == f.is_outlier_true)), bool(outlier.any())
    (True, True)
    """
    if preset not in PRESETS:
        raise InputError(f"unknown preset {preset!r} (known: {', '.join(PRESETS)})")
    bounded_int("n_units", n_units, 1, 1_000_000)
    bounded_int("n_days", n_days, 2, 1_000_000)
    if int(n_units) < 1 or int(n_days) < 2:
        raise InputError("need at least 1 unit and 2 days")
    # one row per unit and day, about 16 columns
    check_budget(float(n_units) * float(n_days) * 16 * 8,
                 f"a simulated programme of {n_units} units x {n_days} days")
    if missing_prob is not None:
        bounded("missing_prob", missing_prob, 0.0, 1.0)
    pre = PRESETS[preset]
    mp = pre.missing_prob if missing_prob is None else float(missing_prob)
    if isinstance(rng, np.random.SeedSequence):
        ss = rng
        seed = rng.entropy
    else:
        seed = 0 if rng is None else int(rng)
        ss = np.random.SeedSequence(seed)
    frames, params = [], []
    for u, child in enumerate(ss.spawn(int(n_units))):
        gen = np.random.Generator(np.random.PCG64(child))
        df, p = _one_unit(gen, int(n_days), pre, mp, outliers, skip_weekends, start_date)
        uid = f"QA{u + 1:03d}"
        df.insert(0, "unit_id", uid)
        p = {"unit_id": uid, **p}
        frames.append(df)
        params.append(p)
    frame = pd.concat(frames, ignore_index=True)
    meta = {
        "schema_version": 1, "source": "virtual_lab", "seed": seed,
        "generator_version": GENERATOR_VERSION, "preset": preset,
        "preset_values": asdict(pre), "n_units": int(n_units), "n_days": int(n_days),
        "outliers": bool(outliers), "missing_prob": mp, "skip_weekends": bool(skip_weekends),
        "t0": start_date,
        "k1_nominal_ma_per_g": {p["unit_id"]: p["k1_ma_per_g"] for p in params},
        "tol_bias_ug": 50.0, "tol_sf_ppm": 50.0,
        "unit_params": params,
    }
    return StorageBatch(frame=frame, meta=meta, params=params)


# --------------------------------------------------------------------------------------
# benchmark processes of known order (spec 004 §7.3)
# --------------------------------------------------------------------------------------

def benchmark_process(name: str, n: int, rng=0, *, burn_in: int = 200) -> np.ndarray:
    """Synthetic series of known order (spec 004 §7.3).

    ``"S1"``: NLAR(2) y_t = -0.4 (3 - y1^2)/(1 + y1^2) + 0.6 [3 - (y2 - 0.5)^3]/[1 + (y2 - 0.5)^4] + e,
    y_0 = y_1 = 0. ``"S2"``: NAR(3) y_t = 0.3 y1 + 0.9 tanh(-2 y3) + e, first three values 0.1.
    Both with e ~ N(0, 0.1^2) drawn as one ``normal(0, 0.1, n + burn_in)`` (the draw order
    is part of the benchmark). ``"AR2"``: linear y_t = 0.5 y1 - 0.3 y2 + e, e ~ N(0, 1)
    (acceptance A7), same layout. The first ``burn_in`` values are discarded.

    Parameters
    ----------
    name : {"S1", "S2", "AR2"}
    n : int
        Length returned.
    rng : int | Generator | None, default=0
    """
    gen = as_generator(rng)
    N = int(n) + int(burn_in)
    if name == "S1":
        eps = gen.normal(0.0, 0.1, N)
        y = np.zeros(N)
        for t in range(2, N):
            a, b = y[t - 1], y[t - 2] - 0.5
            y[t] = (-0.4 * (3 - a * a) / (1 + a * a)
                    + 0.6 * (3 - b ** 3) / (1 + b ** 4) + eps[t])
    elif name == "S2":
        eps = gen.normal(0.0, 0.1, N)
        y = np.zeros(N)
        y[:3] = 0.1
        for t in range(3, N):
            y[t] = 0.3 * y[t - 1] + 0.9 * np.tanh(-2.0 * y[t - 3]) + eps[t]
    elif name == "AR2":
        eps = gen.normal(0.0, 1.0, N)
        y = np.zeros(N)
        for t in range(2, N):
            y[t] = 0.5 * y[t - 1] - 0.3 * y[t - 2] + eps[t]
    else:
        raise InputError(f"unknown benchmark process {name!r} (S1, S2, AR2)")
    return y[int(burn_in):].copy()


def mackey_glass(n: int, *, tau: float = 17.0, dt: float = 0.1, t_start: int = 118,
                 x0: float = 1.2) -> np.ndarray:
    """The Mackey-Glass series dx/dt = 0.2 x(t - tau) / (1 + x(t - tau)^10) - 0.1 x(t),
    sampled each unit of time from ``t_start`` on: ``n`` values (deterministic).

    Fourth-order Runge-Kutta with step ``dt`` (the delayed value at half steps is the
    mean of its neighbours), x(t) = 0 for t < 0 and x(0) = ``x0``; tau = 17 gives the
    chaotic regime. Jang (1993), IEEE Trans. SMC 23, §V example 3 uses this set-up
    (t from 118); the NAR's learner benchmark takes it.
    """
    lag = int(round(tau / dt))
    per = int(round(1 / dt))
    total = int(t_start) + int(n)
    m = total * per + 1
    x = np.zeros(m + lag)
    x[lag] = x0

    def f(xt, xd):
        return 0.2 * xd / (1 + xd ** 10) - 0.1 * xt

    for i in range(lag, m + lag - 1):
        xd, xd1 = x[i - lag], x[i - lag + 1]
        xm = 0.5 * (xd + xd1)
        k1 = f(x[i], xd)
        k2 = f(x[i] + dt / 2 * k1, xm)
        k3 = f(x[i] + dt / 2 * k2, xm)
        k4 = f(x[i] + dt * k3, xd1)
        x[i + 1] = x[i] + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x[lag::per][int(t_start):total]
