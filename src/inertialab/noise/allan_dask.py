"""Deprecated: this module is :mod:`inertialab.noise.statistics.allan_dask` (the same module object,
so every name keeps working) for one release."""

import sys
import warnings

from inertialab.noise.statistics import allan_dask

warnings.warn("inertialab.noise.allan_dask is deprecated: import from inertialab.noise.statistics.allan_dask",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = allan_dask
