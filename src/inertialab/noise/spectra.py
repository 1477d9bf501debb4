"""Deprecated: this module is :mod:`inertialab.noise.spectral.spectra` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.spectral import spectra

warnings.warn("inertialab.noise.spectra is deprecated: import from inertialab.noise.spectral.spectra",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = spectra
