"""inertialab.noise.terms: The IEEE-952 noise terms (Q, N, B, K, R) read from an
Allan-type curve (slopes, least squares, bounds within physics), how well a record can
determine them, and what a fitted noise model gives: robotics parameters, the six-axis
result, several logs pooled into one model, the drift it predicts.

Modules: band, base, drift_prediction, fit, imu_result, information, least_squares,
pooled, robotics.

The face (imported on first use): fit_noise_terms, NoiseTerms, NoiseTerm,
robotics_values, k_bound.

inertialab.noise.terms was a module until it became this package: its other public
names still resolve here for one release, with a DeprecationWarning (import them from
inertialab.noise.terms.fit).
"""

import warnings

__all__ = [
    "fit_noise_terms", "NoiseTerms", "NoiseTerm", "robotics_values", "k_bound",
]

#: the old module's other public names (deprecated here)
_LEGACY = (
    "BI_FACTOR", "CONFIDENCE", "EDF_MIN", "N_BOOT", "auto_tau_range", "local_slopes",
    "model_alpha", "model_intervals", "not_static_reason",
)


def __getattr__(name):  # PEP 562: imported on first use
    if name in ("fit_noise_terms", "NoiseTerms", "NoiseTerm"):
        from inertialab.noise.terms import fit as mod
    elif name == "robotics_values":
        from inertialab.noise.terms import robotics as mod
    elif name == "k_bound":
        from inertialab.noise.terms import information as mod
    elif name in _LEGACY:
        warnings.warn(f"inertialab.noise.terms.{name} is deprecated: import it from inertialab.noise.terms.fit",
                      DeprecationWarning, stacklevel=2)
        from inertialab.noise.terms import fit as mod
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
