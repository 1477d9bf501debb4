"""One entry point for every statistic of the Allan family (docs/allan.md).

:func:`compute` dispatches ``statistic`` to :func:`inertialab.noise.statistics.allan.deviation`
(adev oadev mdev tdev hdev ohdev totdev) or to the function its entry in
:mod:`inertialab.noise.statistics.registry` declares: :mod:`~inertialab.noise.statistics.total` (mtotdev
ttotdev htotdev), :mod:`~inertialab.noise.statistics.theo` (theo1 theobr theoh) or
:mod:`~inertialab.noise.statistics.tie` (mtie tierms) with the common keywords. ``bias_correction``
applies Stable32's bias corrections where the statistic has one: TOTDEV (``1 - a tau/T``,
``a = 0.481`` FFM, ``0.750`` RWFM, SP 1065 §5.2.11, T the record length), MTOT/TTOT/HTOT
(their factor tables) and Theo1 (the Howe & Tasset ``Avar/Theo1`` of the noise type;
``theobr`` and ``theoh`` are their own statistics, bias-removed by the data's own ratio).
A correction is applied only where the noise type was identified (``alpha_source`` in
:data:`inertialab.noise.statistics.identify.CONFIDENT`: lag-1 ACF, B1, B1 + R(n), or carried from
such a tau, as Stable32 does; 1.0 where the record was too short to identify any), and
the factor the variance was divided by is the result's ``bias`` per tau.
"""

from __future__ import annotations

import numpy as np

from inertialab.errors import InputError
from inertialab.noise.statistics import registry
from inertialab.noise.statistics.allan import STATISTICS as CORE
from inertialab.noise.statistics.allan import CorrectedResult, DeviationResult, deviation
from inertialab.noise.statistics.edf_clock import (  # noqa: F401 - re-exported
    TOTDEV_BIAS_A,
    totdev_bias,
)
from inertialab.noise.statistics.identify import CONFIDENT

#: Every statistic, in their canonical order (declared in :mod:`inertialab.noise.statistics.registry`).
ALL_STATISTICS = registry.names()
#: Statistics in the unit of the phase (rate unit x s; s for a clock), not of the rate.
PHASE_UNIT = registry.phase_unit()


def compute(statistic: str, data, *, rate_hz: float, taus="octave", input: str = "rate",
            confidence: float = 0.683, alpha=None, edf_method: str = "default",
            chunked: bool = False, bias_correction: bool = False,
            progress=None) -> DeviationResult:
    """The statistic ``statistic`` of ``data`` (see the module docstring); ``progress``
    (``update(done, total, note)``) hears the out-of-core path of the core statistics.

    Examples
    --------
    Any statistic by name; for white rate noise of sigma 1 at 100 Hz the Allan deviation
    is ``sigma / sqrt(m)``, and the name may be any case:

    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000)
    >>> r = compute("OADEV", y, rate_hz=100.0, taus=[0.01, 0.16])
    >>> r.statistic, bool(np.allclose(r.dev * np.sqrt(r.m), 1.0, atol=0.03))
    ('oadev', True)
    >>> compute("tierms", y, rate_hz=100.0, taus=[0.04]).dev.round(3).tolist()
    [0.02]
    """
    s = str(statistic).strip().lower()
    common = dict(rate_hz=rate_hz, taus=taus, input=input, confidence=confidence)
    if s in CORE:
        r = deviation(s, data, alpha=alpha, edf_method=edf_method, chunked=chunked,
                      progress=progress, **common)
        if bias_correction and s == "totdev":
            T = (r.n_samples - (0 if r.input == "rate" else 1)) * r.tau0_s
            b = np.where(np.isin(r.alpha_source, CONFIDENT),
                         totdev_bias(r.alpha, r.taus_s, T), 1.0)
            f = 1.0 / np.sqrt(b)
            r = CorrectedResult(**{**r.__dict__, "dev": r.dev * f, "ci_low": r.ci_low * f,
                                   "ci_high": r.ci_high * f, "bias": b})
        return r
    try:
        entry = registry.get(s)
    except KeyError:
        raise InputError(f"unknown statistic '{statistic}' (use "
                         f"{', '.join(ALL_STATISTICS)})") from None
    if entry.edf != "none":  # a noise type for the interval (and the bias correction)
        common["alpha"] = alpha
    if entry.bias_correction:
        common["bias_correction"] = bias_correction
    return entry.function(data, **common)
