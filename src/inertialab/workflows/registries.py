"""What the command line and the batch runner read from the registries: the statistics
(:mod:`inertialab.noise.statistics.registry`), the export targets (:mod:`inertialab.export`)
and the model types (:mod:`inertialab.calib.model_types`, imported when a model is
loaded: it imports every model class).

The command line imports no method or model floor; it asks here for its choices and
help texts, so a new statistic or exporter appears there with no CLI change. Each
registry is imported when asked for, so a command's ``--help`` loads only its own.
"""

from __future__ import annotations

__all__ = ["export_help", "export_targets", "load_model", "save_model", "stat_help", "stat_names"]


def stat_names() -> tuple[str, ...]:
    """The statistic names ``--stat`` takes, canonical order.

    Examples
    --------
    >>> stat_names()[:3]
    ('adev', 'oadev', 'mdev')
    """
    from inertialab.noise.statistics import registry

    return registry.names()


def stat_help() -> str:
    """The ``--stat`` help text: every registered statistic."""
    return "Comma-separated: " + ", ".join(stat_names()) + "."


def export_targets(kind: str) -> tuple[str, ...]:
    """The export targets of ``kind`` (``noise``, ``calibration`` or ``thermal``).

    Examples
    --------
    >>> "kalibr" in export_targets("noise")
    True
    """
    from inertialab import export

    return export.targets(kind)


def export_help(kind: str) -> str:
    """Help text listing the export targets of ``kind`` and their tools."""
    from inertialab import export

    return " | ".join(f"{e.target} ({e.tool})" for e in export.EXPORTERS if e.kind == kind)


def load_model(path, *, expected_type: str | None = None):
    """Load a model file of any registered type (refusing another type than
    ``expected_type`` when given).

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from pathlib import Path
    >>> from inertialab.learn.poly import PolynomialRegressor
    >>> x = np.c_[np.arange(6.0)]
    >>> path = Path(tempfile.mkdtemp()) / "poly.json"
    >>> _ = save_model(PolynomialRegressor(degree=2).fit(x, x[:, 0] ** 2), path)
    >>> type(load_model(path)).__name__
    'PolynomialRegressor'
    >>> load_model(path, expected_type="vibration-compensation")
    Traceback (most recent call last):
    ...
    inertialab.errors.InputError: ...
    """
    from inertialab.calib.model_types import load_model as _load

    return _load(path, expected_type=expected_type)


def save_model(obj, path, **kw):
    """Write a model of a registered type (:func:`inertialab.calib.save_model`, the one
    load/save pair; ``kw`` as :func:`inertialab.io.modelfile.save_model`)."""
    from inertialab.calib.model_types import save_model as _save

    return _save(obj, path, **kw)
