"""Deprecated: this module is :mod:`inertialab.noise.statistics.gaps` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import gaps

warnings.warn("inertialab.noise.gaps is deprecated: import from inertialab.noise.statistics.gaps",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = gaps
