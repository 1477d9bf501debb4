"""Deprecated: this module is :mod:`inertialab.export.thermal_c` (the same module object, so
every name keeps working) for one release."""

import sys
import warnings

from inertialab.export import thermal_c

warnings.warn("inertialab.io.exporters.thermal_c is deprecated: import from inertialab.export.thermal_c",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = thermal_c
