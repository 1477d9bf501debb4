"""inertialab.noise.statistics: The Allan family of deviations with their confidence
intervals: the statistics (Allan, modified, time, Hadamard, total, Theo, TIE), one
registry and one entry point by name, gap-resistant forms, equivalent degrees of
freedom, power-law noise identification, and their kernels (numpy, numba, out of core,
Dask).

Modules: allan, allan_dask, edf, edf_clock, family, gaps, identify, registry, theo,
tie, total.

The face (imported on first use): oadev, adev, mdev, tdev, hdev, ohdev, totdev,
deviation, DeviationResult, tau_grid, mtotdev, ttotdev, htotdev, theo1, theobr, theoh,
mtie, tierms, STATISTICS, Statistic, compute, gap_deviation.
"""

__all__ = [
    "oadev", "adev", "mdev", "tdev", "hdev", "ohdev", "totdev", "deviation",
    "DeviationResult", "tau_grid", "mtotdev", "ttotdev", "htotdev", "theo1", "theobr",
    "theoh", "mtie", "tierms", "STATISTICS", "Statistic", "compute", "gap_deviation",
]


def __getattr__(name):  # PEP 562: imported on first use
    if name in (
            "oadev", "adev", "mdev", "tdev", "hdev", "ohdev", "totdev", "deviation",
            "DeviationResult", "tau_grid",
    ):
        from inertialab.noise.statistics import allan as mod
    elif name in ("mtotdev", "ttotdev", "htotdev"):
        from inertialab.noise.statistics import total as mod
    elif name in ("theo1", "theobr", "theoh"):
        from inertialab.noise.statistics import theo as mod
    elif name in ("mtie", "tierms"):
        from inertialab.noise.statistics import tie as mod
    elif name in ("STATISTICS", "Statistic"):
        from inertialab.noise.statistics import registry as mod
    elif name == "compute":
        from inertialab.noise.statistics import family as mod
    elif name == "gap_deviation":
        from inertialab.noise.statistics import gaps as mod
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
