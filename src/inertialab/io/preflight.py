"""Deprecated: the checks a command runs before computing live in
:mod:`inertialab.workflows.preflight` (the analysis kinds are the workflows'
knowledge); this name is that module (the same object) for one release."""

import sys
import warnings

import inertialab.workflows.preflight as preflight

warnings.warn("inertialab.io.preflight is deprecated: import from inertialab.workflows.preflight",
              DeprecationWarning, stacklevel=2)
sys.modules[__name__] = preflight
