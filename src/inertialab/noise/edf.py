"""Deprecated: this module is :mod:`inertialab.noise.statistics.edf` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import edf

warnings.warn("inertialab.noise.edf is deprecated: import from inertialab.noise.statistics.edf",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = edf
