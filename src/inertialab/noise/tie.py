"""Deprecated: this module is :mod:`inertialab.noise.statistics.tie` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import tie

warnings.warn("inertialab.noise.tie is deprecated: import from inertialab.noise.statistics.tie",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = tie
