"""Deprecated: the ``drift`` commands' settings and calls live in
:mod:`inertialab.workflows.drift` (one workflow module per study); this name keeps them
for one release."""

import warnings

from inertialab.config import Config
from inertialab.workflows.drift import (
    UNITS,
    ApplyResult,
    EvaluateConfig,
    EvaluateResult,
    FitConfig,
    FitResult,
    ForecastResult,
    check_horizon,
    run_apply,
    run_evaluate,
    run_fit,
    run_forecast,
)

__all__ = ["UNITS", "ApplyResult", "Config", "EvaluateConfig", "EvaluateResult", "FitConfig",
           "FitResult", "ForecastResult", "check_horizon", "run_apply", "run_evaluate",
           "run_fit", "run_forecast"]

warnings.warn("inertialab.workflows.drift_run is deprecated: import from "
              "inertialab.workflows.drift", DeprecationWarning, stacklevel=2)
