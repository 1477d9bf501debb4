"""Deprecated: this module is :mod:`inertialab.noise.segments.static_intervals` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.segments import static_intervals

warnings.warn("inertialab.noise.static_intervals is deprecated: import from inertialab.noise.segments.static_intervals",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = static_intervals
