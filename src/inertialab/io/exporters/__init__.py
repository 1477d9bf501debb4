"""Deprecated: the exporters live in :mod:`inertialab.export` (the export floor, above
the results it writes); this path and its submodules keep working for one release."""

import warnings

from inertialab.export import (
    EXPORTERS,
    AxisValues,
    Exporter,
    NoiseParams,
    NoiseValues,
    check_topic,
    export_calibration,
    export_noise,
    get,
    gtsam,
    imu_tk,
    imu_utils,
    imucal,
    kalibr,
    noise_text,
    openvins,
    ros,
    targets,
    thermal_c,
    thermal_params,
    yaml_number,
)

__all__ = ["EXPORTERS", "AxisValues", "Exporter", "NoiseParams", "NoiseValues", "check_topic",
           "export_calibration", "export_noise", "get", "gtsam", "imu_tk", "imu_utils", "imucal",
           "kalibr", "noise_text", "openvins", "ros", "targets", "thermal_c", "thermal_params",
           "yaml_number"]

warnings.warn("inertialab.io.exporters is deprecated: import from inertialab.export",
              DeprecationWarning, stacklevel=2)
