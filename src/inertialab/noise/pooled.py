"""Deprecated: this module is :mod:`inertialab.noise.terms.pooled` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.terms import pooled

warnings.warn("inertialab.noise.pooled is deprecated: import from inertialab.noise.terms.pooled",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = pooled
