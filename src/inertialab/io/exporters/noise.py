"""Deprecated: :mod:`inertialab.export.noise_params` (the same module object) for one
release."""

import sys
import warnings

from inertialab.export import noise_params

warnings.warn("inertialab.io.exporters.noise is deprecated: import from "
              "inertialab.export.noise_params", DeprecationWarning, stacklevel=2)
sys.modules[__name__] = noise_params
