"""Deprecated: the ``vibration`` commands' settings and calls live in
:mod:`inertialab.workflows.vibration` (one workflow module per study); this name keeps
them for one release."""

import warnings

from inertialab.workflows.vibration import (
    JSON_UNITS,
    ApplyConfig,
    ApplyResult,
    FitConfig,
    FitResult,
    run_apply,
    run_fit,
)

__all__ = ["JSON_UNITS", "ApplyConfig", "ApplyResult", "FitConfig", "FitResult", "run_apply",
           "run_fit"]

warnings.warn("inertialab.workflows.vibration_run is deprecated: import from "
              "inertialab.workflows.vibration", DeprecationWarning, stacklevel=2)
