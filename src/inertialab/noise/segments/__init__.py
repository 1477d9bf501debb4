"""inertialab.noise.segments: Parts of one log: the static intervals of a raw
accelerometer log, a start-of-log warm-up, whether the noise stays the same
throughout, and how much the drift its segments predict differs.

Modules: drift_spread, static_intervals, stationarity, warmup.

The face (imported on first use): detect_static_intervals.
"""

__all__ = [
    "detect_static_intervals",
]


def __getattr__(name):  # PEP 562: imported on first use
    if name == "detect_static_intervals":
        from inertialab.noise.segments import static_intervals as mod
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
