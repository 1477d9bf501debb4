"""The statistics of the Allan family, each declared once: its function, unit, gap
support, bias correction and EDF model.

Adding a statistic is one :class:`Statistic` entry here plus its estimator module; the
command line's ``--stat`` choices and help, the workflow's checks and the conformance
tests (``tests/test_registries.py``) read this table. References: NIST Special
Publication 1065, *Handbook of Frequency Stability Analysis* (W. J. Riley, 2008), for
the definitions, EDFs and bias corrections; IEEE Std 952-1997 for the IMU use.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from inertialab.noise.statistics import allan, theo, tie, total

__all__ = ["STATISTICS", "Statistic", "names", "phase_unit", "with_gaps"]


@dataclass(frozen=True)
class Statistic:
    """One statistic of the family.

    Attributes
    ----------
    name : str
        The name users give (``--stat``; :func:`inertialab.noise.statistics.family.compute`).
    function : callable
        ``f(data, *, rate_hz, taus, input, confidence, ...) -> DeviationResult``.
    title : str
        What it is, one line (help texts).
    phase_unit : bool
        True when the deviation is in the unit of the phase (rate unit x s; s for a
        clock), False when in the unit of the rate.
    gaps : bool
        True when a gap-resistant form exists (:func:`inertialab.noise.statistics.gaps.gap_deviation`).
    bias_correction : bool
        True when Stable32's bias correction applies (``bias_correction=True``).
    edf : str
        The model of the equivalent degrees of freedom behind the confidence interval
        (``"none"``: no interval).

    Examples
    --------
    >>> first = STATISTICS[0]
    >>> first.name, first.function is allan.adev, first.phase_unit, first.gaps
    ('adev', True, False, True)
    >>> [s.name for s in STATISTICS if s.phase_unit]
    ['tdev', 'ttotdev', 'mtie', 'tierms']
    """

    name: str
    function: Callable
    title: str
    phase_unit: bool
    gaps: bool
    bias_correction: bool
    edf: str


#: Every statistic, in the canonical order (NIST SP 1065 section numbers in ``title``).
STATISTICS: tuple[Statistic, ...] = (
    Statistic("adev", allan.adev, "non-overlapping Allan deviation (SP 1065 eq. 7)",
              False, True, False, "greenhall"),
    Statistic("oadev", allan.oadev, "overlapping Allan deviation (SP 1065 eq. 11)",
              False, True, False, "greenhall"),
    Statistic("mdev", allan.mdev, "modified Allan deviation (SP 1065 eq. 14)",
              False, True, False, "greenhall"),
    Statistic("tdev", allan.tdev, "time deviation tau/sqrt(3) MDEV (SP 1065 eq. 15)",
              True, True, False, "greenhall"),
    Statistic("hdev", allan.hdev, "non-overlapping Hadamard deviation (SP 1065 eq. 17)",
              False, True, False, "greenhall"),
    Statistic("ohdev", allan.ohdev, "overlapping Hadamard deviation (SP 1065 eq. 18)",
              False, True, False, "greenhall"),
    Statistic("totdev", allan.totdev, "total deviation (SP 1065 eq. 25)",
              False, False, True, "sp1065-totdev"),
    Statistic("mtotdev", total.mtotdev, "modified total deviation (SP 1065 eq. 27)",
              False, False, True, "sp1065-table8"),
    Statistic("ttotdev", total.ttotdev, "time total deviation (SP 1065 eq. 28)",
              True, False, True, "sp1065-table8"),
    Statistic("htotdev", total.htotdev, "Hadamard total deviation (SP 1065 eq. 29)",
              False, False, True, "htotvar-howe2000"),
    Statistic("theo1", theo.theo1, "Theo1 deviation (SP 1065 eq. 30)",
              False, False, True, "theo1-howe-peppler"),
    Statistic("theobr", theo.theobr, "bias-removed Theo1 (SP 1065 eq. 31)",
              False, False, False, "theo1-howe-peppler"),
    Statistic("theoh", theo.theoh, "hybrid OADEV/TheoBR (SP 1065 eq. 32)",
              False, False, False, "theo1-howe-peppler"),
    Statistic("mtie", tie.mtie, "maximum time interval error", True, False, False, "none"),
    Statistic("tierms", tie.tierms, "time interval error, rms", True, False, False, "none"),
)

_BY_NAME = {s.name: s for s in STATISTICS}


def names() -> tuple[str, ...]:
    """The statistic names, in canonical order."""
    return tuple(s.name for s in STATISTICS)


def get(name: str) -> Statistic:
    """The entry of ``name`` (case-insensitive); ``KeyError`` when unknown."""
    return _BY_NAME[str(name).strip().lower()]


def phase_unit() -> tuple[str, ...]:
    """Names of the statistics in the unit of the phase."""
    return tuple(s.name for s in STATISTICS if s.phase_unit)


def with_gaps() -> tuple[str, ...]:
    """Names of the statistics with a gap-resistant form."""
    return tuple(s.name for s in STATISTICS if s.gaps)
