"""Deprecated: this module is :mod:`inertialab.export.openvins` (the same module object, so
every name keeps working) for one release."""

import sys
import warnings

from inertialab.export import openvins

warnings.warn("inertialab.io.exporters.openvins is deprecated: import from inertialab.export.openvins",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = openvins
