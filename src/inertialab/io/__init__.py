"""Record I/O: schemas, readers, writers, sidecars and model files.

``read_record(path, kind)`` returns a validated :class:`Record`; ``write_record`` writes
CSV/Parquet plus the JSON sidecar atomically; ``save_model`` writes the JSON model-file
envelope (docs/model-files.md). Models are loaded with
:func:`inertialab.calib.model_types.load_model`, which holds the registry of model types
(this floor cannot import the model classes); exporters to other tools are in
:mod:`inertialab.io.exporters`.
"""

from inertialab.io.mapping import ReadOptions
from inertialab.io.modelfile import read_envelope, save_model
from inertialab.io.readers import Record, hash_frame, peek_columns, read_record, validate_frame
from inertialab.io.schemas import SCHEMAS
from inertialab.io.sidecar import read_sidecar, sidecar_path
from inertialab.io.writers import atomic_write_bytes, atomic_write_text, write_record

__all__ = [
    "ReadOptions",
    "SCHEMAS",
    "Record",
    "atomic_write_bytes",
    "atomic_write_text",
    "hash_frame",
    "peek_columns",
    "read_envelope",
    "read_record",
    "read_sidecar",
    "save_model",
    "sidecar_path",
    "validate_frame",
    "write_record",
]
