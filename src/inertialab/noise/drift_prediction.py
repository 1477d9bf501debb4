"""Deprecated: this module is :mod:`inertialab.noise.terms.drift_prediction` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.terms import drift_prediction

warnings.warn("inertialab.noise.drift_prediction is deprecated: import from inertialab.noise.terms.drift_prediction",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = drift_prediction
