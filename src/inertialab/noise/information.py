"""Deprecated: this module is :mod:`inertialab.noise.terms.information` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.terms import information

warnings.warn("inertialab.noise.information is deprecated: import from inertialab.noise.terms.information",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = information
