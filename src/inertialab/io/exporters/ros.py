"""Deprecated: this module is :mod:`inertialab.export.ros` (the same module object, so
every name keeps working) for one release."""

import sys
import warnings

from inertialab.export import ros

warnings.warn("inertialab.io.exporters.ros is deprecated: import from inertialab.export.ros",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = ros
