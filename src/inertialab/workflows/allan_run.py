"""Deprecated: the ``allan`` command's settings and call live in
:mod:`inertialab.workflows.allan` (one workflow module per study); this name keeps them
for one release."""

import warnings

from inertialab.workflows.allan import (
    IMU_CONFIDENCE,
    AllanConfig,
    AllanRun,
    lone_series,
    run,
)

__all__ = ["IMU_CONFIDENCE", "AllanConfig", "AllanRun", "lone_series", "run"]

warnings.warn("inertialab.workflows.allan_run is deprecated: import from "
              "inertialab.workflows.allan", DeprecationWarning, stacklevel=2)
