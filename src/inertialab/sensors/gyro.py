"""Static FOG output and noise model (spec 001 §6.2; IEEE Std 952-1997 Annex C).

The rate output in deg/h is

    omega_k = input_k + b0 + white_k + bi_k + rrw_k + ramp_k   (then angle quantization)

with, per sample k at rate ``fs`` (``tau0 = 1/fs``):

- white rate (ARW N, deg/sqrt(h)): ``Normal(0, (60 N)^2 fs)``, two-sided PSD N^2;
- bias instability (B, deg/h): the sum of five first-order Gauss–Markov processes with
  correlation times ``gm_tc_s`` (default 0.3, 3, 30, 300, 3000 s) and stationary std
  ``0.84 B`` each, exact discretisation ``z_{k+1} = a z_k + s sqrt(1-a^2) e_k`` started
  from the stationary law; or (``bi_model="kasdin"``) 1/f noise by Kasdin's fractional
  filter ``(1 - z^-1)^(-1/2)`` driven by white noise of std B;
- rate random walk (K, deg/h/sqrt(h)): ``r_{k+1} = r_k + (K/60) sqrt(tau0) e_k``;
- rate ramp (R, deg/h^2): ``(R/3600) t_k``;
- angle quantization with LSB ``q_arcsec``: ``Theta_k = tau0 sum_{i<k} omega_i`` (+ white
  angle noise of std ``angle_white_arcsec`` + jitter of std ``j_k q/sqrt(12)``), output
  angle ``q floor(Theta_k/q)``, rate ``(q floor(Theta_{k+1}/q) - q floor(Theta_k/q))/tau0``.

Random streams are spawned from ``rng`` in this fixed order (spec 001 §6.2): white,
GM1..GM5, RRW, jitter, spare (the spare stream draws the white angle noise and the
Kasdin driving noise). The streams are independent child generators, so one stream
never depends on another's settings (a zero-amplitude stream is simply not drawn), and
the vibration rig can scale them per sample through
``multipliers`` (an object with arrays ``white``, ``gm``, ``rrw``, ``jitter``, e.g.
:class:`inertialab.sensors.gyro_vibration.NoiseMultipliers`).

Hand-written because no maintained library simulates this five-term gyro model with
exact Gauss–Markov discretisation and integrate-then-quantize output.

References
----------
IEEE Std 952-1997 Annex C; Kasdin (1995), Proc. IEEE 83(5) §IV; spec 001 §3.3, §6.2.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np
from scipy.signal import fftconvolve, lfilter
from scipy.special import sici

from inertialab import units
from inertialab.errors import InputError
from inertialab.seeding import spawn

#: Order of the child streams spawned from ``rng``.
STREAMS = ("white", "gm1", "gm2", "gm3", "gm4", "gm5", "rrw", "jitter", "spare")

_ARW_NATIVE = units.convert(1.0, "deg/sqrt(h)", "deg/h/sqrt(Hz)")  # = 60
_RRW_NATIVE = units.convert(units.convert(1.0, "deg/h/sqrt(h)", "rad/s/sqrt(s)"), "rps", "dph")
_RAMP_NATIVE = units.convert(units.convert(1.0, "deg/h^2", "rad/s^2"), "rps", "dph")


@dataclass(frozen=True)
class GyroNoiseParams:
    """Parameters of the static FOG model (spec 001 §6.2 "mid" preset by default).

    Attributes
    ----------
    arw_deg_rth : float, default 0.01
        Angle random walk N in deg/sqrt(h).
    bias_instability_dph : float, default 0.15
        Bias instability B in deg/h (Allan floor 0.6643 B).
    rrw_dph_rth : float, default 0.05
        Rate random walk K in deg/h/sqrt(h).
    ramp_dph_per_h : float, default 0.05
        Rate ramp R in deg/h^2.
    q_arcsec : float, default 0.1
        Angle LSB q in arcsec (0: no quantization). Q = q/sqrt(12).
    b0_dph : float, default 0.5
        Constant bias in deg/h.
    angle_white_arcsec : float, default 0.0
        Extra white angle noise std in arcsec (a Q term without a quantizer).
    bi_model : {"gm", "kasdin"}, default "gm"
    gm_tc_s : tuple of float, default (0.3, 3, 30, 300, 3000)
        Gauss–Markov correlation times in s.
    gm_std_factor : float, default 0.84
        Stationary std of each GM process in units of B.

    Examples
    --------
    >>> mid = GyroNoiseParams()
    >>> mid.arw_deg_rth, mid.bias_instability_dph
    (0.01, 0.15)
    >>> white = mid.with_(bias_instability_dph=0.0, rrw_dph_rth=0.0, ramp_dph_per_h=0.0)
    >>> GyroNoiseParams.from_dict(white.to_dict()) == white
    True
    """

    arw_deg_rth: float = 0.01
    bias_instability_dph: float = 0.15
    rrw_dph_rth: float = 0.05
    ramp_dph_per_h: float = 0.05
    q_arcsec: float = 0.1
    b0_dph: float = 0.5
    angle_white_arcsec: float = 0.0
    bi_model: str = "gm"
    gm_tc_s: tuple = (0.3, 3.0, 30.0, 300.0, 3000.0)
    gm_std_factor: float = 0.84

    def to_dict(self) -> dict:
        d = asdict(self)
        d["gm_tc_s"] = list(self.gm_tc_s)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> GyroNoiseParams:
        d = dict(d)
        if "gm_tc_s" in d:
            d["gm_tc_s"] = tuple(float(v) for v in d["gm_tc_s"])
        return cls(**d)

    def with_(self, **kw) -> GyroNoiseParams:
        """A copy with some fields replaced."""
        return replace(self, **kw)


#: Presets of spec 001 §6.2 plus the noise core's identification presets.
PRESETS: dict[str, GyroNoiseParams] = {
    "mid": GyroNoiseParams(),
    "nav": GyroNoiseParams(arw_deg_rth=0.002, bias_instability_dph=0.01, rrw_dph_rth=0.005,
                           ramp_dph_per_h=0.005, q_arcsec=0.05),
    "tactical": GyroNoiseParams(arw_deg_rth=0.1, bias_instability_dph=1.0, rrw_dph_rth=0.5,
                                ramp_dph_per_h=0.5, q_arcsec=1.0),
    # spec 001 §6.2 identification presets (10 h at 10 Hz): N and K, and N and B
    "allan-rrw": GyroNoiseParams(arw_deg_rth=0.002, bias_instability_dph=0.0, rrw_dph_rth=1.0,
                                 ramp_dph_per_h=0.0, q_arcsec=0.0),
    "allan-bi": GyroNoiseParams(arw_deg_rth=0.01, bias_instability_dph=0.1, rrw_dph_rth=0.0,
                                ramp_dph_per_h=0.0, q_arcsec=0.0),
    # known Q, N, B, K in one record (spec 001 §7 check 9 without the ramp; GM times
    # extended by two decades so the floor is flat to the longest taus)
    "allan-test": GyroNoiseParams(arw_deg_rth=0.01, bias_instability_dph=0.1, rrw_dph_rth=0.1,
                                  ramp_dph_per_h=0.0, q_arcsec=0.0, angle_white_arcsec=0.5,
                                  gm_tc_s=(0.3, 3.0, 30.0, 300.0, 3000.0, 3.0e4)),
}


def preset(name: str) -> GyroNoiseParams:
    """The named preset (:data:`PRESETS`); unknown names are an InputError.

    Examples
    --------
    >>> preset("nav").arw_deg_rth, preset("tactical").bias_instability_dph
    (0.002, 1.0)
    >>> preset("best")
    Traceback (most recent call last):
    ...
    inertialab.errors.InputError: unknown gyro preset 'best' (use mid, nav, tactical, ...)
    """
    try:
        return PRESETS[name]
    except KeyError:
        raise InputError(f"unknown gyro preset '{name}' (use {', '.join(PRESETS)})") from None


@dataclass(frozen=True)
class GyroNoiseComponents:
    """The simulated output and its parts, all in deg/h, shape (n,).

    ``quantization`` is the rate error of the angle quantizer, white angle noise and
    jitter together (output minus the unquantized rate).
    """

    rate_dph: np.ndarray
    white: np.ndarray
    bias_instability: np.ndarray
    rrw: np.ndarray
    ramp: np.ndarray
    quantization: np.ndarray
    b0_dph: float


def _mult(multipliers, name: str, n: int):
    if multipliers is None:
        return None
    v = getattr(multipliers, name, None)
    if v is None:
        return None
    v = np.asarray(v, dtype=float)
    if v.ndim == 0:
        return float(v)
    if v.shape != (n,) and not (name == "jitter" and v.shape == (n + 1,)):
        raise InputError(f"multiplier '{name}' has shape {v.shape}, expected ({n},)")
    return v


def _gauss_markov(e: np.ndarray, tc: float, std: float, tau0: float, mult) -> np.ndarray:
    a = math.exp(-tau0 / tc)
    v = e * (std * math.sqrt(1.0 - a * a))
    if mult is not None:
        v *= mult
    v[0] = std * e[0]  # stationary initial state
    return lfilter([1.0], [1.0, -a], v)


def kasdin_flicker(e: np.ndarray) -> np.ndarray:
    """1/f noise: white ``e`` through ``(1 - z^-1)^(-1/2)`` (Kasdin 1995, alpha = -1)."""
    n = e.size
    h = np.empty(n)
    h[0] = 1.0
    k = np.arange(1, n, dtype=float)
    h[1:] = np.cumprod((k - 0.5) / k)
    return fftconvolve(e, h)[:n]


def simulate_gyro_components(n: int, fs_hz: float, params: GyroNoiseParams | str = "mid",
                             rng=None, *, input_rate_dph=0.0,
                             multipliers=None) -> GyroNoiseComponents:
    """Simulate the static FOG output with its components (see module docstring).

    Parameters
    ----------
    n : int
        Number of samples.
    fs_hz : float
        Output rate in Hz.
    params : GyroNoiseParams or str, default "mid"
        Parameters or a preset name.
    rng : int, Generator or None
        Seed; the nine child streams are spawned in :data:`STREAMS` order.
    input_rate_dph : float or ndarray (n,), default 0
        True input rate plus any deterministic effect (Earth rate, vibration bias,
        lines ...) in deg/h; added before the angle quantizer.
    multipliers : object with ``white``, ``gm``, ``rrw``, ``jitter`` arrays, optional
        Per-sample scale of the white rate, GM driving noise, RRW increments, and the
        jitter std in units of ``q/sqrt(12)`` (0 when absent).
    """
    p = preset(params) if isinstance(params, str) else params
    n = int(n)
    if n < 1:
        raise InputError(f"number of samples must be >= 1, got {n}")
    fs = float(fs_hz)
    if not math.isfinite(fs) or fs <= 0:
        raise InputError(f"sample rate must be positive, got {fs_hz}")
    tau0 = 1.0 / fs
    if p.bi_model not in ("gm", "kasdin"):
        raise InputError(f"bi_model must be 'gm' or 'kasdin', got '{p.bi_model}'")
    gens = spawn(rng, len(STREAMS))
    g = dict(zip(STREAMS, gens))

    # Child streams are independent, so a stream whose amplitude is zero is not drawn
    # at all; the other streams' values do not change.
    if p.arw_deg_rth > 0:
        white = g["white"].standard_normal(n) * (_ARW_NATIVE * p.arw_deg_rth * math.sqrt(fs))
        mw = _mult(multipliers, "white", n)
        if mw is not None:
            white *= mw
    else:
        white = np.zeros(n)

    bi = np.zeros(n)
    mg = _mult(multipliers, "gm", n)
    tcs = list(p.gm_tc_s)
    s = p.gm_std_factor * p.bias_instability_dph
    gm_streams = [g[f"gm{i}"] for i in range(1, 6)]
    for i, tc in enumerate(tcs):
        # five spawned GM streams; extra processes (extended presets) use child
        # streams of the fifth, so the first five never change
        if p.bi_model == "gm" and s > 0:
            gen = gm_streams[i] if i < 5 else gm_streams[4].spawn(i - 4)[-1]
            bi += _gauss_markov(gen.standard_normal(n), float(tc), s, tau0, mg)

    rrw = np.zeros(n)
    if p.rrw_dph_rth > 0:
        inc = g["rrw"].standard_normal(n) * (_RRW_NATIVE * p.rrw_dph_rth * math.sqrt(tau0))
        mr = _mult(multipliers, "rrw", n)
        if mr is not None:
            inc *= mr
        np.cumsum(inc[:-1], out=rrw[1:])

    ramp = (_RAMP_NATIVE * p.ramp_dph_per_h) * (np.arange(n) * tau0)

    # spare stream: white angle noise (n+1 values) first, then Kasdin driving noise
    e_ang = g["spare"].standard_normal(n + 1)
    if p.bi_model == "kasdin" and p.bias_instability_dph > 0:
        bi = kasdin_flicker(g["spare"].standard_normal(n)) * p.bias_instability_dph
        if mg is not None:
            bi *= mg

    rate = np.asarray(input_rate_dph, dtype=float) + p.b0_dph + white + bi + rrw + ramp
    rate = np.broadcast_to(rate, (n,)).astype(float, copy=True)

    mj = _mult(multipliers, "jitter", n)
    q = float(p.q_arcsec)
    need_angle = q > 0 or p.angle_white_arcsec > 0 or mj is not None
    if need_angle:
        theta = np.empty(n + 1)
        theta[0] = 0.0
        np.cumsum(rate * tau0, out=theta[1:])
        err = e_ang * p.angle_white_arcsec
        if mj is not None and q > 0:
            jm = mj if np.ndim(mj) == 0 or np.shape(mj) == (n + 1,) else np.r_[mj, mj[-1]]
            e_jit = g["jitter"].standard_normal(n + 1)
            err = err + e_jit * (jm * q / math.sqrt(12.0))
        theta_out = theta + err
        if q > 0:
            theta_out = q * np.floor(theta_out / q)
        out = np.diff(theta_out) / tau0
        quant = out - rate
    else:
        out = rate
        quant = np.zeros(n)
    return GyroNoiseComponents(rate_dph=out, white=white, bias_instability=bi, rrw=rrw,
                               ramp=ramp, quantization=quant, b0_dph=float(p.b0_dph))


def simulate_gyro_noise(n: int, fs_hz: float, params: GyroNoiseParams | str = "mid", rng=None,
                        *, input_rate_dph=0.0, multipliers=None) -> np.ndarray:
    """Static FOG rate output in deg/h, shape (n,) (stable signature; see
    :func:`simulate_gyro_components` for the parameters and the truth components).

    Examples
    --------
    Angle random walk alone, N = 0.1 deg/sqrt(h) at 10 Hz: white rate noise of std
    ``N * 60 * sqrt(fs)`` deg/h about the constant bias b0 = 0.5 deg/h:

    >>> import numpy as np
    >>> arw = GyroNoiseParams(arw_deg_rth=0.1, bias_instability_dph=0.0, rrw_dph_rth=0.0,
    ...                       ramp_dph_per_h=0.0, q_arcsec=0.0, b0_dph=0.5)
    >>> rate = simulate_gyro_noise(20_000, 10.0, arw, rng=0)
    >>> bool(np.isclose(rate.std(), 0.1 * 60 * np.sqrt(10.0), rtol=0.02))
    True
    >>> bool(abs(rate.mean() - 0.5) < 3 * rate.std() / np.sqrt(rate.size))
    True
    """
    return simulate_gyro_components(n, fs_hz, params, rng, input_rate_dph=input_rate_dph,
                                    multipliers=multipliers).rate_dph


# ----------------------------------------------------------------------------- analytic AVAR


def gm_avar(tau, tc: float, std: float) -> np.ndarray:
    """AVAR of a first-order Gauss–Markov process of stationary std ``std`` (spec 001 §3.3):
    ``(q_c T_c)^2/tau [1 - T_c/(2 tau)(3 - 4 e^{-tau/T_c} + e^{-2 tau/T_c})]``,
    ``q_c^2 = 2 std^2/T_c``."""
    tau = np.asarray(tau, dtype=float)
    qc2 = 2.0 * std * std / tc
    x = tau / tc
    return qc2 * tc * tc / tau * (1.0 - (3.0 - 4.0 * np.exp(-x) + np.exp(-2.0 * x)) / (2.0 * x))


def flicker_avar(tau, B: float, f0: float | None = None) -> np.ndarray:
    """AVAR of bias instability B (deg/h): ``(2 ln2/pi) B^2`` or, with a cut-off ``f0``,
    the full IEEE 952 C.1.3 curve (spec 001 §3.3)."""
    tau = np.asarray(tau, dtype=float)
    if f0 is None:
        return np.full(tau.shape, 2.0 * math.log(2.0) / math.pi * B * B)
    x = math.pi * f0 * tau
    ci2 = sici(2 * x)[1]
    ci4 = sici(4 * x)[1]
    return 2 * B * B / math.pi * (math.log(2.0) - np.sin(x) ** 3 * (np.sin(x) + 4 * x * np.cos(x))
                                  / (2 * x * x) + ci2 - ci4)


def model_avar(tau, params: GyroNoiseParams | str = "mid") -> np.ndarray:
    """Analytic AVAR (deg/h)^2 of the simulated output at ``tau`` (s), continuous-time
    formulas: Q from ``q/sqrt(12)`` and the white angle noise, N, the GM sum (or the
    flicker floor for Kasdin), K and R. The quantizer is modelled as white angle noise
    (valid while the per-sample angle noise exceeds ~0.4 q, spec 001 §6.2)."""
    p = preset(params) if isinstance(params, str) else params
    tau = np.asarray(tau, dtype=float)
    q2 = p.q_arcsec**2 / 12.0 + p.angle_white_arcsec**2
    n_nat = _ARW_NATIVE * p.arw_deg_rth
    k_nat = _RRW_NATIVE * p.rrw_dph_rth
    r_nat = _RAMP_NATIVE * p.ramp_dph_per_h
    av = 3 * q2 / tau**2 + n_nat**2 / tau + k_nat**2 * tau / 3 + r_nat**2 * tau**2 / 2
    if p.bias_instability_dph > 0:
        if p.bi_model == "gm":
            s = p.gm_std_factor * p.bias_instability_dph
            for tc in p.gm_tc_s:
                av = av + gm_avar(tau, float(tc), s)
        else:
            av = av + flicker_avar(tau, p.bias_instability_dph)
    return av


def native_terms(params: GyroNoiseParams | str) -> dict:
    """The preset's Q N B K R in the report units of docs/noise-terms.md (arcsec, deg/sqrt(h),
    deg/h, deg/h/sqrt(h), deg/h^2); Q combines ``q/sqrt(12)`` and the white angle noise."""
    p = preset(params) if isinstance(params, str) else params
    return {"Q": math.sqrt(p.q_arcsec**2 / 12.0 + p.angle_white_arcsec**2),
            "N": p.arw_deg_rth, "B": p.bias_instability_dph, "K": p.rrw_dph_rth,
            "R": p.ramp_dph_per_h}


__all__ = ["PRESETS", "STREAMS", "GyroNoiseComponents", "GyroNoiseParams", "flicker_avar",
           "gm_avar", "kasdin_flicker", "model_avar", "native_terms", "preset",
           "simulate_gyro_components", "simulate_gyro_noise"]
