"""Deprecated: this module is :mod:`inertialab.noise.statistics.identify` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import identify

warnings.warn("inertialab.noise.identify is deprecated: import from inertialab.noise.statistics.identify",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = identify
