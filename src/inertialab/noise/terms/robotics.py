"""Noise parameters for robotics estimators from fitted IMU noise terms.

Plain numbers (no files: the io floor writes them) for Kalibr, OpenVINS, VINS-Mono /
VINS-Fusion (and imu_utils, which writes the same four names) and GTSAM, per axis and
for the worst axis, with the conversion stated.

Continuous time (what all four tools take as input):

- white-noise density ``sigma_c`` = IEEE N in SI: rad/s/sqrt(Hz) (gyro),
  m/s^2/sqrt(Hz) (accelerometer);
- bias random walk ``sigma_bc`` = IEEE K in SI: rad/s^2/sqrt(Hz), m/s^3/sqrt(Hz).

Discrete time at the IMU rate ``f`` (Kalibr's "IMU noise model"): ``sigma_d =
sigma_c sqrt(f)`` (per-sample standard deviation) and ``sigma_bd = sigma_bc / sqrt(f)``
(bias step per sample); the ``sqrt(f)`` factor is returned as ``sqrt_rate_factor``.

Names per tool: Kalibr ``imu.yaml`` and OpenVINS ``kalibr_imu_chain.yaml``:
``gyroscope_noise_density, gyroscope_random_walk, accelerometer_noise_density,
accelerometer_random_walk, update_rate`` (continuous); VINS ``gyr_n, gyr_w, acc_n,
acc_w`` (continuous densities); GTSAM ``PreintegrationParams`` /
``PreintegrationCombinedParams``: ``gyroscopeCovariance = sigma_c^2 I``,
``accelerometerCovariance``, ``biasOmegaCovariance = sigma_bc^2 I``,
``biasAccCovariance`` (continuous-time covariances; GTSAM multiplies by dt).

``inflation`` (default 1) multiplies every standard deviation (covariances by its
square) — the usual safety factor for unmodelled effects — and is recorded. A term
reported as an upper bound (not significant) contributes its upper bound, flagged.
"""

from __future__ import annotations

import math

from inertialab.errors import InputError

_DEG = math.pi / 180.0
_UG = 9.80665e-6


def _si(terms, name):
    """(value in SI continuous units, bounded?) of N or K of one axis."""
    t = getattr(terms, name)
    v = t.value
    bounded = not t.significant
    if bounded and math.isfinite(t.upper_bound):
        v = t.upper_bound
    if not math.isfinite(v):
        return float("nan"), True
    if terms.kind == "gyro":
        f = _DEG / 60.0 if name == "N" else _DEG / 3600.0 / 60.0  # deg/sqrt(h); deg/h/sqrt(h)
    else:
        f = 1.0 / 60.0  # m/s/sqrt(h) -> m/s^2/sqrt(Hz); m/s^2/sqrt(h) -> m/s^3/sqrt(Hz)
    return v * f, bounded


def _axis(terms, rate_hz, inflation):
    n, nb = _si(terms, "N")
    k, kb = _si(terms, "K")
    n, k = n * inflation, k * inflation
    sq = math.sqrt(rate_hz)
    return {"noise_density": n, "random_walk": k, "noise_discrete": n * sq,
            "random_walk_discrete": k / sq, "bounded": {"N": nb, "K": kb}}


def robotics_values(gyro: dict | None = None, accel: dict | None = None, *,
                    rate_hz: float | None = None, inflation: float = 1.0) -> dict:
    """Estimator noise parameters from per-axis :class:`~inertialab.noise.terms.fit.NoiseTerms`.

    Parameters
    ----------
    gyro, accel : dict axis -> NoiseTerms, optional
        Fitted terms per axis (e.g. ``{"x": ..., "y": ..., "z": ...}``).
    rate_hz : float, optional
        IMU rate (default: the terms' ``rate_hz``).
    inflation : float, default 1
        Safety factor on every standard deviation (module docstring).

    Returns
    -------
    dict
        ``{"rate_hz", "sqrt_rate_factor", "inflation", "units", "gyro"/"accel":
        {"axes": {axis: {...}}, "worst_axis", "worst": {...}}, "kalibr", "openvins",
        "vins", "gtsam"}``; per axis ``noise_density, random_walk`` (continuous) and
        ``noise_discrete, random_walk_discrete`` (at ``rate_hz``).

    Examples
    --------
    White gyro noise of 0.1 deg/s per sample at 100 Hz: the continuous noise density is
    ``0.1 deg/s / sqrt(100 Hz)`` in rad/s/sqrt(Hz), its discrete value the per-sample std:

    >>> import numpy as np
    >>> from inertialab.noise import fit_noise_terms, oadev
    >>> y = np.random.default_rng(0).normal(0.0, 0.1, 20_000)
    >>> terms = fit_noise_terms(oadev(y, rate_hz=100.0), unit="dps", n_boot=0)
    >>> v = robotics_values({"x": terms})
    >>> x = v["gyro"]["axes"]["x"]
    >>> bool(np.isclose(x["noise_density"], np.deg2rad(0.1) / 10.0, rtol=0.05))
    True
    >>> bool(np.isclose(x["noise_discrete"], x["noise_density"] * 10.0))
    True
    >>> kalibr = v["kalibr"]
    >>> kalibr["update_rate"], bool(kalibr["gyroscope_noise_density"] == x["noise_density"])
    (100.0, True)
    """
    if not (math.isfinite(inflation) and inflation > 0):
        raise InputError(f"inflation must be positive, got {inflation}")
    if not gyro and not accel:
        raise InputError("robotics_values needs gyro or accel terms")
    if rate_hz is None:
        any_t = next(iter((gyro or accel).values()))
        rate_hz = any_t.rate_hz
    if not rate_hz or rate_hz <= 0:
        raise InputError("robotics_values needs the IMU rate (rate_hz)")
    out = {"rate_hz": float(rate_hz), "sqrt_rate_factor": math.sqrt(rate_hz),
           "inflation": float(inflation),
           "units": {"gyro": {"noise_density": "rad/s/sqrt(Hz)",
                              "random_walk": "rad/s^2/sqrt(Hz)", "noise_discrete": "rad/s",
                              "random_walk_discrete": "rad/s"},
                     "accel": {"noise_density": "m/s^2/sqrt(Hz)",
                               "random_walk": "m/s^3/sqrt(Hz)", "noise_discrete": "m/s^2",
                               "random_walk_discrete": "m/s^2"}},
           "discrete_rule": "noise_discrete = noise_density * sqrt(rate_hz); "
                            "random_walk_discrete = random_walk / sqrt(rate_hz)"}
    for label, group in (("gyro", gyro), ("accel", accel)):
        if not group:
            continue
        axes = {}
        for ax, t in group.items():
            want = "gyro" if label == "gyro" else "accel"
            if t.kind != want:
                raise InputError(f"axis '{ax}' of {label} holds {t.kind} terms")
            axes[ax] = _axis(t, float(rate_hz), float(inflation))
        worst_ax = max(axes, key=lambda a: (axes[a]["noise_density"], axes[a]["random_walk"]))
        worst = {"noise_density": max(v["noise_density"] for v in axes.values()),
                 "random_walk": max(v["random_walk"] for v in axes.values())}
        sq = math.sqrt(rate_hz)
        worst["noise_discrete"] = worst["noise_density"] * sq
        worst["random_walk_discrete"] = worst["random_walk"] / sq
        out[label] = {"axes": axes, "worst_axis": worst_ax, "worst": worst}
    g = out.get("gyro", {}).get("worst", {})
    a = out.get("accel", {}).get("worst", {})
    nan = float("nan")
    kal = {"gyroscope_noise_density": g.get("noise_density", nan),
           "gyroscope_random_walk": g.get("random_walk", nan),
           "accelerometer_noise_density": a.get("noise_density", nan),
           "accelerometer_random_walk": a.get("random_walk", nan),
           "update_rate": float(rate_hz)}
    out["kalibr"] = dict(kal)
    out["openvins"] = dict(kal)
    out["vins"] = {"gyr_n": kal["gyroscope_noise_density"],
                   "gyr_w": kal["gyroscope_random_walk"],
                   "acc_n": kal["accelerometer_noise_density"],
                   "acc_w": kal["accelerometer_random_walk"]}
    out["gtsam"] = {"gyroscopeCovariance": kal["gyroscope_noise_density"] ** 2,
                    "accelerometerCovariance": kal["accelerometer_noise_density"] ** 2,
                    "biasOmegaCovariance": kal["gyroscope_random_walk"] ** 2,
                    "biasAccCovariance": kal["accelerometer_random_walk"] ** 2,
                    "note": "continuous-time covariances, times the 3x3 identity"}
    return out


__all__ = ["robotics_values"]
