"""GTSAM IMU preintegration parameters (``PreintegrationCombinedParams``).

GTSAM has no parameter file of its own; this writes the fields of
``gtsam::PreintegrationCombinedParams`` under their C++/Python setter names, as YAML,
so a script can do ``p = PreintegrationCombinedParams(n_gravity)`` and
``p.setAccelerometerCovariance(np.array(d["accelerometerCovariance"]))`` ...:

* ``accelerometerCovariance`` = accel_noise_density^2 I3 ((m/s^2)^2/Hz, continuous),
* ``gyroscopeCovariance`` = gyro_noise_density^2 I3 ((rad/s)^2/Hz),
* ``integrationCovariance`` = integration_sigma^2 I3 (default 1e-8, the usual value),
* ``biasAccCovariance`` = accel_random_walk^2 I3, ``biasOmegaCovariance`` =
  gyro_random_walk^2 I3 (continuous-time bias random walks),
* ``biasAccOmegaInit`` = bias_init_sigma^2 I6 (1e-5 I6 when not given),
* ``n_gravity`` = [0, 0, -g] (navigation frame z up; ``MakeSharedU(g)``).

:func:`gtsam_params` returns the same as a dict of numpy arrays;
:func:`to_gtsam` builds the GTSAM object when ``gtsam`` is installed.
"""

from __future__ import annotations

import math

import numpy as np

from inertialab.errors import InputError
from inertialab.export.noise_params import NoiseParams, units_comments
from inertialab.export.yaml_text import dump_yaml

__all__ = ["gtsam_params", "gtsam_preintegration_yaml", "to_gtsam", "write_gtsam_params"]


def gtsam_params(*, gyro_noise_density: float, gyro_random_walk: float,
                 accel_noise_density: float, accel_random_walk: float, rate_hz: float,
                 g: float = 9.80665, integration_sigma: float = 1e-4,
                 bias_init_sigma: float | None = None) -> dict:
    """The covariance matrices (numpy) and gravity vector of the preintegration."""
    p = NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                    accel_random_walk, rate_hz)
    return _params(p, g=g, integration_sigma=integration_sigma, bias_init_sigma=bias_init_sigma)


def _params(p: NoiseParams, *, g: float, integration_sigma: float,
            bias_init_sigma: float | None) -> dict:
    for name, v in (("g", g), ("integration_sigma", integration_sigma)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise InputError(f"argument '{name}' must be finite and positive, got {v!r}")
    i3 = np.eye(3)
    bias_int = (bias_init_sigma ** 2) * np.eye(6) if bias_init_sigma is not None \
        else 1e-5 * np.eye(6)
    return {
        "n_gravity": np.array([0.0, 0.0, -float(g)]),
        "accelerometerCovariance": p.accel_noise_density ** 2 * i3,
        "gyroscopeCovariance": p.gyro_noise_density ** 2 * i3,
        "integrationCovariance": float(integration_sigma) ** 2 * i3,
        "biasAccCovariance": p.accel_random_walk ** 2 * i3,
        "biasOmegaCovariance": p.gyro_random_walk ** 2 * i3,
        "biasAccOmegaInit": bias_int,
        "rate_hz": p.rate_hz,
    }


def gtsam_text(p: NoiseParams, *, note=(), g: float = 9.80665, integration_sigma: float = 1e-4,
               bias_init_sigma: float | None = None) -> str:
    """YAML of :func:`gtsam_params` for ``p``."""
    p.require_all("GTSAM")
    d = _params(p, g=g, integration_sigma=integration_sigma, bias_init_sigma=bias_init_sigma)
    doc = {k: (v.tolist() if isinstance(v, np.ndarray) else float(v)) for k, v in d.items()}
    return dump_yaml(doc, comments=[
        "GTSAM PreintegrationCombinedParams (continuous-time covariances, SI units),",
        "by inertialab; keys are GTSAM's setter names without 'set'", *units_comments(),
        *note, *p.bound_comments()])


def gtsam_preintegration_yaml(*, gyro_noise_density: float, gyro_random_walk: float,
                              accel_noise_density: float, accel_random_walk: float,
                              rate_hz: float, **opts) -> str:
    """YAML of :func:`gtsam_params` (same arguments)."""
    return gtsam_text(NoiseParams(gyro_noise_density, gyro_random_walk, accel_noise_density,
                                  accel_random_walk, rate_hz), **opts)


def to_gtsam(**params):
    """A ``gtsam.PreintegrationCombinedParams`` (needs the ``gtsam`` package)."""
    try:
        import gtsam
    except ImportError:
        raise InputError("building GTSAM parameters needs the 'gtsam' package: pip install "
                         "gtsam") from None
    d = gtsam_params(**params)
    p = gtsam.PreintegrationCombinedParams(d["n_gravity"])
    p.setAccelerometerCovariance(d["accelerometerCovariance"])
    p.setGyroscopeCovariance(d["gyroscopeCovariance"])
    p.setIntegrationCovariance(d["integrationCovariance"])
    p.setBiasAccCovariance(d["biasAccCovariance"])
    p.setBiasOmegaCovariance(d["biasOmegaCovariance"])
    setter = getattr(p, "setBiasAccOmegaInit", None) or p.setBiasAccOmegaInt
    setter(d["biasAccOmegaInit"])
    return p


def write_gtsam_params(path, **params) -> None:
    """Write :func:`gtsam_preintegration_yaml` atomically."""
    from inertialab.io.writers import atomic_write_text

    atomic_write_text(path, gtsam_preintegration_yaml(**params))
