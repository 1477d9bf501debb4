"""Deprecated: this module is :mod:`inertialab.export.thermal_params` (the same module object, so
every name keeps working) for one release."""

import sys
import warnings

from inertialab.export import thermal_params

warnings.warn("inertialab.io.exporters.thermal_params is deprecated: import from inertialab.export.thermal_params",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = thermal_params
