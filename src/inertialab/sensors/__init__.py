"""inertialab.sensors: forward error models of the instruments (accelerometers, gyros).

The public face, imported on first use::

    GyroNoiseParams preset simulate_gyro_noise (gyro)
"""

__all__ = ["GyroNoiseParams", "preset", "simulate_gyro_noise"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name in ('GyroNoiseParams', 'preset', 'simulate_gyro_noise',):
        from inertialab.sensors import gyro as mod
    else:
        raise AttributeError(f"module 'inertialab.sensors' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
