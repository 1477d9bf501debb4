"""Forward model of a FOG's errors under linear vibration (spec 001 §6.3).

The effects are active while ``vib_on = 1`` and follow the shapes the seed shows and
the FOG vibration literature explains (coil strain, pigtail motion, structural
resonances, rectification of harmonic stresses into a DC bias). Every amplitude is an
assumption of the spec (marked [A] there) for a poorly damped unit at ``a = 5 g``:

- bias shift ``b_v(f) = (a/5 g)^2 [0.5 + 3.0 (f/500)^2 + 8/(1 + ((f-470)/47)^2)]`` deg/h,
  seen through a first-order lag ``tau_b = 0.5 s`` (:func:`bias_shift_dph`,
  :func:`first_order_lag`);
- noise increase: ARW x ``(1 + 0.5 f/500)``, Gauss-Markov driving noise x 2, RRW
  increments x 3, extra white angle jitter of std ``q/sqrt(12)``
  (:class:`NoiseMultipliers`, :func:`noise_multipliers`);
- fixture thermal drift: +2 deg/h per hour during P2, decaying with 60 s after ``k_off``
  (:func:`thermal_drift_dph`);
- edge transients ``5 exp(-dt/1 s) sin(2 pi 2 Hz dt)`` deg/h at ``t_on`` and ``t_off``
  (:func:`edge_transient_dph`);
- vibration lines h = 1, 2, 3 with amplitudes ``20 (0.2 + f/500) {1, 0.3, 0.1}`` deg/h,
  averaged over each output interval (integrate-and-dump), so sample k gets
  ``A_h sinc(h f tau0) sin(h Phi(t_k) + pi h f tau0)`` (:func:`vibration_lines_dph`).

All functions are deterministic and vectorised; the random parts (the multiplied noise
streams) are drawn by the static noise model of :mod:`inertialab.sensors.gyro`, which
this module only scales.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.signal import lfilter, lfilter_zi

from inertialab.errors import InputError

__all__ = [
    "NoiseMultipliers",
    "VibrationEffects",
    "bias_shift_dph",
    "drive_phase_rad",
    "edge_transient_dph",
    "first_order_lag",
    "noise_multipliers",
    "thermal_drift_dph",
    "vibration_lines_dph",
]


@dataclass(frozen=True)
class VibrationEffects:
    """Parameters of the vibration effects (spec 001 §6.3 defaults, all [A]).

    Attributes
    ----------
    ref_acc_g : float, default=5.0
        Acceleration at which the bias-shift amplitudes hold (g peak).
    bias_const_dph, bias_quad_dph, resonance_dph : float, default 0.5, 3.0, 8.0
        The three terms of ``b_v`` (deg/h at ``ref_acc_g``).
    f_ref_hz : float, default=500.0
        Frequency scale of the quadratic rise and the ARW/line growth.
    resonance_hz, resonance_width_hz : float, default 470.0 and 47.0
        Resonance centre and half width (Q_r = 5).
    bias_lag_s : float, default=0.5
        First-order lag of the bias shift.
    arw_gain : float, default=0.5
        ARW multiplied by ``1 + arw_gain f/f_ref``.
    gm_factor, rrw_factor : float, default 2.0 and 3.0
        Multipliers of the Gauss-Markov driving noise and the RRW increments in P2.
    jitter : float, default=1.0
        Extra white angle jitter in P2, in units of ``q/sqrt(12)``.
    thermal_dph_per_h : float, default=2.0
        Fixture thermal drift slope during P2 (deg/h per hour).
    thermal_decay_s : float, default=60.0
    edge_amp_dph, edge_tau_s, edge_freq_hz : float, default 5.0, 1.0, 2.0
    line_amp_dph, line_offset : float, default 20.0 and 0.2
        Fundamental amplitude ``line_amp (line_offset + f/f_ref)`` deg/h.
    line_rel : tuple, default=(1.0, 0.3, 0.1)
        Relative amplitudes of harmonics 1, 2, 3.
    """

    ref_acc_g: float = 5.0
    bias_const_dph: float = 0.5
    bias_quad_dph: float = 3.0
    resonance_dph: float = 8.0
    f_ref_hz: float = 500.0
    resonance_hz: float = 470.0
    resonance_width_hz: float = 47.0
    bias_lag_s: float = 0.5
    arw_gain: float = 0.5
    gm_factor: float = 2.0
    rrw_factor: float = 3.0
    jitter: float = 1.0
    thermal_dph_per_h: float = 2.0
    thermal_decay_s: float = 60.0
    edge_amp_dph: float = 5.0
    edge_tau_s: float = 1.0
    edge_freq_hz: float = 2.0
    line_amp_dph: float = 20.0
    line_offset: float = 0.2
    line_rel: tuple = (1.0, 0.3, 0.1)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["line_rel"] = list(self.line_rel)
        return d


DEFAULT_EFFECTS = VibrationEffects()


def bias_shift_dph(f_hz, acc_g: float = 5.0, effects: VibrationEffects = DEFAULT_EFFECTS):
    """Steady-state vibration bias shift ``b_v(f)`` in deg/h (spec 001 §6.3).

    Parameters
    ----------
    f_hz : array_like
        Drive frequency, Hz.
    acc_g : float or array_like, default=5.0
        Acceleration amplitude, g peak; the shift scales with ``(a/5 g)^2``.

    Returns
    -------
    ndarray
        0.58 at 1 Hz, 0.75 at 100 Hz, 2.15 at 300 Hz, 11.15 at 470 Hz, 9.18 at 500 Hz
        (defaults).
    """
    e = effects
    f = np.asarray(f_hz, dtype=float)
    scale = (np.asarray(acc_g, dtype=float) / e.ref_acc_g) ** 2
    res = e.resonance_dph / (1.0 + ((f - e.resonance_hz) / e.resonance_width_hz) ** 2)
    return scale * (e.bias_const_dph + e.bias_quad_dph * (f / e.f_ref_hz) ** 2 + res)


def first_order_lag(x, tau_s: float, fs_hz: float, *, x0: float | None = None) -> np.ndarray:
    """First-order lag ``tau dy/dt = x - y`` by exact discretisation (zero-order hold).

    ``y_k = a y_{k-1} + (1 - a) x_k`` with ``a = exp(-tau0/tau)``; ``y_{-1} = x0``
    (default: 0, i.e. the lag starts from rest). ``tau_s = 0`` returns ``x``.
    """
    x = np.asarray(x, dtype=float)
    if tau_s < 0:
        raise InputError(f"lag time constant must be >= 0, got {tau_s}")
    if tau_s == 0:
        return x.copy()
    a = float(np.exp(-1.0 / (fs_hz * tau_s)))
    zi = lfilter_zi([1.0 - a], [1.0, -a]) * (0.0 if x0 is None else float(x0))
    y, _ = lfilter([1.0 - a], [1.0, -a], x, zi=zi)
    return y


def drive_phase_rad(f_hz, fs_hz: float) -> np.ndarray:
    """Drive phase ``Phi(t_k) = 2 pi sum_{i<k} f_i tau0`` (rad), starting at 0 (spec §6.1)."""
    f = np.asarray(f_hz, dtype=float)
    phi = np.empty_like(f)
    if f.size:
        phi[0] = 0.0
        np.cumsum(f[:-1] * (2.0 * np.pi / fs_hz), out=phi[1:])
    return phi


def vibration_lines_dph(phi_rad, f_hz, fs_hz: float, vib_on=None,
                        effects: VibrationEffects = DEFAULT_EFFECTS) -> np.ndarray:
    """Integrate-and-dump samples of the drive-harmonic lines (deg/h).

    Sample k gets ``sum_h A_h sinc(h f tau0) sin(h Phi_k + pi h f tau0)`` with
    ``A_h = line_amp (line_offset + f/f_ref) rel_h``: the mean of
    ``A_h sin(h Phi(t))`` over ``[t_k, t_k + tau0)`` for constant f. Aliasing follows
    by itself (500 Hz at 200 Hz lands on 100 Hz; exact multiples of fs are nulled).
    """
    e = effects
    f = np.asarray(f_hz, dtype=float)
    phi = np.asarray(phi_rad, dtype=float)
    tau0 = 1.0 / fs_hz
    a1 = e.line_amp_dph * (e.line_offset + f / e.f_ref_hz)
    out = np.zeros_like(f)
    for h, rel in enumerate(e.line_rel, start=1):
        out += a1 * rel * np.sinc(h * f * tau0) * np.sin(h * phi + np.pi * h * f * tau0)
    if vib_on is not None:
        out *= np.asarray(vib_on) != 0
    return out


def thermal_drift_dph(t_s, t_on_s: float, t_off_s: float,
                      effects: VibrationEffects = DEFAULT_EFFECTS) -> np.ndarray:
    """Fixture thermal drift: ramp during P2, exponential decay after ``t_off`` (deg/h)."""
    e = effects
    t = np.asarray(t_s, dtype=float)
    slope = e.thermal_dph_per_h / 3600.0
    out = np.zeros_like(t)
    on = (t >= t_on_s) & (t <= t_off_s)
    out[on] = slope * (t[on] - t_on_s)
    after = t > t_off_s
    peak = slope * (t_off_s - t_on_s)
    out[after] = peak * np.exp(-(t[after] - t_off_s) / e.thermal_decay_s)
    return out


def edge_transient_dph(t_s, edges_s, effects: VibrationEffects = DEFAULT_EFFECTS) -> np.ndarray:
    """Damped 2-Hz transients ``A exp(-dt/tau) sin(2 pi f dt)`` after each edge (deg/h)."""
    e = effects
    t = np.asarray(t_s, dtype=float)
    out = np.zeros_like(t)
    for t_e in edges_s:
        dt = t - t_e
        m = dt >= 0
        out[m] += e.edge_amp_dph * np.exp(-dt[m] / e.edge_tau_s) * np.sin(
            2 * np.pi * e.edge_freq_hz * dt[m])
    return out


@dataclass(frozen=True)
class NoiseMultipliers:
    """Per-sample multipliers of the static noise streams (spec 001 §6.3).

    Attributes
    ----------
    white : ndarray
        ARW multiplier, ``1 + arw_gain f/f_ref`` in P2, else 1.
    gm : ndarray
        Gauss-Markov driving-noise multiplier (2 in P2).
    rrw : ndarray
        RRW increment multiplier (3 in P2).
    jitter : ndarray
        Extra white angle jitter in units of ``q/sqrt(12)`` (1 in P2, else 0).
    """

    white: np.ndarray
    gm: np.ndarray
    rrw: np.ndarray
    jitter: np.ndarray


def noise_multipliers(vib_on, f_hz, effects: VibrationEffects = DEFAULT_EFFECTS
                      ) -> NoiseMultipliers:
    """Multipliers of the noise streams while the shaker drives (spec 001 §6.3)."""
    e = effects
    on = np.asarray(vib_on) != 0
    f = np.asarray(f_hz, dtype=float)
    one = np.ones(on.shape)
    return NoiseMultipliers(
        white=np.where(on, 1.0 + e.arw_gain * f / e.f_ref_hz, 1.0),
        gm=np.where(on, e.gm_factor, one),
        rrw=np.where(on, e.rrw_factor, one),
        jitter=np.where(on, e.jitter, 0.0),
    )
