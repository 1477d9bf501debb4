"""A ROS parameter file of IMU noise (``rosparam load``): under one namespace the four
Kalibr names (continuous time, SI), ``update_rate`` (Hz) and, per axis, the noise
density, random walk and whether the random walk is an upper bound.
"""

from __future__ import annotations

import re

from inertialab.errors import InputError
from inertialab.export.noise_params import NoiseParams, units_comments
from inertialab.export.yaml_text import Flow, dump_yaml

__all__ = ["ros_text"]

_NAMESPACE = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}")


def ros_text(p: NoiseParams, *, namespace: str = "imu", per_axis=(), note=()) -> str:
    """The parameter file for ``p``; ``per_axis`` is a sequence of ``(axis,
    noise_density, random_walk, random_walk_bound)``."""
    if not _NAMESPACE.fullmatch(str(namespace)):
        raise InputError(f"argument 'namespace' must be a ROS parameter name (a letter, then "
                         f"letters, digits, _), got {str(namespace)[:60]!r}")
    body = {"accelerometer_noise_density": p.accel_noise_density,
            "accelerometer_random_walk": p.accel_random_walk,
            "gyroscope_noise_density": p.gyro_noise_density,
            "gyroscope_random_walk": p.gyro_random_walk,
            "update_rate": p.rate_hz}
    if per_axis:
        body["per_axis"] = {str(ax): Flow(noise_density=float(nd), random_walk=float(rw),
                                          random_walk_bound=bool(b))
                            for ax, nd, rw, b in per_axis}
    return dump_yaml({str(namespace): body},
                     comments=["IMU noise parameters from inertialab (ROS parameter file)",
                               *units_comments(), *note, *p.bound_comments()])
