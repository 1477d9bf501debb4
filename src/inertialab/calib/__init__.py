"""The product models, one module each: ``triaxial`` (accelerometer + gyro field and
turntable calibration, spec 002), ``ferraris`` (six faces + rotations, a
``ferraris-calibration``: a triaxial calibration with a typed gyro block), ``thermal`` (spec 000), ``dual``
(spec 003), ``vibration`` (spec 001), ``drift`` (spec 004). Each holds the estimator on
arrays (no files, no records), its fitted artefact following the model contract of
:mod:`inertialab.calib.base` (``MODEL_TYPE``, ``FORMAT_VERSION``, ``to_dict`` /
``from_dict``), its units and plausibility checks. :mod:`inertialab.calib.model_types`
is the registry of every model type a model file may hold. Imports the method floor
(``noise learn optim regress sensors metrics``) and nothing above.

The public face, imported on first use::

    load_model save_model MODEL_TYPES (model_types)  ModelContract GyroBlock (base)
    TriaxialCalibration (triaxial)  ThermalModel (thermal)  DualCalibration (dual)
    VibrationModel (vibration)  DriftModel (drift)  FerrarisCalibration fit_ferraris (ferraris)
"""

_TYPES = ("load_model", "save_model", "MODEL_TYPES")
_BASE = ("ModelContract", "GyroBlock", "gyro_block")

__all__ = [*_TYPES, *_BASE, "TriaxialCalibration", "ThermalModel", "DualCalibration",
           "VibrationModel", "DriftModel", "FerrarisCalibration", "fit_ferraris"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name in _TYPES:
        from inertialab.calib import model_types as mod
    elif name in _BASE:
        from inertialab.calib import base as mod
    elif name == "TriaxialCalibration":
        from inertialab.calib import triaxial as mod
    elif name == "ThermalModel":
        from inertialab.calib import thermal as mod
    elif name == "DualCalibration":
        from inertialab.calib import dual as mod
    elif name == "VibrationModel":
        from inertialab.calib import vibration as mod
    elif name == "DriftModel":
        from inertialab.calib import drift as mod
    elif name in ("fit_ferraris", "FerrarisCalibration"):
        from inertialab.calib import ferraris as mod
    else:
        raise AttributeError(f"module 'inertialab.calib' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
