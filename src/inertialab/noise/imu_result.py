"""Deprecated: this module is :mod:`inertialab.noise.terms.imu_result` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.terms import imu_result

warnings.warn("inertialab.noise.imu_result is deprecated: import from inertialab.noise.terms.imu_result",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = imu_result
