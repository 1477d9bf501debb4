"""The registry of model types: every class a model file may hold, imported explicitly.

It lives on the calibration floor because that is the lowest floor that may import all
of them (the learners of ``learn/``, the noise terms of ``noise/`` and the calibrations
of ``calib/``); the model-file envelope (:mod:`inertialab.io.modelfile`) is one floor
below and takes the registry as an argument. :func:`load_model` and :func:`save_model`
here are the ones to call.

Each :class:`ModelType` entry names the tag, the class (which follows
:class:`inertialab.calib.base.ModelContract`), what kind of model it is and how it is
applied; the payload schema is the tag's entry in :mod:`inertialab.io.model_schemas`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from inertialab.calib import dual as _dual
from inertialab.calib import ferraris as _ferraris
from inertialab.calib import thermal as _thermal
from inertialab.calib import thermal_imu as _thermal_imu
from inertialab.calib import triaxial_session as _triaxial_session
from inertialab.calib.base import format_version
from inertialab.calib.drift import DriftModel
from inertialab.calib.dual import DualCalibration
from inertialab.calib.ferraris import FerrarisCalibration
from inertialab.calib.thermal import ThermalModel
from inertialab.calib.triaxial import TriaxialCalibration
from inertialab.calib.vibration import VibrationModel
from inertialab.estimator import Estimator
from inertialab.io import modelfile
from inertialab.io.model_schemas import SCHEMAS
from inertialab.learn.anfis import ANFIS
from inertialab.learn.mlp_lm import MLPRegressorLM
from inertialab.learn.nar import NARForecaster
from inertialab.learn.poly import PolynomialRegressor
from inertialab.learn.rbf import RBFNetwork
from inertialab.noise.terms.fit import NoiseTerms, fit_noise_terms

__all__ = ["MODEL_TYPES", "ModelType", "TYPES", "load_model", "save_model", "serves"]


@dataclass(frozen=True)
class ModelType:
    """One registered model type.

    Attributes
    ----------
    cls : type
        The class; its ``MODEL_TYPE`` is the tag.
    kind : str
        ``calibration`` (a product model of ``calib/``), ``learner`` or ``noise``.
    apply : callable or None
        How the model is used on arrays (a method of ``cls`` or a function taking the
        model first); None for a model that is only reported (the noise terms).
    made_by : callable or None
        For a result (not an estimator, :mod:`inertialab.calib.base`): the one function
        that makes it (returning the model, or a fit whose ``model`` it is). None for an
        estimator, which ``cls.fit`` makes.
    """

    cls: type
    kind: str
    apply: Callable | None
    made_by: Callable | None = None

    @property
    def estimator(self) -> bool:
        """Whether the class follows the estimator contract (:mod:`inertialab.estimator`);
        otherwise it is a result (:mod:`inertialab.calib.base`)."""
        return issubclass(self.cls, Estimator)

    @property
    def tag(self) -> str:
        return self.cls.MODEL_TYPE

    @property
    def version(self) -> int:
        """Payload version (``FORMAT_VERSION``; 1 when the class declares none)."""
        return format_version(self.cls)

    @property
    def schema(self):
        """The payload check of :mod:`inertialab.io.model_schemas` (None: none)."""
        return SCHEMAS.get(self.tag)

    @property
    def name(self) -> str:
        """The name a user knows the model by (messages)."""
        return modelfile.MODEL_NAMES.get(self.tag, self.tag)


_ENTRIES = (
    ModelType(PolynomialRegressor, "learner", PolynomialRegressor.predict),
    ModelType(RBFNetwork, "learner", RBFNetwork.predict),
    ModelType(ANFIS, "learner", ANFIS.predict),
    ModelType(MLPRegressorLM, "learner", MLPRegressorLM.predict),
    ModelType(NARForecaster, "learner", NARForecaster.forecast),
    ModelType(NoiseTerms, "noise", None, fit_noise_terms),
    ModelType(VibrationModel, "calibration", VibrationModel.compensate),
    ModelType(ThermalModel, "calibration", _thermal.compensate, _thermal.fit_model),
    ModelType(_thermal_imu.ThermalImuModel, "calibration", _thermal_imu.ThermalImuModel.correct,
              _thermal_imu.fit_imu_model),
    ModelType(TriaxialCalibration, "calibration", TriaxialCalibration.apply,
              _triaxial_session.to_model),
    ModelType(FerrarisCalibration, "calibration", FerrarisCalibration.apply, _ferraris.to_model),
    ModelType(DualCalibration, "calibration", DualCalibration.predict_outputs, _dual.calibrate),
    ModelType(DriftModel, "calibration", DriftModel.forecast, DriftModel.from_results),
)

#: tag -> entry, in the order above.
MODEL_TYPES: dict[str, ModelType] = {e.tag: e for e in _ENTRIES}
#: tag -> class: the allow-list :mod:`inertialab.io.modelfile` takes.
TYPES: dict[str, type] = {tag: e.cls for tag, e in MODEL_TYPES.items()}


def serves(tag: str, expected_type: str) -> bool:
    """Whether a model of type ``tag`` may be used where ``expected_type`` is asked for:
    the same type, or a registered subclass of its class (a ``ferraris-calibration`` is a
    ``triaxial-calibration``)."""
    if tag == expected_type:
        return True
    cls, base = TYPES.get(tag), TYPES.get(expected_type)
    return cls is not None and base is not None and issubclass(cls, base)


def load_model(path, *, expected_type: str | None = None):
    """Load a model file of any registered type (:func:`inertialab.io.modelfile.load_model`
    with this registry); ``expected_type`` refuses a model of another type (a subtype,
    :func:`serves`, is accepted).

    Examples
    --------
    >>> import numpy as np
    >>> from inertialab.calib.triaxial_session import StaticData, calibrate_record_data
    >>> from inertialab.sensors import triaxial as tx
    >>> u = np.random.default_rng(0).normal(size=(12, 3))
    >>> a_true = 9.81 * u / np.linalg.norm(u, axis=1, keepdims=True)  # 12 static attitudes
    >>> x = [0.1, -0.05, 0.2, 1.02, 0.98, 1.01, 0.002, -0.001, 0.003]  # b, k, theta
    >>> raw = tx.forward(x, a_true)
    >>> data = StaticData(a=raw, ref=None, g=9.81, raw_unit="mps2", raw_scale=1.0,
    ...                   raw_offset=0.0, counts=False)
    >>> model = calibrate_record_data(data).model
    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> _ = save_model(model, folder / "acc.json")
    >>> loaded = load_model(folder / "acc.json", expected_type="triaxial-calibration")
    >>> type(loaded).__name__, bool(np.array_equal(loaded.correction_matrix,
    ...                                            model.correction_matrix))
    ('TriaxialCalibration', True)
    >>> load_model(folder / "acc.json", expected_type="thermal-compensation")
    Traceback (most recent call last):
    ...
    inertialab.errors.InputError: ...: model file holds a 'triaxial-calibration' model, ...
    >>> tmp.cleanup()
    """
    if expected_type is not None and any(serves(t, expected_type) for t in TYPES
                                         if t != expected_type):
        tag = modelfile.read_envelope(path, types=TYPES)["type"]
        if serves(tag, expected_type):
            expected_type = tag
    return modelfile.load_model(path, types=TYPES, expected_type=expected_type)


def save_model(obj, path, **kw):
    """Write a registered model (:func:`inertialab.io.modelfile.save_model`).

    Examples
    --------
    >>> import numpy as np
    >>> from inertialab.calib.triaxial_session import StaticData, calibrate_record_data
    >>> from inertialab.sensors import triaxial as tx
    >>> u = np.random.default_rng(0).normal(size=(12, 3))
    >>> a_true = 9.81 * u / np.linalg.norm(u, axis=1, keepdims=True)  # 12 static attitudes
    >>> x = [0.1, -0.05, 0.2, 1.02, 0.98, 1.01, 0.002, -0.001, 0.003]  # b, k, theta
    >>> raw = tx.forward(x, a_true)
    >>> data = StaticData(a=raw, ref=None, g=9.81, raw_unit="mps2", raw_scale=1.0,
    ...                   raw_offset=0.0, counts=False)
    >>> model = calibrate_record_data(data).model
    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> save_model(model, folder / "acc.json").name
    'acc.json'
    >>> bool(np.allclose(load_model(folder / "acc.json").apply(raw), a_true))
    True
    >>> tmp.cleanup()
    """
    if type(obj) not in TYPES.values():
        raise TypeError(f"{type(obj).__name__} is not a registered model type")
    return modelfile.save_model(obj, path, **kw)
