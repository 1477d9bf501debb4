"""Deprecated: this module is :mod:`inertialab.noise.statistics.allan` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import allan

warnings.warn("inertialab.noise.allan is deprecated: import from inertialab.noise.statistics.allan",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = allan
