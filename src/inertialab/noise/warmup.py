"""Deprecated: this module is :mod:`inertialab.noise.segments.warmup` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.segments import warmup

warnings.warn("inertialab.noise.warmup is deprecated: import from inertialab.noise.segments.warmup",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = warmup
