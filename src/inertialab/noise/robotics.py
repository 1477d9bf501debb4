"""Deprecated: this module is :mod:`inertialab.noise.terms.robotics` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.terms import robotics

warnings.warn("inertialab.noise.robotics is deprecated: import from inertialab.noise.terms.robotics",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = robotics
