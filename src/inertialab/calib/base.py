"""The contract every saved model follows, and the typed gyro block of a triaxial
calibration.

A model type (a calibration of ``calib/``, a learner of ``learn/``, the noise terms of
``noise/``) is a class with

* ``MODEL_TYPE``: its tag in the model file (``"triaxial-calibration"``);
* ``FORMAT_VERSION``: the version of its payload layout (1 when the class declares none);
* ``to_dict()``: a plain-JSON payload (numbers, strings, lists, dicts), and
* ``from_dict(payload)``: the class method that rebuilds an equal model from it, first
  checking the payload against its type's schema
  (:func:`inertialab.io.model_schemas.check_own_payload`: one
  :class:`~inertialab.errors.InputError` line naming the key), and raising InputError
  (or ``KeyError/TypeError/ValueError``) on a payload it cannot use.

:class:`ModelContract` states it as a :class:`typing.Protocol`; the registry of model
types (:mod:`inertialab.calib.model_types`) lists every class that follows it and
``tests/test_registries.py`` checks each one (round trip, schema, fixture).

Estimators and results
----------------------
Beside that, every model type is one of two kinds, and the registry says which
(:attr:`inertialab.calib.model_types.ModelType.estimator`):

**An estimator** follows the estimator contract of :mod:`inertialab.estimator`
(scikit-learn's): a keyword-only constructor that only stores its hyper-parameters,
``fit`` that sets ``attr_`` attributes and returns ``self``,
:class:`~inertialab.errors.NotFittedError` before it, ``get_params``/``set_params`` and
:func:`~inertialab.estimator.clone`. These are the learners of ``learn/`` and
:class:`~inertialab.calib.vibration.VibrationModel`, whose fit is a map from arrays to
arrays (``fit(f_hz, e_dph)``).

**A result** is the outcome of a study's fit, not an estimator: the calibrations
:class:`~inertialab.calib.triaxial.TriaxialCalibration`,
:class:`~inertialab.calib.ferraris.FerrarisCalibration`,
:class:`~inertialab.calib.thermal.ThermalModel`,
:class:`~inertialab.calib.thermal_imu.ThermalImuModel`,
:class:`~inertialab.calib.dual.DualCalibration`,
:class:`~inertialab.calib.drift.DriftModel` and the noise terms
(:class:`~inertialab.noise.terms.fit.NoiseTerms`). Their fit needs the study's whole session
(static intervals with references, sections and turns, tumble samples with their splits,
reduced tumbles with a prior, the daily grids of many units, an Allan curve) and gives
diagnostics beside the model (fit statistics, checks, held-out scores) that a
``fit(X, y)`` returning ``self`` has no place for; and their attributes are what the
model file stores, read by name by the exporters and the workflows. A result follows
instead:

1. one function makes it, named in its registry entry
   (:attr:`~inertialab.calib.model_types.ModelType.made_by`):
   ``triaxial_session.to_model`` (of :func:`~inertialab.calib.triaxial.calibrate`'s fit),
   ``ferraris.to_model`` (of ``fit_ferraris``), ``thermal.fit_model``,
   ``thermal_imu.fit_imu_model`` (its ``model``), ``dual.calibrate``
   (its ``model``), :meth:`DriftModel.from_results <inertialab.calib.drift.DriftModel.from_results>`
   (of ``fit_series``) and ``noise.terms.fit.fit_noise_terms``;
2. it has no ``fit`` and no unfitted state: the constructor takes every fitted value by
   keyword, so the registered ``apply`` works at once and ``NotFittedError`` never
   arises;
3. ``from_dict(to_dict())`` rebuilds it with the same payload.

``tests/test_estimator_conformance.py`` runs the estimator contract over every estimator
and this one over every result, each found from the registry.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar, Protocol, runtime_checkable

import numpy as np

from inertialab.errors import InputError

__all__ = ["GyroBlock", "ModelContract", "format_version", "gyro_block"]


@runtime_checkable
class ModelContract(Protocol):
    """What a saved model provides (see the module docstring).

    Examples
    --------
    Every registered model type keeps the contract (checked at run time):

    >>> from inertialab.calib.model_types import TYPES
    >>> all(isinstance(cls, type) and hasattr(cls, "MODEL_TYPE") and callable(cls.from_dict)
    ...     and callable(getattr(cls, "to_dict", None)) for cls in TYPES.values())
    True
    >>> class Offset:
    ...     MODEL_TYPE = "offset"
    ...     def __init__(self, b):
    ...         self.b = b
    ...     def to_dict(self):
    ...         return {"b": self.b}
    ...     @classmethod
    ...     def from_dict(cls, d):
    ...         return cls(d["b"])
    >>> isinstance(Offset(0.5), ModelContract), Offset.from_dict(Offset(0.5).to_dict()).b
    (True, 0.5)
    >>> isinstance(object(), ModelContract)
    False
    """

    MODEL_TYPE: ClassVar[str]

    def to_dict(self) -> dict: ...

    @classmethod
    def from_dict(cls, d: dict): ...


def format_version(cls) -> int:
    """The payload version of model class ``cls`` (1 when it declares none)."""
    return int(getattr(cls, "FORMAT_VERSION", 1))


_CORE = ("method", "raw_unit", "correction_matrix", "offset", "g_sensitivity", "params",
         "residual_rms", "n_records", "static_intervals")


@dataclass
class GyroBlock(Mapping):
    """The gyro part of a triaxial calibration (Ferraris protocol or turntable fit).

    ``rate = correction_matrix @ (raw - offset - g_sensitivity @ acc)`` with ``raw`` in
    ``raw_unit``, ``rate`` in rad/s and ``acc`` the calibrated specific force in m/s^2
    (``g_sensitivity`` in raw unit per m/s^2; None when not estimated).

    It also reads as a read-only mapping of its stored layout (:meth:`to_dict`:
    ``block["offset"]``, ``block.get("g_sensitivity")``), so that code written for a
    triaxial calibration's gyro dict reads a typed block unchanged.

    Attributes
    ----------
    method : str                ``ferraris`` or ``integration``
    raw_unit : str              unit suffix of the raw gyro samples
    correction_matrix : ndarray (3, 3), rad/s per raw unit
    offset : ndarray (3,), raw unit
    g_sensitivity : ndarray (3, 3) or None, raw unit per m/s^2
    params : dict               named parameters (bias, matrix entries)
    residual_rms : float        raw unit
    n_records, static_intervals : int
    extra : dict                method-specific entries (``turns``, ``rotation_deg``,
                                ``stderr``, ``iterations`` ...), kept in order

    Examples
    --------
    A gyro reading 1 % high on x and 1 % low on y, with biases in deg/s; a true rate of
    (10, 20, 30) deg/s comes back in rad/s:

    >>> import numpy as np
    >>> block = GyroBlock(method="integration", raw_unit="dps",
    ...                   correction_matrix=np.deg2rad(np.diag([1 / 1.01, 1 / 0.99, 1.0])),
    ...                   offset=np.array([0.5, -0.2, 0.1]))
    >>> raw = np.array([[10 * 1.01 + 0.5, 20 * 0.99 - 0.2, 30 + 0.1]])
    >>> bool(np.allclose(block.apply(raw), np.deg2rad([[10.0, 20.0, 30.0]])))
    True
    >>> block["raw_unit"], "g_sensitivity" in block
    ('dps', False)
    """

    method: str
    raw_unit: str
    correction_matrix: np.ndarray
    offset: np.ndarray
    g_sensitivity: np.ndarray | None = None
    params: dict = field(default_factory=dict)
    residual_rms: float = math.nan
    n_records: int = 0
    static_intervals: int | None = None
    extra: dict = field(default_factory=dict)

    def __post_init__(self):
        self.correction_matrix = np.asarray(self.correction_matrix, dtype=float)
        self.offset = np.asarray(self.offset, dtype=float)
        if self.correction_matrix.shape != (3, 3) or self.offset.shape != (3,):
            raise InputError(f"gyro block needs a 3x3 correction matrix and a 3-vector offset, "
                             f"got {self.correction_matrix.shape} and {self.offset.shape}")
        if self.g_sensitivity is not None:
            self.g_sensitivity = np.asarray(self.g_sensitivity, dtype=float)
            if self.g_sensitivity.shape != (3, 3):
                raise InputError("gyro g-sensitivity must be 3x3, got "
                                 f"{self.g_sensitivity.shape}")

    def to_dict(self) -> dict:
        """The block as a triaxial calibration stores it (arrays stay numpy; the model
        file writer makes them lists). ``g_sensitivity`` is omitted when None."""
        d = {"method": self.method, "raw_unit": self.raw_unit,
             "correction_matrix": self.correction_matrix, "offset": self.offset}
        if self.g_sensitivity is not None:
            d["g_sensitivity"] = self.g_sensitivity
        d.update({"params": dict(self.params), "residual_rms": self.residual_rms,
                  "n_records": self.n_records, "static_intervals": self.static_intervals})
        d.update(self.extra)
        return d

    @classmethod
    def from_dict(cls, d: dict) -> GyroBlock:
        """Rebuild from :meth:`to_dict` (or a stored block: lists instead of arrays)."""
        try:
            return cls(method=str(d.get("method", "")), raw_unit=str(d["raw_unit"]),
                       correction_matrix=d["correction_matrix"], offset=d["offset"],
                       g_sensitivity=d.get("g_sensitivity"), params=dict(d.get("params") or {}),
                       residual_rms=float(d["residual_rms"]) if d.get("residual_rms")
                       is not None else math.nan,
                       n_records=int(d.get("n_records", 0)),
                       static_intervals=d.get("static_intervals"),
                       extra={k: v for k, v in d.items() if k not in _CORE})
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"not a valid gyro block ({exc})") from None

    def __getitem__(self, key):
        return self.to_dict()[key]

    def __iter__(self):
        return iter(self.to_dict())

    def __len__(self) -> int:
        return len(self.to_dict())

    def apply(self, raw, acc=None) -> np.ndarray:
        """Calibrated rates (rad/s) of raw gyro samples ``(n, 3)``; ``acc`` (m/s^2) is
        needed when the block corrects the g-sensitivity."""
        r = np.asarray(raw, dtype=float) - self.offset
        if self.g_sensitivity is not None:
            if acc is None:
                raise InputError("this gyro calibration corrects the g-sensitivity: give the "
                                 "calibrated accelerations (argument 'acc')")
            r = r - np.asarray(acc, dtype=float) @ self.g_sensitivity.T
        return r @ self.correction_matrix.T


def gyro_block(model) -> GyroBlock | None:
    """The typed gyro block of a triaxial calibration (None when it has none).

    Examples
    --------
    The stored dict form of a triaxial calibration's gyro block comes back typed:

    >>> import numpy as np
    >>> block = GyroBlock(method="integration", raw_unit="dps",
    ...                   correction_matrix=np.deg2rad(np.diag([1 / 1.01, 1 / 0.99, 1.0])),
    ...                   offset=np.array([0.5, -0.2, 0.1]))
    >>> class Model:
    ...     gyro = block.to_dict()
    >>> typed = gyro_block(Model())
    >>> isinstance(typed, GyroBlock), bool(np.array_equal(typed.offset, block.offset))
    (True, True)
    >>> class NoGyro:
    ...     gyro = None
    >>> gyro_block(NoGyro()) is None
    True
    """
    g = getattr(model, "gyro", None)
    if g is None or isinstance(g, GyroBlock):
        return g
    return GyroBlock.from_dict(g)

