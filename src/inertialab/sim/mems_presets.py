"""Virtual-lab MEMS IMU logs that look like real ones.

A static MEMS gyro (or accelerometer) axis logged at its output data rate ``fs``
(100–1000 Hz) for 2–20 h. Each sample is, in the preset's report rate unit (deg/h for
gyros, m/s^2 for accelerometers),

    y_k = Q_lsb * round( LPF[ b0 + w_k + sum_i g_i,k + r_k + c (T_k - T_0) ]_k / Q_lsb )

- ``w``: white rate noise, per-sample std ``N_w sqrt(fs)`` (N_w the continuous density);
- ``g_i``: bias instability as a *sum of first-order Gauss–Markov processes* (exact AR(1)
  discretisation ``g_{k+1} = phi g_k + s sqrt(1 - phi^2) e_k``, ``phi = exp(-tau0/Tc)``,
  started from the stationary law) — not the 1/f model the five-term fit assumes;
- ``r``: rate random walk, increments of std ``K sqrt(tau0)``;
- ``c (T - T0)``: a slow linear temperature ramp ``T_k = T0 + dT/dt t_k`` times the
  uncompensated bias temperature coefficient ``c`` (a rate ramp ``R = c dT/dt``);
- ``LPF``: the sensor's internal digital low-pass (decimation) filter, a Butterworth
  filter of ``lpf_order`` at ``lpf_fraction * fs`` (DC gain 1, so it colours only
  tau below about ``1/(lpf_fraction fs)`` ~ 10 samples and leaves N untouched);
- ``Q_lsb``: rate quantisation to the output register's LSB (dithered by the noise, it
  adds white rate noise of variance ``Q_lsb^2/12`` per sample; it is *not* IEEE angle
  quantisation Q, which stays 0).

Ground truth (:attr:`MemsPreset.truth`, in the report units of
:mod:`inertialab.noise.terms.fit`):

- ``N = sqrt(N_w^2 + Q_lsb^2 / (12 fs))`` (white noise seen at tau >> filter length);
- ``B`` per IEEE Std 952-1997 (the flat region: sigma = 0.6643 B where the slope of the
  bias-instability part is 0): ``B = max_tau sigma_GM(tau) / 0.6643`` with
  ``sigma_GM^2(tau) = sum_i AVAR_AR1(tau; phi_i, s_i^2)`` the exact Allan variance of the
  Gauss–Markov sum (:func:`inertialab.noise.gmwm.fit.avar_ar1`), maximised on a dense tau
  grid (4096 log-spaced points from tau0 to 1e6 s). The textbook reading
  ``min_tau sigma_total(tau)/0.6643`` is :meth:`MemsPreset.textbook_b` (it is larger,
  because N and K add to the minimum);
- ``K`` the random-walk amplitude, ``R = c dT/dt``, ``Q = 0``.

Parameter values are typical of data sheets and published Allan curves of the class
named (consumer ~ ICM-42688/BMI088, industrial ~ ADIS16470), rounded; they were set
before any fit was run on them and are not tuned to a method.

Random streams (fixed order, spawned from ``seed``): white, gm (one child per GM
process), rrw.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace

import numpy as np
import pandas as pd
from scipy.signal import butter, lfilter, sosfilt, sosfilt_zi

from inertialab.errors import InputError
from inertialab.noise.gmwm.fit import avar_ar1, avar_rw, avar_white
from inertialab.seeding import spawn

GENERATOR_VERSION = "mems-presets/1"

#: sqrt(2 ln2 / pi): sigma of flicker rate noise = BI_FACTOR * B (IEEE 952).
BI_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)

_UNITS = {"gyro": {"rate": "deg/h", "N": "deg/sqrt(h)", "B": "deg/h", "K": "deg/h/sqrt(h)",
                   "R": "deg/h^2", "Q": "arcsec", "column": "rate_dph", "unit": "dph"},
          "accel": {"rate": "m/s^2", "N": "m/s/sqrt(h)", "B": "ug", "K": "m/s^2/sqrt(h)",
                    "R": "m/s^3", "Q": "m/s", "column": "acc_mps2", "unit": "mps2"}}
_UG = 9.80665e-6


@dataclass(frozen=True)
class MemsPreset:
    """One MEMS axis. Amplitudes in the rate unit ``u`` (deg/h or m/s^2), times in s.

    Attributes
    ----------
    name, kind : str
    rate_hz : float
        Default output data rate.
    n_white : float
        White-noise density ``u sqrt(s)`` (deg/h/sqrt(Hz); 60 x deg/sqrt(h)).
    gm : tuple of (std, tc_s)
        Gauss–Markov processes of the bias instability: stationary std (u), correlation
        time (s).
    k_rw : float
        Rate random walk ``u / sqrt(s)``.
    tempco : float
        Bias temperature coefficient, u per degC.
    temp_ramp_c_per_h : float
        Ambient temperature ramp, degC/h.
    lsb : float
        Output LSB in u (0: not quantised).
    lpf_fraction, lpf_order : float, int
        Internal low-pass cut-off as a fraction of ``rate_hz`` and its order.
    b0 : float
        Turn-on bias, u.
    """

    name: str
    kind: str
    rate_hz: float
    n_white: float
    gm: tuple
    k_rw: float
    tempco: float
    temp_ramp_c_per_h: float
    lsb: float
    lpf_fraction: float = 0.1
    lpf_order: int = 2
    b0: float = 0.0
    note: str = ""

    def with_(self, **kw) -> MemsPreset:
        return replace(self, **kw)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["gm"] = [list(g) for g in self.gm]
        return d

    # ------------------------------------------------------------------ truth
    def n_total(self, rate_hz: float | None = None) -> float:
        """White density including the quantisation's white noise (u sqrt(s))."""
        fs = float(rate_hz or self.rate_hz)
        return math.sqrt(self.n_white**2 + self.lsb**2 / (12.0 * fs))

    def gm_avar(self, taus_s, rate_hz: float | None = None) -> np.ndarray:
        """Exact Allan variance of the Gauss–Markov sum at ``taus_s`` (u^2)."""
        tau0 = 1.0 / float(rate_hz or self.rate_hz)
        m = np.asarray(taus_s, dtype=float) / tau0
        out = np.zeros(m.shape)
        for std, tc in self.gm:
            out += avar_ar1(m, math.exp(-tau0 / tc), std * std)
        return out

    def b_ieee(self, rate_hz: float | None = None) -> float:
        """IEEE 952 flat-region B of the GM sum (module docstring), in u."""
        fs = float(rate_hz or self.rate_hz)
        taus = np.geomspace(1.0 / fs, 1e6, 4096)
        return float(np.sqrt(self.gm_avar(taus, fs).max()) / BI_FACTOR)

    def ramp(self) -> float:
        """Rate ramp ``R = tempco * dT/dt`` in u/s."""
        return self.tempco * self.temp_ramp_c_per_h / 3600.0

    def model_avar(self, taus_s, rate_hz: float | None = None) -> np.ndarray:
        """Allan variance of the unfiltered model (white incl. quantisation, GM sum, RRW,
        ramp) at ``taus_s``; exact above the filter's reach (tau >~ 10 samples)."""
        fs = float(rate_hz or self.rate_hz)
        tau0 = 1.0 / fs
        t = np.asarray(taus_s, dtype=float)
        m = t / tau0
        n2 = self.n_total(fs) ** 2
        out = avar_white(m, n2 * fs) + self.gm_avar(t, fs)
        out = out + avar_rw(m, self.k_rw**2 * tau0) + 0.5 * (self.ramp() * t) ** 2
        return out

    def textbook_b(self, rate_hz: float | None = None) -> float:
        """``min_tau sigma_model(tau) / 0.6643`` (u): what the textbook reading gives on
        the noise-free curve."""
        fs = float(rate_hz or self.rate_hz)
        taus = np.geomspace(10.0 / fs, 1e5, 2048)
        return float(np.sqrt(self.model_avar(taus, fs).min()) / BI_FACTOR)

    def truth(self, rate_hz: float | None = None) -> dict:
        """True terms in the report units (module docstring)."""
        fs = float(rate_hz or self.rate_hz)
        u = _UNITS[self.kind]
        n = self.n_total(fs)
        k = self.k_rw
        if self.kind == "gyro":  # deg/h sqrt(s) -> deg/sqrt(h); deg/h/sqrt(s) -> /sqrt(h)
            vals = {"Q": 0.0, "N": n / 60.0, "B": self.b_ieee(fs), "K": k * 60.0,
                    "R": self.ramp() * 3600.0}
        else:  # m/s^2 sqrt(s) -> m/s/sqrt(h) (x 60); B in ug; R in m/s^3
            vals = {"Q": 0.0, "N": n * 60.0, "B": self.b_ieee(fs) / _UG, "K": k * 60.0,
                    "R": self.ramp()}
        return {name: {"value": float(v), "unit": u[name]} for name, v in vals.items()}


def _gyro(name, rate_hz, arw_deg_rth, gm, rrw_dph_rth, tempco_dph_c, ramp_c_h, lsb_dps,
          note, **kw):
    return MemsPreset(name=name, kind="gyro", rate_hz=rate_hz, n_white=arw_deg_rth * 60.0,
                      gm=tuple(gm), k_rw=rrw_dph_rth / 60.0, tempco=tempco_dph_c,
                      temp_ramp_c_per_h=ramp_c_h, lsb=lsb_dps * 3600.0, note=note, **kw)


#: The presets (module docstring). Gyro amplitudes: ARW deg/sqrt(h), GM std deg/h,
#: RRW deg/h/sqrt(h), tempco deg/h/degC, LSB deg/s.
PRESETS: dict[str, MemsPreset] = {
    p.name: p for p in (
        _gyro("consumer-100hz", 100.0, 0.30, ((3.0, 4.0), (2.5, 40.0), (2.0, 400.0)), 10.0,
              18.0, 0.1, 1.0 / 131.0,
              "ICM-42688-class consumer gyro, +-250 dps 16-bit, 100 Hz ODR, 2nd-order LPF at "
              "10 Hz", b0=500.0),
        _gyro("industrial-400hz", 400.0, 0.15, ((1.2, 10.0), (1.0, 100.0), (0.8, 1000.0)), 2.0,
              2.0, 0.2, 0.00025,
              "ADIS16470-class industrial gyro, 400 Hz ODR, 3rd-order LPF at 40 Hz",
              lpf_order=3, b0=50.0),
        _gyro("consumer-1khz", 1000.0, 0.50, ((6.0, 2.0), (5.0, 20.0), (4.0, 200.0)), 20.0,
              36.0, 0.3, 2000.0 / 32768.0,
              "BMI088-class drone gyro, +-2000 dps 16-bit, 1 kHz ODR, 2nd-order LPF at 100 Hz",
              b0=1800.0),
        MemsPreset(name="accel-200hz", kind="accel", rate_hz=200.0,
                   n_white=150e-6 * 9.80665, gm=((20e-6 * 9.80665, 10.0),
                                                 (15e-6 * 9.80665, 150.0)),
                   k_rw=2e-6 * 9.80665, tempco=50e-6 * 9.80665, temp_ramp_c_per_h=0.1,
                   lsb=0.061e-3 * 9.80665, b0=5e-3 * 9.80665,
                   note="consumer accelerometer, 150 ug/sqrt(Hz), +-2 g 16-bit, 200 Hz"),
    )
}


def preset(name: str) -> MemsPreset:
    """A preset by name (:data:`PRESETS`)."""
    try:
        return PRESETS[name]
    except KeyError:
        raise InputError(f"unknown MEMS preset '{name}' (use {', '.join(PRESETS)})") from None


@dataclass(frozen=True)
class MemsRun:
    """A simulated static MEMS log.

    ``y``: samples in the report rate unit (deg/h or m/s^2); ``unit``: its suffix
    ('dph' or 'mps2') for :func:`inertialab.noise.terms.fit.fit_noise_terms`; ``truth``:
    the true terms; ``meta``: sidecar-style metadata; ``temperature_c``: the ramp.
    """

    y: np.ndarray
    rate_hz: float
    unit: str
    kind: str
    truth: dict
    meta: dict = field(default_factory=dict)
    temperature_c: np.ndarray | None = None

    def record(self) -> pd.DataFrame:
        """``t_s``, the rate column and ``temp_c`` as a record table."""
        col = _UNITS[self.kind]["column"]
        t = np.arange(self.y.size) / self.rate_hz
        return pd.DataFrame({"t_s": t, col: self.y, "temp_c": self.temperature_c})


def simulate(name: str | MemsPreset = "consumer-100hz", *, hours: float = 10.0,
             rate_hz: float | None = None, seed: int = 0, t0_c: float = 25.0) -> MemsRun:
    """Simulate one static MEMS axis (module docstring).

    Parameters
    ----------
    name : str or MemsPreset
    hours : float, default 10
        Record length (2–20 h is the documented range; any positive length runs).
    rate_hz : float, optional
        Output data rate (default the preset's); the filter scales with it.
    seed : int, default 0
    t0_c : float, default 25
        Starting temperature, degC.
    """
    p = name if isinstance(name, MemsPreset) else preset(name)
    fs = float(rate_hz or p.rate_hz)
    if not (math.isfinite(hours) and hours > 0 and math.isfinite(fs) and fs > 0):
        raise InputError(f"hours and rate_hz must be positive, got {hours}, {fs}")
    n = int(round(hours * 3600.0 * fs))
    if n < 64:
        raise InputError(f"record too short: {n} samples (hours x 3600 x rate_hz)")
    tau0 = 1.0 / fs
    # in place into two buffers (no temporaries of the record's length beyond lfilter's
    # and sosfilt's outputs): the same operations in the same order as the plain
    # expressions, so the output is bit-identical for a seed (tests/sim)
    streams = spawn(seed, 2 + len(p.gm))
    y = np.empty(n)
    e = np.empty(n)
    streams[0].standard_normal(out=y)
    y *= p.n_white * math.sqrt(fs)
    for (std, tc), rng in zip(p.gm, streams[1:1 + len(p.gm)]):
        phi = math.exp(-tau0 / tc)
        rng.standard_normal(out=e)
        e *= std * math.sqrt(1.0 - phi * phi)
        e[0] = rng.standard_normal() * std  # stationary start
        y += lfilter([1.0], [1.0, -phi], e)
    if p.k_rw > 0:
        streams[-1].standard_normal(out=e)
        e *= p.k_rw * math.sqrt(tau0)
        np.cumsum(e, out=e)
        y += e
    temp = np.arange(n, dtype=float)
    temp *= tau0
    temp *= p.temp_ramp_c_per_h
    temp /= 3600.0
    temp += t0_c
    np.subtract(temp, t0_c, out=e)
    e *= p.tempco
    e += p.b0
    y += e
    del e
    if p.lpf_fraction > 0:
        sos = butter(p.lpf_order, 2.0 * p.lpf_fraction, output="sos")
        y = sosfilt(sos, y, zi=sosfilt_zi(sos) * y[0])[0]
    if p.lsb > 0:
        y /= p.lsb
        np.round(y, out=y)
        y *= p.lsb
    u = _UNITS[p.kind]
    meta = {"fs_hz": fs, "units": {"rate": u["unit"]}, "source": "virtual_lab",
            "seed": int(seed), "generator_version": GENERATOR_VERSION, "preset": p.name,
            "hours": float(hours), "mems": p.to_dict(), "truth_terms": p.truth(fs),
            "textbook_b": float(p.textbook_b(fs)) * (1.0 if p.kind == "gyro" else 1 / _UG)}
    return MemsRun(y=y, rate_hz=fs, unit=u["unit"], kind=p.kind, truth=p.truth(fs),
                   meta=meta, temperature_c=temp)


__all__ = ["BI_FACTOR", "GENERATOR_VERSION", "MemsPreset", "MemsRun", "PRESETS", "preset",
           "simulate"]
