"""Deprecated: the shared pieces of the exporters live in
:mod:`inertialab.export.yaml_text` (YAML) and :mod:`inertialab.export.noise_params` (the
noise numbers); this name keeps them for one release."""

import warnings

from inertialab.export.noise_params import NoiseParams, units_comments
from inertialab.export.yaml_text import Flow, check_topic, comment_lines, dump_yaml, yaml_number

__all__ = ["Flow", "NoiseParams", "check_topic", "comment_lines", "dump_yaml", "units_comments",
           "yaml_number"]

warnings.warn("inertialab.io.exporters._common is deprecated: import from "
              "inertialab.export.yaml_text or inertialab.export.noise_params",
              DeprecationWarning, stacklevel=2)
