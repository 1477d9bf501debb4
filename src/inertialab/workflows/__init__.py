"""Thin workflows, one module per study (docs/architecture.md).

Each offers one verb set on records: ``prepare(record) -> data``, ``fit(data, config) ->
result`` and ``apply(model, record) -> record``; the estimators live on the calib/ and
method floors below, the papers' reproductions in :mod:`inertialab.studies` above.
Workflows never import ``sim/`` and never draw.

The public face, imported on first use: what the registries offer::

    export_targets load_model stat_names (registries)
"""

__all__ = ["export_targets", "load_model", "stat_names"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name in ('export_targets', 'load_model', 'stat_names',):
        from inertialab.workflows import registries as mod
    else:
        raise AttributeError(f"module 'inertialab.workflows' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
