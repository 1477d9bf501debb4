"""Deprecated: this module is :mod:`inertialab.noise.spectral.emd` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.spectral import emd

warnings.warn("inertialab.noise.emd is deprecated: import from inertialab.noise.spectral.emd",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = emd
