"""Deprecated: this module is :mod:`inertialab.noise.segments.stationarity` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.segments import stationarity

warnings.warn("inertialab.noise.stationarity is deprecated: import from inertialab.noise.segments.stationarity",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = stationarity
