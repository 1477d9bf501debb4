"""Deprecated: the ``thermal`` commands' settings and calls live in
:mod:`inertialab.workflows.thermal` (one workflow module per study); this name keeps them
for one release."""

import warnings

from inertialab.workflows.thermal import (
    ApplyConfig,
    ApplyResult,
    ExportConfig,
    ExportResult,
    FitConfig,
    FitResult,
    methods_from,
    run_apply,
    run_export,
    run_fit,
)

__all__ = ["ApplyConfig", "ApplyResult", "ExportConfig", "ExportResult", "FitConfig", "FitResult",
           "methods_from", "run_apply", "run_export", "run_fit"]

warnings.warn("inertialab.workflows.thermal_run is deprecated: import from "
              "inertialab.workflows.thermal", DeprecationWarning, stacklevel=2)
