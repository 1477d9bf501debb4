"""The papers' reproductions, above the product (docs/architecture.md).

One module per study (``allan vibration thermal triaxial dual drift``): its quick and
full settings, the virtual-lab run, Monte Carlo, bootstrap and sweeps, and the
``STUDY`` object the demo runs (:mod:`inertialab.studies.base`). The only floor besides
``cli/`` that imports ``sim/``. Workflows below never import from here.

:data:`STUDIES` is the one table of the studies: their order, and for each whether it is
a command group of its own and the group's help. It feeds the command list
(:data:`inertialab.cli.main.TOP_LEVEL`), the study modules the demo runs
(:func:`study_modules`, :data:`inertialab.studies.base.STUDY_ORDER`) and the report's
figure modules (:func:`inertialab.report.build.figure_modules`); each of them imports its
modules by name in the source, one per entry (tests/studies/test_studies_table.py holds
them to the table). Importing this package loads nothing else.
"""

from typing import NamedTuple


class StudyEntry(NamedTuple):
    """One study: ``name`` (its module in ``studies/``, ``report/figures/``, ``cli/``
    and ``workflows/``) and ``group``: the help of its command group
    ``inertialab <name> fit|apply|...``, or None when the study's command is one
    top-level command (``allan``).

    Examples
    --------
    >>> [s.name for s in STUDIES if s.group is None]
    ['allan']
    >>> STUDIES[2]
    StudyEntry(name='thermal', group='Temperature-drift compensation of quartz accelerometers (spec 000).')
    """

    name: str
    group: str | None


#: The studies, in the order of the command list, the demo and the report.
STUDIES: tuple[StudyEntry, ...] = (
    StudyEntry("allan", None),
    StudyEntry("vibration", "FOG under vibration: wavelet bias separation, RBF bias model "
                            "(spec 001)."),
    StudyEntry("thermal", "Temperature-drift compensation of quartz accelerometers "
                          "(spec 000)."),
    StudyEntry("triaxial", "Triaxial accelerometer + gyro calibration: field poses, Ferraris "
                           "protocol, apply (spec 002)."),
    StudyEntry("dual", "Dual-accelerometer dividing-head calibration, EBR, design (spec 003)."),
    StudyEntry("drift", "Long-term storage drift forecasting and compensation (spec 004)."),
)


def study_module(name: str):
    """The study module ``inertialab.studies.<name>`` of a :data:`STUDIES` entry (each
    imported explicitly, when asked for).

    Examples
    --------
    >>> study_module("drift").STUDY.name
    'drift'
    """
    if name == "allan":
        from inertialab.studies import allan as mod
    elif name == "vibration":
        from inertialab.studies import vibration as mod
    elif name == "thermal":
        from inertialab.studies import thermal as mod
    elif name == "triaxial":
        from inertialab.studies import triaxial as mod
    elif name == "dual":
        from inertialab.studies import dual as mod
    elif name == "drift":
        from inertialab.studies import drift as mod
    else:
        raise KeyError(f"no study {name!r}")
    return mod


def study_modules() -> tuple:
    """The study modules the demo runs (each defines ``STUDY``), in :data:`STUDIES`
    order.

    Examples
    --------
    >>> [m.STUDY.name for m in study_modules()]
    ['allan', 'vibration', 'thermal', 'triaxial', 'dual', 'drift']
    """
    return tuple(study_module(s.name) for s in STUDIES)


__all__ = ["STUDIES", "StudyEntry", "study_module", "study_modules"]
