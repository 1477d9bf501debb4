"""The numbers a noise file holds: the four continuous-time noise parameters and the
rate (:class:`NoiseParams`), and how they come from a six-axis analysis
(:class:`NoiseValues`, the typed values of
:class:`inertialab.noise.terms.imu_result.IMUNoise`; :func:`noise_params`).

Units (Kalibr's "IMU Noise Model", https://github.com/ethz-asl/kalibr/wiki/IMU-Noise-Model),
continuous time, SI:

* ``gyro_noise_density`` rad/s/sqrt(Hz) and ``accel_noise_density`` m/s^2/sqrt(Hz)
  (white noise; = Allan N, angle / velocity random walk);
* ``gyro_random_walk`` rad/s^2/sqrt(Hz) and ``accel_random_walk`` m/s^3/sqrt(Hz)
  (bias random walk; = Allan K);
* ``rate_hz``, the IMU rate (the tools discretise with it:
  sigma_d = density * sqrt(rate), sigma_bd = random_walk / sqrt(rate)).

Each sensor's value is the largest of its three axes, the conservative choice for an
estimator that takes one number; a random walk that is an upper bound on any axis is
marked so in the file's comments, and so is one held by a Gauss–Markov correlation time
(the value is then its random-walk density below that time, with the time in the
comment).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from inertialab.errors import InputError

if TYPE_CHECKING:
    from inertialab.noise.terms.imu_result import IMUNoise

__all__ = ["AxisValues", "NoiseParams", "NoiseValues", "imu_utils_axes", "noise_params",
           "per_axis", "span_notes", "units_comments"]


_FIELDS = ("gyro_noise_density", "gyro_random_walk", "accel_noise_density",
           "accel_random_walk", "rate_hz")


@dataclass(frozen=True)
class NoiseParams:
    """The four continuous-time noise numbers and the rate (module docstring), whether
    each random walk is an upper bound (the record too short to show the +1/2 slope of
    the bias random walk), and ``*_random_walk_t_s``: ``((axis, t_s), ...)`` of the axes
    whose bias random walk is held by a first-order Gauss–Markov correlation time
    ``t_s`` (the random walk given is its density below ``t_s``).

    ``allow_missing`` admits NaN for the numbers of an absent sensor (a gyro-only log);
    the writers put ``null`` there.

    Examples
    --------
    >>> p = NoiseParams(1e-4, 2e-6, 2e-3, 3e-4, rate_hz=400.0)
    >>> round(p.discrete()["gyro_sigma_d"], 12)
    0.002
    >>> NoiseParams(1e-4, 2e-6, -2e-3, 3e-4, rate_hz=400.0)
    Traceback (most recent call last):
    ...
    inertialab.errors.InputError: argument 'accel_noise_density' must be finite and positive, got -0.002
    """

    gyro_noise_density: float
    gyro_random_walk: float
    accel_noise_density: float
    accel_random_walk: float
    rate_hz: float
    gyro_random_walk_bound: bool = False
    accel_random_walk_bound: bool = False
    allow_missing: bool = False
    gyro_random_walk_t_s: tuple = ()
    accel_random_walk_t_s: tuple = ()

    def __post_init__(self):
        for name in _FIELDS:
            v = getattr(self, name)
            try:
                f = float(v)
            except (TypeError, ValueError):
                raise InputError(f"argument '{name}' must be a number, got {v!r}") from None
            missing_ok = self.allow_missing and name != "rate_hz" and math.isnan(f)
            if not missing_ok and (not math.isfinite(f) or f <= 0):
                raise InputError(f"argument '{name}' must be finite and positive, got {v!r}")
            object.__setattr__(self, name, f)

    def discrete(self) -> dict:
        """Per-sample standard deviations at ``rate_hz`` (Kalibr's discretisation)."""
        r = math.sqrt(self.rate_hz)
        return {"gyro_sigma_d": self.gyro_noise_density * r,
                "gyro_sigma_bd": self.gyro_random_walk / r,
                "accel_sigma_d": self.accel_noise_density * r,
                "accel_sigma_bd": self.accel_random_walk / r}

    def require_all(self, target: str) -> None:
        """Refuse missing numbers for a tool that needs all four."""
        gone = [n for n in _FIELDS if math.isnan(getattr(self, n))]
        if gone:
            raise InputError(f"{target} needs gyro and accelerometer noise; the log has none for "
                             + ", ".join(gone))

    def bound_comments(self) -> list[str]:
        """Comment lines saying which random walks are upper bounds, and which are held
        by a Gauss–Markov correlation time (with that time)."""
        out = []
        for flag, held, key in (
                (self.gyro_random_walk_bound, self.gyro_random_walk_t_s, "gyroscope"),
                (self.accel_random_walk_bound, self.accel_random_walk_t_s, "accelerometer")):
            if flag:
                out.append(f"{key} random walk is an upper bound, not an estimate: the "
                           "record does not determine it (K not significant, or no +1/2 "
                           "slope); the value is K's upper limit (or the random-walk line "
                           "through the upper confidence limit of the longest tau).")
            if held:
                times = ", ".join(f"{ax} T = {t:.4g} s" for ax, t in held)
                out.append(f"{key} bias random walk is held by a first-order Gauss-Markov "
                           f"correlation time ({times}): the random walk given is its "
                           "density below T, conservative past T, where the bias wanders "
                           "less than this random walk.")
        return out


def units_comments() -> list[str]:
    """The continuous/discrete convention, for a file's head."""
    return ["Continuous-time values, SI units: noise densities are white-noise spectral",
            "densities (rad/s/sqrt(Hz), m/s^2/sqrt(Hz)); random walks are bias random-walk",
            "densities (rad/s^2/sqrt(Hz), m/s^3/sqrt(Hz)). Discrete-time equivalents at",
            "update_rate: sigma_d = noise_density * sqrt(update_rate),",
            "sigma_bd = random_walk / sqrt(update_rate)."]


_PER_SENSOR_NOTE = "Each value is the largest of the sensor's three axes."


@dataclass(frozen=True)
class AxisValues:
    """The numbers of one analysed axis that the noise files hold (continuous time, SI).

    Attributes
    ----------
    axis : str             ``gx gy gz ax ay az``
    kind : str             ``gyro`` or ``accel``
    noise_density : float  white-noise density (rad/s/sqrt(Hz) or m/s^2/sqrt(Hz)); NaN: none
    random_walk : float    bias random walk (rad/s^2/sqrt(Hz) or m/s^3/sqrt(Hz)); NaN: none
    random_walk_bound : bool   ``random_walk`` is an upper bound
    random_walk_t_s : float or None
        The Gauss–Markov correlation time (s) holding the random walk; None: a pure one.
    status : str           the analysis' status of the axis (``ok``, ``not static`` ...)

    Examples
    --------
    >>> AxisValues("gx", "gyro", 2e-3, 3e-5).status
    'ok'
    """

    axis: str
    kind: str
    noise_density: float
    random_walk: float
    random_walk_bound: bool = False
    random_walk_t_s: float | None = None
    status: str = "ok"


@dataclass(frozen=True)
class NoiseValues:
    """What a noise export reads of a six-axis analysis: the IMU rate (Hz) and the
    :class:`AxisValues` of each analysed axis.

    Examples
    --------
    >>> v = NoiseValues(100.0, (AxisValues("gx", "gyro", 2e-3, 3e-5),
    ...                         AxisValues("ax", "accel", 3e-3, 5e-4)))
    >>> noise_params(v).gyro_noise_density
    0.002
    """

    rate_hz: float
    axes: tuple[AxisValues, ...]

    @classmethod
    def of(cls, result: IMUNoise | NoiseValues) -> NoiseValues:
        """The values of a six-axis analysis (:class:`inertialab.noise.terms.imu_result.IMUNoise`,
        read through its public fields ``rate_hz`` and ``axes``), or ``result`` itself."""
        if isinstance(result, cls):
            return result
        axes = tuple(AxisValues(a.axis, a.kind, a.noise_density, a.random_walk,
                                getattr(a, "random_walk_bound", False),
                                getattr(a, "random_walk_t_s", None),
                                getattr(a, "status", "no value"))
                     for a in getattr(result, "axes", ()))
        return cls(getattr(result, "rate_hz", math.nan), axes)


def _worst(axes, kind: str, what: str) -> float:
    vals = [float(getattr(a, what)) for a in axes if a.kind == kind]
    vals = [v for v in vals if math.isfinite(v)]
    return max(vals) if vals else math.nan


def noise_params(noise: NoiseValues) -> NoiseParams:
    """The :class:`NoiseParams` of a six-axis analysis (module docstring); an absent
    sensor's numbers are NaN (written as null where the tool allows it)."""
    noise = NoiseValues.of(noise)
    axes = noise.axes
    if not axes:
        raise InputError("no IMU axes to export")
    return NoiseParams(
        _worst(axes, "gyro", "noise_density"), _worst(axes, "gyro", "random_walk"),
        _worst(axes, "accel", "noise_density"), _worst(axes, "accel", "random_walk"),
        float(noise.rate_hz),
        gyro_random_walk_bound=any(a.random_walk_bound for a in axes if a.kind == "gyro"),
        accel_random_walk_bound=any(a.random_walk_bound for a in axes if a.kind == "accel"),
        gyro_random_walk_t_s=_held(axes, "gyro"), accel_random_walk_t_s=_held(axes, "accel"),
        allow_missing=True)


def _held(axes, kind: str) -> tuple:
    """``((axis, t_s), ...)`` of the sensor's axes whose random walk is held by a
    Gauss–Markov correlation time ``t_s``."""
    return tuple((a.axis, float(t)) for a in axes if a.kind == kind
                 and (t := a.random_walk_t_s) is not None)


def per_axis(noise: NoiseValues) -> list[tuple]:
    """``(axis, noise_density, random_walk, random_walk_bound)`` per analysed axis."""
    return [(a.axis, a.noise_density, a.random_walk, bool(a.random_walk_bound))
            for a in noise.axes]


def imu_utils_axes(noise: NoiseValues) -> dict:
    """imu_utils' per-axis mapping ``{"x": {"gyr_n", "gyr_w", "acc_n", "acc_w"}}`` of the
    axes whose gyro and accelerometer were both analysed."""
    by = {a.axis: a for a in noise.axes}
    out = {}
    for ax in "xyz":
        g, a = by.get(f"g{ax}"), by.get(f"a{ax}")
        if g is not None and a is not None:
            out[ax] = {"gyr_n": g.noise_density, "gyr_w": g.random_walk,
                       "acc_n": a.noise_density, "acc_w": a.random_walk}
    return out


NOTE = (_PER_SENSOR_NOTE,)

_SENSOR = {"gyro": "gyroscope", "accel": "accelerometer"}


def span_notes(noise: NoiseValues) -> tuple[str, ...]:
    """One line per sensor naming the axes its single value is the largest of, and the
    axes left out with their status (an axis that is not static, constant or without
    terms has no value)."""
    out = []
    for kind in ("gyro", "accel"):
        axes = [a for a in noise.axes if a.kind == kind]
        if not axes:
            continue
        used = [a.axis for a in axes if math.isfinite(float(a.noise_density))]
        left = [f"{a.axis} ({a.status})" for a in axes
                if a.axis not in used]
        text = (f"{_SENSOR[kind]} values: the largest of {', '.join(used)}" if used
                else f"{_SENSOR[kind]} values: none (no axis has noise terms)")
        if left:
            text += "; left out: " + ", ".join(left)
        out.append(text + ".")
    return tuple(out)
