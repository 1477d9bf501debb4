"""Deprecated: this module is :mod:`inertialab.noise.statistics.total` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import total

warnings.warn("inertialab.noise.total is deprecated: import from inertialab.noise.statistics.total",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = total
