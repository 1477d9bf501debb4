"""Deprecated: the ``batch`` command's settings and calls live in
:mod:`inertialab.workflows.batch` (one workflow module per study); this name keeps them
for one release."""

import warnings

from inertialab.workflows.batch import (
    ALIASES,
    BatchConfig,
    BatchJob,
    BatchRun,
    parse_tolerance,
    prepare,
    run,
)

__all__ = ["ALIASES", "BatchConfig", "BatchJob", "BatchRun", "parse_tolerance", "prepare", "run"]

warnings.warn("inertialab.workflows.batch_run is deprecated: import from "
              "inertialab.workflows.batch", DeprecationWarning, stacklevel=2)
