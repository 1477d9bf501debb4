"""Deprecated: the ``triaxial`` commands' settings and calls live in
:mod:`inertialab.workflows.triaxial` (``ferraris``: :mod:`inertialab.workflows.ferraris`;
one workflow module per study); this name keeps them for one release."""

import warnings

from inertialab.workflows.ferraris import FerrarisConfig, FerrarisResult, run_ferraris
from inertialab.workflows.triaxial import (
    ApplyConfig,
    ApplyResult,
    BatchResult,
    ExportConfig,
    ExportResult,
    FitConfig,
    FitResult,
    run_apply,
    run_export,
    run_fit,
    run_fit_file,
)

__all__ = ["ApplyConfig", "ApplyResult", "BatchResult", "ExportConfig", "ExportResult",
           "FerrarisConfig", "FerrarisResult", "FitConfig", "FitResult", "run_apply",
           "run_export", "run_ferraris", "run_fit", "run_fit_file"]

warnings.warn("inertialab.workflows.triaxial_run is deprecated: import from "
              "inertialab.workflows.triaxial", DeprecationWarning, stacklevel=2)
