"""Deprecated: :mod:`inertialab.export.triad` (the same module object) for one release."""

import sys
import warnings

from inertialab.export import triad

warnings.warn("inertialab.io.exporters._triad is deprecated: import from inertialab.export.triad",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = triad
