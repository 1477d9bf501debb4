"""Record I/O: schemas, readers, writers, sidecars and model files.

``read_record(path, kind)`` returns a validated :class:`Record`; ``write_record`` writes
CSV/Parquet plus the JSON sidecar atomically; ``save_model`` writes the JSON model-file
envelope (docs/model-files.md). Models are loaded with
:func:`inertialab.calib.model_types.load_model`, which holds the registry of model types
(this floor cannot import the model classes); exporters to other tools are on their own
floor, :mod:`inertialab.export` (``inertialab.io.exporters`` is its deprecated alias).

The public face is imported on first use, so ``import inertialab.io.<module>`` stays
light (the command line starts without pandas)::

    ReadOptions (mapping)  read_envelope save_model (modelfile)
    Record hash_frame peek_columns read_record validate_frame (readers)
    SCHEMAS (schemas)  read_sidecar sidecar_path (sidecar)
    atomic_write_bytes atomic_write_text write_record (writers)
"""

_FACE = {
    "ReadOptions": "mapping",
    "read_envelope": "modelfile",
    "save_model": "modelfile",
    "Record": "readers",
    "hash_frame": "readers",
    "peek_columns": "readers",
    "read_record": "readers",
    "validate_frame": "readers",
    "SCHEMAS": "schemas",
    "read_sidecar": "sidecar",
    "sidecar_path": "sidecar",
    "atomic_write_bytes": "writers",
    "atomic_write_text": "writers",
    "write_record": "writers",
}

#: ``save_model`` still resolves (deprecated: :func:`inertialab.calib.save_model` is the
#: pair of :func:`inertialab.calib.load_model`) but is no longer part of the face.
__all__ = sorted(set(_FACE) - {"save_model"})


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name == "save_model":  # the one pair is inertialab.calib.load_model / save_model
        import warnings

        warnings.warn("inertialab.io.save_model is deprecated: use inertialab.calib.save_model "
                      "(with load_model, the one pair; it refuses unregistered types)",
                      DeprecationWarning, stacklevel=2)
    module = _FACE.get(name)
    if module is None:
        raise AttributeError(f"module 'inertialab.io' has no attribute {name!r}")
    if module == "mapping":
        from inertialab.io import mapping as mod
    elif module == "modelfile":
        from inertialab.io import modelfile as mod
    elif module == "readers":
        from inertialab.io import readers as mod
    elif module == "schemas":
        from inertialab.io import schemas as mod
    elif module == "sidecar":
        from inertialab.io import sidecar as mod
    else:
        from inertialab.io import writers as mod
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
