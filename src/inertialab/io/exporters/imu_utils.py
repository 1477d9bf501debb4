"""Deprecated: this module is :mod:`inertialab.export.imu_utils` (the same module object, so
every name keeps working) for one release."""

import sys
import warnings

from inertialab.export import imu_utils

warnings.warn("inertialab.io.exporters.imu_utils is deprecated: import from inertialab.export.imu_utils",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = imu_utils
