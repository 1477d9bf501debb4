"""Deprecated: this module is :mod:`inertialab.noise.spectral.lines` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.spectral import lines

warnings.warn("inertialab.noise.lines is deprecated: import from inertialab.noise.spectral.lines",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = lines
