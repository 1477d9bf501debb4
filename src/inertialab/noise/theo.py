"""Deprecated: this module is :mod:`inertialab.noise.statistics.theo` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import theo

warnings.warn("inertialab.noise.theo is deprecated: import from inertialab.noise.statistics.theo",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = theo
