"""Deprecated: this module is :mod:`inertialab.export.gtsam` (the same module object, so
every name keeps working) for one release."""

import sys
import warnings

from inertialab.export import gtsam

warnings.warn("inertialab.io.exporters.gtsam is deprecated: import from inertialab.export.gtsam",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = gtsam
