"""Deprecated: this module is :mod:`inertialab.noise.statistics.edf_clock` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import edf_clock

warnings.warn("inertialab.noise.edf_clock is deprecated: import from inertialab.noise.statistics.edf_clock",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = edf_clock
