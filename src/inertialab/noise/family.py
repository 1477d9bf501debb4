"""One entry point for every statistic of the Allan family (issue 15).

:func:`compute` dispatches ``statistic`` to :func:`inertialab.noise.allan.deviation`
(adev oadev mdev tdev hdev ohdev totdev), :mod:`~inertialab.noise.total` (mtotdev
ttotdev htotdev), :mod:`~inertialab.noise.theo` (theo1 theobr theoh) or
:mod:`~inertialab.noise.tie` (mtie tierms) with the common keywords. ``bias_correction``
applies Stable32's bias corrections where the statistic has one: TOTDEV (``1 - a tau/T``,
``a = 0.481`` FFM, ``0.750`` RWFM, SP 1065 §5.2.11, T the record length), MTOT/TTOT/HTOT
(their factor tables) and Theo1 (reported as TheoBR, the data-derived correction).
"""

from __future__ import annotations

import numpy as np

from inertialab.errors import InputError
from inertialab.noise.allan import STATISTICS as CORE
from inertialab.noise.allan import DeviationResult, deviation
from inertialab.noise.edf_clock import TOTDEV_BIAS_A, totdev_bias  # noqa: F401 - re-exported

#: Every statistic, in their canonical order.
ALL_STATISTICS = CORE + ("mtotdev", "ttotdev", "htotdev", "theo1", "theobr", "theoh",
                         "mtie", "tierms")
#: Statistics in the unit of the phase (rate unit x s; s for a clock), not of the rate.
PHASE_UNIT = ("tdev", "ttotdev", "mtie", "tierms")
def compute(statistic: str, data, *, rate_hz: float, taus="octave", input: str = "rate",
            confidence: float = 0.683, alpha=None, edf_method: str = "default",
            chunked: bool = False, bias_correction: bool = False) -> DeviationResult:
    """The statistic ``statistic`` of ``data`` (see the module docstring)."""
    s = str(statistic).strip().lower()
    common = dict(rate_hz=rate_hz, taus=taus, input=input, confidence=confidence)
    if s in CORE:
        r = deviation(s, data, alpha=alpha, edf_method=edf_method, chunked=chunked, **common)
        if bias_correction and s == "totdev":
            T = (r.n_samples - (0 if r.input == "rate" else 1)) * r.tau0_s
            b = totdev_bias(r.alpha, r.taus_s, T)
            f = 1.0 / np.sqrt(b)
            r = DeviationResult(**{**r.__dict__, "dev": r.dev * f, "ci_low": r.ci_low * f,
                                   "ci_high": r.ci_high * f})
        return r
    if s in ("mtotdev", "ttotdev", "htotdev"):
        from inertialab.noise import total

        return getattr(total, s)(data, alpha=alpha, bias_correction=bias_correction, **common)
    if s in ("theo1", "theobr", "theoh"):
        from inertialab.noise import theo

        if s == "theo1" and bias_correction:
            try:
                return theo.theobr(data, alpha=alpha, **common)
            except InputError as exc:
                if "TheoBR needs" not in str(exc):
                    raise
                import warnings

                from inertialab.errors import DataQualityWarning

                warnings.warn(f"Theo1 not bias-corrected: {exc}", DataQualityWarning,
                              stacklevel=2)
        return getattr(theo, s)(data, alpha=alpha, **common)
    if s in ("mtie", "tierms"):
        from inertialab.noise import tie

        return getattr(tie, s)(data, **common)
    raise InputError(f"unknown statistic '{statistic}' (use {', '.join(ALL_STATISTICS)})")
