"""Model files: a JSON envelope around a model's parameters.

::

    {"format": "inertialab-model", "format_version": 1, "type": "<tag>",
     "inertialab_version": "...", "created_utc": "...", "units": {...},
     "training_data_sha256": "..." | null, "settings": {...},
     "dependencies": {"numpy": "...", ...}, "payload": {...}}

Loading never executes code from the file: the type tag is looked up in an allow-list
of classes that the caller gives (``types``: the registry of model types,
:data:`inertialab.calib.model_types.TYPES`, which lives on the floor that may import
the model classes; call :func:`inertialab.calib.model_types.load_model`) and the class
rebuilds itself from the plain-JSON payload with ``from_dict``, which checks the payload
against its type's schema first (:func:`inertialab.io.model_schemas.check_own_payload`:
types, shapes, finiteness, ranges). The file is parsed strictly
(:func:`parse_json_strict`: no NaN/Infinity, bounded size, nesting and integers). An
unknown tag, a newer format version, a malformed envelope or a payload the class
rejects is an :class:`~inertialab.errors.InputError`.
Writes are atomic (temporary file + rename). Never pickle. The format is described in
docs/model-files.md.
"""

from __future__ import annotations

import datetime as _dt
import importlib.metadata
import json
import math
import stat
from pathlib import Path

from inertialab.errors import InputError
from inertialab.io.model_schemas import SCHEMAS
from inertialab.io.model_schemas import model_name as _model_name
from inertialab.jsonable import to_jsonable

FORMAT = "inertialab-model"
FORMAT_VERSION = 1

#: Distribution name of each numeric dependency recorded in a model file.
_DEPENDENCIES = {"numpy": "numpy", "scipy": "scipy", "pandas": "pandas", "pywt": "PyWavelets",
                 "statsmodels": "statsmodels"}


def dependency_versions() -> dict[str, str]:
    """Versions of inertialab's numeric dependencies (for provenance)."""
    out = {}
    for name, dist in _DEPENDENCIES.items():
        try:
            out[name] = importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:  # pragma: no cover - core deps
            out[name] = "missing"
    return out


def _model_type(obj) -> str:
    tag = getattr(obj, "MODEL_TYPE", None)
    if tag is None or tag not in SCHEMAS:
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


#: Largest model file read (bytes), deepest nesting and longest integer accepted
#: (a model file is data, never a way to exhaust memory or the stack).
MAX_MODEL_BYTES = 64 << 20
MAX_DEPTH = 32
MAX_INT_DIGITS = 80


class _NonFinite:
    """Stands in for a NaN/Infinity token or an overflowing number while parsing, so that
    the error can name the model type and the key (found after parsing)."""

    def __init__(self, token: str):
        self.token = token


def _nonfinite_float(text: str):
    v = float(text)
    return v if math.isfinite(v) else _NonFinite(text[:30])


def _bounded_int(text: str) -> int:
    if len(text.lstrip("-")) > MAX_INT_DIGITS:
        raise ValueError(f"integer of {len(text)} digits (at most {MAX_INT_DIGITS})")
    return int(text)


def _walk(obj) -> tuple[int, str | None, _NonFinite | None]:
    """Nesting depth of a parsed JSON value, and the key path and token of its first
    non-finite number (iterative: no recursion)."""
    deepest, first, stack = 0, None, [(obj, 1, "")]
    while stack:
        v, d, where = stack.pop()
        if isinstance(v, _NonFinite):
            if first is None or where < first[0]:
                first = (where, v)
            continue
        items = v.items() if isinstance(v, dict) else enumerate(v) if isinstance(v, list) \
            else None
        if items is None:
            continue
        deepest = max(deepest, d)
        for k, x in items:
            if isinstance(x, (list, dict, _NonFinite)):
                stack.append((x, d + 1, f"{where}.{k}" if isinstance(k, str) else
                              f"{where}[{k}]"))
    return deepest, (first[0] if first else None), (first[1] if first else None)


class DuplicateKeyError(ValueError):
    """A JSON object naming one key twice (which value wins differs between parsers)."""


def unique_keys(pairs: list) -> dict:
    """``object_pairs_hook`` of :func:`json.loads` refusing an object that names a key
    twice: a hand-edited file with two ``"fs_hz"`` or two ``"correction_matrix"`` is
    ambiguous, and the last one silently winning is not a reading."""
    out = {}
    for k, v in pairs:
        if k in out:
            raise DuplicateKeyError(f"key '{str(k)[:40]}' appears twice in one object")
        out[k] = v
    return out


def parse_json_strict(raw: bytes, *, what: str, path) -> object:
    """Parse untrusted JSON bytes: UTF-8 only, no NaN/Infinity tokens, no number that
    overflows a double, integers of at most :data:`MAX_INT_DIGITS` digits, nesting of at
    most :data:`MAX_DEPTH`. Anything else is one :class:`InputError` naming ``path``
    (and the key of a non-finite number)."""
    obj = _parse(raw, what=what, path=path)
    _, where, bad = _walk(obj)
    if bad is not None:
        raise InputError(f"{what}{where}: {bad.token} is not finite ({what}s hold finite "
                         "numbers only)", path=path)
    return obj


def _parse(raw: bytes, *, what: str, path) -> object:
    try:
        txt = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{what} is not UTF-8 JSON (byte {exc.start})", path=path) from None
    if txt.startswith("\ufeff"):
        txt = txt[1:]
    try:
        obj = json.loads(txt, parse_constant=_NonFinite, parse_float=_nonfinite_float,
                         parse_int=_bounded_int, object_pairs_hook=unique_keys)
    except json.JSONDecodeError as exc:
        raise InputError(f"{what} is not valid JSON (line {exc.lineno})", path=path) from None
    except RecursionError:
        raise InputError(f"{what} is nested too deeply", path=path) from None
    except ValueError as exc:
        raise InputError(f"{what} is not valid: {exc}", path=path) from None
    if _walk(obj)[0] > MAX_DEPTH:
        raise InputError(f"{what} is nested more than {MAX_DEPTH} deep", path=path)
    return obj


def read_envelope(path, *, types=None) -> dict:
    """Read and check a model file's envelope (without building the model).

    The file must be a regular file of at most :data:`MAX_MODEL_BYTES`; its JSON is
    parsed by :func:`parse_json_strict`; its type must be one of ``types`` (tag ->
    class; default: the tags with a payload schema).

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
    >>> from inertialab.calib import save_model
    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> env = read_envelope(save_model(model, folder / "acc.json"))
    >>> env["format"], env["type"], env["format_version"]
    ('inertialab-model', 'triaxial-calibration', 1)
    >>> sorted(env["payload"])[:3]
    ['correction_matrix', 'flags', 'g_local']
    >>> tmp.cleanup()
    """
    known = SCHEMAS if types is None else types
    p = Path(path)
    try:
        st = p.stat()
    except FileNotFoundError:
        raise InputError("no such model file", path=p) from None
    except OSError as exc:
        raise InputError(f"cannot read model file ({exc.strerror})", path=p) from None
    if not stat.S_ISREG(st.st_mode):
        raise InputError("model file is not a regular file", path=p)
    if st.st_size > MAX_MODEL_BYTES:
        raise InputError(f"model file is larger than {MAX_MODEL_BYTES >> 20} MiB", path=p)
    try:
        with open(p, "rb") as fh:
            raw = fh.read(MAX_MODEL_BYTES + 1)
    except OSError as exc:
        raise InputError(f"cannot read model file ({exc.strerror})", path=p) from None
    if len(raw) > MAX_MODEL_BYTES:
        raise InputError(f"model file is larger than {MAX_MODEL_BYTES >> 20} MiB", path=p)
    env = _parse(raw, what="model file", path=p)
    _, where, bad = _walk(env)
    if bad is not None:  # name the model type when the file has a readable one
        tag = env.get("type") if isinstance(env, dict) else None
        where = where[len(".payload"):] if where.startswith(".payload") else where
        raise InputError(f"{_model_name(tag)} payload{where}: {bad.token} is not finite "
                         "(model files hold finite numbers only)", path=p)
    if not isinstance(env, dict) or env.get("format") != FORMAT:
        raise InputError(f"not an inertialab model file (no \"format\": \"{FORMAT}\")", path=p)
    version = env.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise InputError(f"bad format_version {version!r}", path=p)
    if version > FORMAT_VERSION:
        raise InputError(f"model file format_version {version} is newer than this inertialab "
                         f"reads ({FORMAT_VERSION}); upgrade inertialab", path=p)
    tag = env.get("type")
    if tag not in known:
        raise InputError(f"unknown model type {tag!r} (known: {', '.join(sorted(known))})",
                         path=p)
    if not isinstance(env.get("payload"), dict):
        raise InputError("model file has no payload object", path=p)
    return env


def load_model(path, *, types: dict, expected_type: str | None = None):
    """Load a model written by :func:`save_model`.

    Parameters
    ----------
    types : dict
        The allow-list, tag -> class (:data:`inertialab.calib.model_types.TYPES`).
    expected_type : str, optional
        Refuse a model of another type (e.g. a thermal model given to ``drift forecast``).
    """
    env = read_envelope(path, types=types)
    tag = env["type"]
    if expected_type is not None and tag != expected_type:
        raise InputError(f"model file holds a '{tag}' model, expected '{expected_type}'", path=path)
    cls = types[tag]  # its from_dict checks the payload against the schema of its tag
    try:
        obj = cls.from_dict(env["payload"])
    except (KeyError, TypeError, ValueError, IndexError, AttributeError, OverflowError,
            ZeroDivisionError) as exc:
        if isinstance(exc, InputError):
            raise InputError(str(exc), path=path) from None
        raise InputError(f"model payload is invalid ({type(exc).__name__}: {exc})",
                         path=path) from None
    return obj
