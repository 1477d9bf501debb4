"""inertialab.noise: the Allan family with confidence intervals, the IEEE-952 noise
terms, GMWM, wavelet multiscale views, spectra, EMD.

The public face (``from inertialab.noise import oadev, fit_noise_terms``) is imported on
first use, so ``import inertialab.noise.<module>`` stays light::

    oadev adev mdev tdev hdev ohdev totdev deviation DeviationResult   (statistics.allan)
    mtotdev ttotdev htotdev (statistics.total)  theo1 theobr theoh (statistics.theo)  mtie tierms (statistics.tie)
    compute (statistics.family: any statistic by name)  STATISTICS Statistic (statistics.registry)
    gap_deviation (statistics.gaps)  fit_noise_terms NoiseTerms NoiseTerm (terms.fit)
    fit_gmwm (gmwm.fit)  robotics_values (terms.robotics)  k_bound (terms.information)
    detect_static_intervals (segments.static_intervals)

Its modules live in subpackages by meaning: ``statistics``, ``terms``, ``gmwm``,
``spectral``, ``segments`` (docs/architecture.md).
"""

_ALLAN = ("oadev", "adev", "mdev", "tdev", "hdev", "ohdev", "totdev", "deviation",
          "DeviationResult", "tau_grid")
_TOTAL = ("mtotdev", "ttotdev", "htotdev")
_THEO = ("theo1", "theobr", "theoh")
_TIE = ("mtie", "tierms")
_TERMS = ("fit_noise_terms", "NoiseTerms", "NoiseTerm")
_REGISTRY = ("STATISTICS", "Statistic")

__all__ = [*_ALLAN, *_TOTAL, *_THEO, *_TIE, *_TERMS, *_REGISTRY, "compute", "gap_deviation",
           "fit_gmwm", "robotics_values", "k_bound", "detect_static_intervals"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name in _ALLAN:
        from inertialab.noise.statistics import allan as mod
    elif name in _TOTAL:
        from inertialab.noise.statistics import total as mod
    elif name in _THEO:
        from inertialab.noise.statistics import theo as mod
    elif name in _TIE:
        from inertialab.noise.statistics import tie as mod
    elif name in _TERMS:
        from inertialab.noise.terms import fit as mod
    elif name in _REGISTRY:
        from inertialab.noise.statistics import registry as mod
    elif name == "compute":
        from inertialab.noise.statistics import family as mod
    elif name == "gap_deviation":
        from inertialab.noise.statistics import gaps as mod
    elif name == "fit_gmwm":
        from inertialab.noise.gmwm import fit as mod
    elif name == "robotics_values":
        from inertialab.noise.terms import robotics as mod
    elif name == "k_bound":
        from inertialab.noise.terms import information as mod
    elif name == "detect_static_intervals":
        from inertialab.noise.segments import static_intervals as mod
    else:
        raise AttributeError(f"module 'inertialab.noise' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
