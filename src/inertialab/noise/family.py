"""Deprecated: this module is :mod:`inertialab.noise.statistics.family` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import family

warnings.warn("inertialab.noise.family is deprecated: import from inertialab.noise.statistics.family",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = family
