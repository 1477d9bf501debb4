"""Deprecated: this module is :mod:`inertialab.export.imu_tk` (the same module object, so
every name keeps working) for one release."""

import sys
import warnings

from inertialab.export import imu_tk

warnings.warn("inertialab.io.exporters.imu_tk is deprecated: import from inertialab.export.imu_tk",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = imu_tk
