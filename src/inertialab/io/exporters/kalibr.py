"""Kalibr ``imu.yaml`` (the IMU configuration of kalibr_calibrate_imu_camera).

Grammar (Kalibr wiki, "YAML formats" / IMU configuration): a flat mapping with
``accelerometer_noise_density``, ``accelerometer_random_walk``,
``gyroscope_noise_density``, ``gyroscope_random_walk`` (continuous-time, SI),
``rostopic`` and ``update_rate`` (Hz).
"""

from __future__ import annotations

from inertialab.io.exporters import NoiseParams, yaml_number

__all__ = ["kalibr_imu_yaml", "write_kalibr_imu"]


def kalibr_imu_yaml(*, gyro_noise_density: float, gyro_random_walk: float,
                    accel_noise_density: float, accel_random_walk: float, rate_hz: float,
                    rostopic: str = "/imu0") -> str:
    """The text of a Kalibr ``imu.yaml`` (units: module docstring of
    :mod:`inertialab.io.exporters`)."""
    p = NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                    accel_random_walk, rate_hz)
    return "\n".join([
        "# Kalibr IMU noise model (continuous time, SI units), written by inertialab",
        "#Accelerometers",
        f"accelerometer_noise_density: {yaml_number(p.accel_noise_density)}   "
        "#Noise density (continuous-time), m/s^2/sqrt(Hz)",
        f"accelerometer_random_walk: {yaml_number(p.accel_random_walk)}   "
        "#Bias random walk, m/s^3/sqrt(Hz)",
        "#Gyroscopes",
        f"gyroscope_noise_density: {yaml_number(p.gyro_noise_density)}   "
        "#Noise density (continuous-time), rad/s/sqrt(Hz)",
        f"gyroscope_random_walk: {yaml_number(p.gyro_random_walk)}   "
        "#Bias random walk, rad/s^2/sqrt(Hz)",
        f"rostopic: {_topic(rostopic)}   #the IMU ROS topic",
        f"update_rate: {yaml_number(p.rate_hz)}   #Hz (for discretization of the values above)",
        "",
    ])


def _topic(t: str) -> str:
    t = str(t)
    if not t or any(c in t for c in "\n\r#:'\"{}[],&*!|>%@`") or t != t.strip():
        from inertialab.errors import InputError

        raise InputError(f"argument 'rostopic' must be a plain ROS topic name, got {t!r}")
    return t


def write_kalibr_imu(path, **params) -> None:
    """Write :func:`kalibr_imu_yaml` to ``path`` atomically."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, kalibr_imu_yaml(**params))
