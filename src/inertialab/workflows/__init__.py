"""Thin workflows, one module per study (docs/architecture.md).

Each offers one verb set on records: ``prepare(record) -> data``, ``fit(data, config) ->
result`` and ``apply(model, record) -> record``; the estimators live on the calib/ and
method floors below, the papers' reproductions in :mod:`inertialab.studies` above.
Workflows never import ``sim/`` and never draw.
"""
