"""Deprecated: this module is :mod:`inertialab.export.kalibr` (the same module object, so
every name keeps working) for one release."""

import sys
import warnings

from inertialab.export import kalibr

warnings.warn("inertialab.io.exporters.kalibr is deprecated: import from inertialab.export.kalibr",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = kalibr
