"""Deprecated: this module is :mod:`inertialab.noise.spectral.wavelet` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.spectral import wavelet

warnings.warn("inertialab.noise.wavelet is deprecated: import from inertialab.noise.spectral.wavelet",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = wavelet
