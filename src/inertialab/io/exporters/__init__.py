"""Writers of the files other tools load directly: noise parameters for Kalibr,
VINS-Mono/imu_utils, OpenVINS and GTSAM (this package: :mod:`.kalibr`,
:mod:`.imu_utils`, :mod:`.openvins`, :mod:`.gtsam`); calibrations for imucal, imu_tk and
Kalibr's intrinsics (beside them, from the calibration side). Each writes atomically
and is tested by reading back with the format's own reader or a parser of its
documented grammar.

Every noise exporter takes plain numbers, continuous-time and in SI units, as
Kalibr defines them (https://github.com/ethz-asl/kalibr/wiki/IMU-Noise-Model):

* ``gyro_noise_density`` rad/s/sqrt(Hz) and ``accel_noise_density`` m/s^2/sqrt(Hz)
  (white noise; = Allan N, angle / velocity random walk);
* ``gyro_random_walk`` rad/s^2/sqrt(Hz) and ``accel_random_walk`` m/s^3/sqrt(Hz)
  (bias random walk; = Allan K);
* ``rate_hz``, the IMU rate (the tools discretise with it:
  sigma_d = density * sqrt(rate), sigma_bd = random_walk / sqrt(rate)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from inertialab.errors import InputError

__all__ = ["NoiseParams", "yaml_number"]


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


@dataclass(frozen=True)
class NoiseParams:
    """The four continuous-time noise numbers and the rate (see the module docstring)."""

    gyro_noise_density: float
    gyro_random_walk: float
    accel_noise_density: float
    accel_random_walk: float
    rate_hz: float

    def __post_init__(self):
        for name in ("gyro_noise_density", "gyro_random_walk", "accel_noise_density",
                     "accel_random_walk", "rate_hz"):
            v = getattr(self, name)
            try:
                f = float(v)
            except (TypeError, ValueError):
                raise InputError(f"argument '{name}' must be a number, got {v!r}") from None
            if not math.isfinite(f) or f <= 0:
                raise InputError(f"argument '{name}' must be finite and positive, got {v!r}")
            object.__setattr__(self, name, f)

    def discrete(self) -> dict:
        """Per-sample standard deviations at ``rate_hz`` (Kalibr's discretisation)."""
        r = math.sqrt(self.rate_hz)
        return {"gyro_sigma_d": self.gyro_noise_density * r,
                "gyro_sigma_bd": self.gyro_random_walk / r,
                "accel_sigma_d": self.accel_noise_density * r,
                "accel_sigma_bd": self.accel_random_walk / r}
