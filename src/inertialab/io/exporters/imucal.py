"""Deprecated: this module is :mod:`inertialab.export.imucal` (the same module object, so
every name keeps working) for one release."""

import sys
import warnings

from inertialab.export import imucal

warnings.warn("inertialab.io.exporters.imucal is deprecated: import from inertialab.export.imucal",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = imucal
