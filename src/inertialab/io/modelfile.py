"""Model files: a JSON envelope around a model's parameters (DESIGN.md "Model files").

::

    {"format": "inertialab-model", "format_version": 1, "type": "<tag>",
     "inertialab_version": "...", "created_utc": "...", "units": {...},
     "training_data_sha256": "..." | null, "settings": {...},
     "dependencies": {"numpy": "...", ...}, "payload": {...}}

Loading never executes code from the file: the type tag is looked up in the allow-list
:data:`MODEL_TYPES` (tag -> inertialab class, imported lazily) and the class rebuilds
itself from the plain-JSON payload with ``from_dict``. An unknown tag, a newer format
version, a malformed envelope or a payload the class rejects is an
:class:`~inertialab.errors.InputError`. Writes are atomic (temporary file + rename).
Never pickle.
"""

from __future__ import annotations

import datetime as _dt
import importlib
import json
from pathlib import Path

from inertialab.errors import InputError
from inertialab.jsonable import to_jsonable

FORMAT = "inertialab-model"
FORMAT_VERSION = 1

#: The allow-list: type tag -> "module:Class" inside inertialab.
MODEL_TYPES: dict[str, str] = {
    "polynomial": "inertialab.learn.poly:PolynomialRegressor",
    "rbf": "inertialab.learn.rbf:RBFNetwork",
    "anfis": "inertialab.learn.anfis:ANFIS",
    "mlp-lm": "inertialab.learn.mlp_lm:MLPRegressorLM",
    "nar": "inertialab.learn.nar:NARForecaster",
    "noise-terms": "inertialab.noise.terms:NoiseTerms",
    "vibration-compensation": "inertialab.calib.vibration:VibrationModel",
    "thermal-compensation": "inertialab.calib.thermal:ThermalModel",
    "triaxial-calibration": "inertialab.calib.triaxial:TriaxialCalibration",
    "dual-calibration": "inertialab.calib.dual:DualCalibration",
    "storage-drift": "inertialab.calib.drift:DriftModel",
}

_DEPENDENCIES = ("numpy", "scipy", "pandas", "pywt", "statsmodels")


def dependency_versions() -> dict[str, str]:
    """Versions of inertialab's numeric dependencies (for provenance)."""
    out = {}
    for name in _DEPENDENCIES:
        try:
            mod = importlib.import_module(name)
            out[name] = str(getattr(mod, "__version__", "unknown"))
        except ImportError:  # pragma: no cover - core deps are installed
            out[name] = "missing"
    return out


def _model_type(obj) -> str:
    tag = getattr(obj, "MODEL_TYPE", None)
    if tag is None or tag not in MODEL_TYPES:
        raise TypeError(f"{type(obj).__name__} is not a registered model type")
    return tag


def save_model(obj, path, *, units: dict | None = None, training_data_sha256: str | None = None,
               settings: dict | None = None) -> Path:
    """Write ``obj`` (a registered model: ``MODEL_TYPE`` + ``to_dict()``) to ``path``.

    Parameters
    ----------
    units : dict
        Quantity -> unit of the model's inputs and outputs (e.g. ``{"T": "c"}``).
    training_data_sha256 : str, optional
        :attr:`inertialab.io.Record.sha256` of the training record(s).
    settings : dict, optional
        The settings the model was built with (provenance).
    """
    from inertialab import __version__
    from inertialab.io.writers import atomic_write_text

    tag = _model_type(obj)
    envelope = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "type": tag,
        "inertialab_version": __version__,
        "created_utc": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "units": dict(units or {}),
        "training_data_sha256": training_data_sha256,
        "settings": to_jsonable(settings or {}),
        "dependencies": dependency_versions(),
        "payload": to_jsonable(obj.to_dict()),
    }
    text = json.dumps(envelope, indent=1, allow_nan=False)
    return atomic_write_text(path, text + "\n")


def read_envelope(path) -> dict:
    """Read and check a model file's envelope (without building the model)."""
    p = Path(path)
    if not p.exists():
        raise InputError("no such model file", path=p)
    try:
        env = json.loads(p.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise InputError("model file is not UTF-8 JSON", path=p) from None
    except json.JSONDecodeError as exc:
        raise InputError(f"model file is not valid JSON (line {exc.lineno})", path=p) from None
    if not isinstance(env, dict) or env.get("format") != FORMAT:
        raise InputError(f"not an inertialab model file (no \"format\": \"{FORMAT}\")", path=p)
    version = env.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise InputError(f"bad format_version {version!r}", path=p)
    if version > FORMAT_VERSION:
        raise InputError(f"model file format_version {version} is newer than this inertialab "
                         f"reads ({FORMAT_VERSION}); upgrade inertialab", path=p)
    tag = env.get("type")
    if tag not in MODEL_TYPES:
        raise InputError(f"unknown model type {tag!r} (known: {', '.join(sorted(MODEL_TYPES))})",
                         path=p)
    if not isinstance(env.get("payload"), dict):
        raise InputError("model file has no payload object", path=p)
    return env


def load_model(path, *, expected_type: str | None = None):
    """Load a model written by :func:`save_model`.

    Parameters
    ----------
    expected_type : str, optional
        Refuse a model of another type (e.g. a thermal model given to ``drift forecast``).
    """
    env = read_envelope(path)
    tag = env["type"]
    if expected_type is not None and tag != expected_type:
        raise InputError(f"model file holds a '{tag}' model, expected '{expected_type}'", path=path)
    module_name, _, cls_name = MODEL_TYPES[tag].partition(":")
    cls = getattr(importlib.import_module(module_name), cls_name)
    try:
        obj = cls.from_dict(env["payload"])
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        if isinstance(exc, InputError):
            raise InputError(str(exc), path=path) from None
        raise InputError(f"model payload is invalid ({type(exc).__name__}: {exc})",
                         path=path) from None
    return obj
