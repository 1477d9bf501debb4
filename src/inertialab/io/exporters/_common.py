"""What every exporter shares: the four continuous-time noise numbers
(:class:`NoiseParams`), YAML written through a serialiser (:func:`dump_yaml`, PyYAML's
safe dumper: a value can never add a key or break the document), comments made safe
(:func:`comment_lines`) and exact float spelling (:func:`yaml_number`).

Units (Kalibr's "IMU Noise Model", https://github.com/ethz-asl/kalibr/wiki/IMU-Noise-Model),
continuous time, SI:

* ``gyro_noise_density`` rad/s/sqrt(Hz) and ``accel_noise_density`` m/s^2/sqrt(Hz)
  (white noise; = Allan N, angle / velocity random walk);
* ``gyro_random_walk`` rad/s^2/sqrt(Hz) and ``accel_random_walk`` m/s^3/sqrt(Hz)
  (bias random walk; = Allan K);
* ``rate_hz``, the IMU rate (the tools discretise with it:
  sigma_d = density * sqrt(rate), sigma_bd = random_walk / sqrt(rate)).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from inertialab.errors import InputError

__all__ = ["Flow", "NoiseParams", "check_topic", "comment_lines", "dump_yaml", "yaml_number"]


def yaml_number(x: float) -> str:
    """A float as YAML 1.1 and 1.2 both read back exactly: the shortest round-trip
    repr with a dot in the mantissa (PyYAML reads ``1e-05`` as a string)."""
    s = repr(float(x))
    if "e" in s or "E" in s:
        mant, exp = s.lower().split("e")
        if "." not in mant:
            mant += ".0"
        s = f"{mant}e{exp}"
    elif "." not in s and "inf" not in s and "nan" not in s:
        s += ".0"
    return s


class Flow(dict):
    """A mapping written in YAML flow style (``{a: 1, b: 2}``) on one line."""


def _dumper():
    import yaml

    class Dumper(yaml.SafeDumper):
        pass

    def flow_map(dumper, data):
        return dumper.represent_mapping("tag:yaml.org,2002:map", data.items(), flow_style=True)

    def seq(dumper, data):  # rows of numbers on one line each, nested lists in block style
        flat = all(not isinstance(v, (list, tuple, dict)) for v in data)
        return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flat)

    def num(dumper, data):
        if not math.isfinite(data):
            return dumper.represent_scalar("tag:yaml.org,2002:null", "null")
        return dumper.represent_scalar("tag:yaml.org,2002:float", yaml_number(data))

    Dumper.add_representer(Flow, flow_map)
    Dumper.add_representer(list, seq)
    Dumper.add_representer(tuple, seq)
    Dumper.add_representer(float, num)
    return Dumper


def dump_yaml(data: dict, *, comments=(), directive: str | None = None) -> str:
    """``data`` as YAML through PyYAML's safe dumper (block style, keys in the given
    order, NaN as ``null``), after ``directive`` (OpenCV's ``%YAML:1.0``) and the
    ``comments`` lines (each made a comment by :func:`comment_lines`)."""
    try:
        import yaml
    except ImportError:  # pragma: no cover - PyYAML is a dependency
        raise InputError("writing YAML needs PyYAML: pip install pyyaml") from None
    head = [directive] if directive else []
    head += comment_lines(comments)
    body = yaml.dump(data, Dumper=_dumper(), sort_keys=False, default_flow_style=False,
                     allow_unicode=False, width=1 << 16)
    return "\n".join(head + [body.rstrip("\n")]) + "\n"


def comment_lines(lines, width: int = 88) -> list[str]:
    """``# ...`` lines, wrapped at ``width``: every line break inside a text starts a new
    comment line, so data placed in a comment (a method name, a unit id) cannot start a
    YAML line."""
    import textwrap

    out = []
    for text in lines:
        for part in str(text).splitlines() or [""]:
            wrapped = textwrap.wrap(part, width - 2, break_long_words=False,
                                    break_on_hyphens=False) or [""]
            out += [("# " + w).rstrip() for w in wrapped]
    return out


#: A ROS graph resource name (ROS wiki "Names"): '/', '~' or a letter first, then
#: letters, digits, '_' and '/'.
_ROS_NAME = re.compile(r"[~/A-Za-z][A-Za-z0-9_/]*")


def check_topic(topic: str, what: str = "rostopic") -> str:
    """``topic`` when it is a valid ROS name; else one-line InputError naming ``what``.

    Examples
    --------
    >>> check_topic("/imu0")
    '/imu0'
    >>> check_topic("imu0; rm -rf")
    Traceback (most recent call last):
    ...
    inertialab.errors.InputError: argument 'rostopic' must be a ROS topic name (letters, digits, _ and /), got 'imu0; rm -rf'
    """
    t = str(topic)
    if not _ROS_NAME.fullmatch(t) or len(t) > 256:
        raise InputError(f"argument '{what}' must be a ROS topic name (letters, digits, _ and "
                         f"/), got {t[:60]!r}")
    return t


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
