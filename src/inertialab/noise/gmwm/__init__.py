"""inertialab.noise.gmwm: The generalized method of wavelet moments (GMWM): the latent
processes, their exact Allan variances, the covariance of the wavelet variance, and the
IEEE-952 terms read from a fit.

Modules: covariance, fit, model, terms.

The face (imported on first use): fit_gmwm.

inertialab.noise.gmwm was a module until it became this package: its other public names
still resolve here for one release, with a DeprecationWarning (import them from
inertialab.noise.gmwm.fit).
"""

import warnings

__all__ = [
    "fit_gmwm",
]

#: the old module's other public names (deprecated here)
_LEGACY = (
    "GmwmFit", "Process", "WaveletVariance", "avar_ar1", "avar_drift", "avar_quant",
    "avar_rw", "avar_white", "fit_gmwm_curve", "fit_gmwm_wv", "wavelet_variance",
    "wv_from_curve",
)


def __getattr__(name):  # PEP 562: imported on first use
    if name == "fit_gmwm":
        from inertialab.noise.gmwm import fit as mod
    elif name in _LEGACY:
        warnings.warn(f"inertialab.noise.gmwm.{name} is deprecated: import it from inertialab.noise.gmwm.fit",
                      DeprecationWarning, stacklevel=2)
        from inertialab.noise.gmwm import fit as mod
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
