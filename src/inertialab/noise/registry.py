"""Deprecated: this module is :mod:`inertialab.noise.statistics.registry` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import registry

warnings.warn("inertialab.noise.registry is deprecated: import from inertialab.noise.statistics.registry",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = registry
