"""Deprecated: the ``dual`` commands' settings and calls live in
:mod:`inertialab.workflows.dual` (one workflow module per study); this name keeps them
for one release."""

import warnings

from inertialab.workflows.dual import (
    DesignConfig,
    DesignResult,
    FitConfig,
    FitResult,
    run_design,
    run_fit,
)

__all__ = ["DesignConfig", "DesignResult", "FitConfig", "FitResult", "run_design", "run_fit"]

warnings.warn("inertialab.workflows.dual_run is deprecated: import from "
              "inertialab.workflows.dual", DeprecationWarning, stacklevel=2)
