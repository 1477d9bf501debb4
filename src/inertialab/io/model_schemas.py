"""Per-type payload schemas of model files (docs/model-files.md).

Every registered model class checks its own payload here, first thing in its
``from_dict`` (:func:`check_own_payload`): types, shapes, finiteness and ranges, so that
a wrong-typed or edited payload is one :class:`~inertialab.errors.InputError` naming the
model and the key, and no model built from a file (or from a dict in memory) can produce
NaN from finite input. The schemas were written by
reading each type's ``to_dict`` (and the fixtures under ``tests/data/models/``); keys a
schema does not name are allowed (newer writers may add some) but still pass the
generic checks of the loader (finite numbers, bounded nesting and integers).

A schema is a callable ``check(value, where)`` that raises
:class:`~inertialab.errors.SchemaError`; the
builders below compose them.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from inertialab.errors import InputError, SchemaError
from inertialab.jsonable import to_jsonable

Check = Callable[[object, str], None]

#: Longest list in a payload (a model of a million numbers is not a calibration).
MAX_ITEMS = 1_000_000
#: Longest string value.
MAX_TEXT = 4096


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def num(lo: float = -math.inf, hi: float = math.inf, *, nullable: bool = False,
        positive: bool = False) -> Check:
    """A finite number in ``[lo, hi]`` (``> 0`` when ``positive``); ``None`` if nullable."""
    def check(v, where):
        if v is None and nullable:
            return
        if not _is_num(v):
            raise SchemaError(where, f"must be a number, got {type(v).__name__}")
        if not math.isfinite(v):
            raise SchemaError(where, "must be finite")
        if positive and not v > 0:
            raise SchemaError(where, f"must be > 0, got {v!r}")
        if not lo <= v <= hi:
            raise SchemaError(where, f"must be in [{lo:g}, {hi:g}], got {v!r}")
    return check


def integer(lo: int = -(2**63), hi: int = 2**63, *, nullable: bool = False) -> Check:
    """An integer (not a bool) in ``[lo, hi]``."""
    def check(v, where):
        if v is None and nullable:
            return
        if isinstance(v, bool) or not isinstance(v, int):
            raise SchemaError(where, f"must be an integer, got {type(v).__name__}")
        if not lo <= v <= hi:
            raise SchemaError(where, f"must be in [{lo}, {hi}], got {v}")
    return check


def text(*choices: str, nullable: bool = False) -> Check:
    """A string (one of ``choices`` when given)."""
    def check(v, where):
        if v is None and nullable:
            return
        if not isinstance(v, str):
            raise SchemaError(where, f"must be a string, got {type(v).__name__}")
        if len(v) > MAX_TEXT:
            raise SchemaError(where, f"string longer than {MAX_TEXT} characters")
        if choices and v not in choices:
            raise SchemaError(where, f"must be one of {', '.join(choices)}, got {v[:40]!r}")
    return check


def boolean(v, where):
    if not isinstance(v, bool):
        raise SchemaError(where, f"must be true or false, got {type(v).__name__}")


def anything(v, where):
    """No constraint beyond the loader's generic checks."""


def array(*shape: int | None, item: Check | None = None, min_len: int = 0) -> Check:
    """A nested list of ``len(shape)`` dimensions (``None`` = any length) whose leaves
    pass ``item`` (default: a finite number)."""
    leaf = item or num()

    def check(v, where, dims=shape):
        if not isinstance(v, list):
            raise SchemaError(where, f"must be a list, got {type(v).__name__}")
        n = dims[0]
        if n is not None and len(v) != n:
            raise SchemaError(where, f"must have {n} entries, got {len(v)}")
        if len(v) < min_len and dims is shape:
            raise SchemaError(where, f"must have at least {min_len} entries")
        if len(v) > MAX_ITEMS:
            raise SchemaError(where, f"more than {MAX_ITEMS} entries")
        for i, x in enumerate(v):
            if len(dims) > 1:
                check(x, f"{where}[{i}]", dims[1:])
            else:
                leaf(x, f"{where}[{i}]")
    return check


def obj(fields: dict[str, Check], *, optional: tuple[str, ...] = (),
        nullable: bool = False) -> Check:
    """A JSON object with (at least) ``fields``; keys in ``optional`` may be absent."""
    def check(v, where):
        if v is None and nullable:
            return
        if not isinstance(v, dict):
            raise SchemaError(where, f"must be an object, got {type(v).__name__}")
        for key, sub in fields.items():
            if key not in v:
                if key in optional:
                    continue
                raise SchemaError(where, f"lacks '{key}'")
            sub(v[key], f"{where}.{key}")
    return check


def mapping(value: Check, *, min_len: int = 0) -> Check:
    """An object of any keys whose values all pass ``value``."""
    def check(v, where):
        if not isinstance(v, dict):
            raise SchemaError(where, f"must be an object, got {type(v).__name__}")
        if len(v) < min_len:
            raise SchemaError(where, f"must have at least {min_len} entries")
        for key, sub in v.items():
            value(sub, f"{where}.{key}")
    return check


def same_length(*keys: str) -> Check:
    """The lists at ``keys`` (top-level of an object) have one length."""
    def check(v, where):
        lens = {k: len(v[k]) for k in keys if isinstance(v.get(k), list)}
        if len(set(lens.values())) > 1:
            raise SchemaError(where, "lengths differ: " +
                              ", ".join(f"{k} {n}" for k, n in lens.items()))
    return check


def maybe(check: Check) -> Check:
    """``check``, or ``None``."""
    def inner(v, where):
        if v is not None:
            check(v, where)
    return inner


def all_of(*checks: Check) -> Check:
    def check(v, where):
        for c in checks:
            c(v, where)
    return check


def either(*checks: Check) -> Check:
    """The first of ``checks`` that passes; else the first one's error."""
    def check(v, where):
        first = None
        for c in checks:
            try:
                c(v, where)
                return
            except SchemaError as exc:
                first = first or exc
        raise first
    return check


def tagged(tag_key: str, value_key: str, table: dict[str, Check]) -> Check:
    """An object whose ``value_key`` is checked by ``table[obj[tag_key]]`` (a payload
    that names its own layout, e.g. a thermal model's ``regressor_type``)."""
    def check(v, where):
        tag = v.get(tag_key) if isinstance(v, dict) else None
        if tag not in table:
            raise SchemaError(f"{where}.{tag_key}", f"must be one of {', '.join(table)}, "
                              f"got {str(tag)[:40]!r}")
        if value_key in v:
            table[tag](v[value_key], f"{where}.{value_key}")
    return check


# ------------------------------------------------------------------ the types

_SPAN = num(positive=True)  # a scaling span divides: never 0

POLYNOMIAL = all_of(obj({
    "degree": integer(0, 50), "interaction": boolean,
    "powers": array(None, None, item=integer(0, 50), min_len=1),
    "x_min": array(None), "x_span": array(None, item=_SPAN),
    "coef": array(None, min_len=1), "rank": integer(0, 10**6),
}), same_length("powers", "coef"), same_length("x_min", "x_span"))

RBF = all_of(obj({
    "spread": num(positive=True), "goal": num(0),
    "max_neurons": integer(0, 10**6, nullable=True),
    "b": num(), "center_values": array(None, None), "weights": array(None), "bias": num(),
    "mse": num(0, nullable=True), "mse_history": array(None, item=num(0)),
    "centers": either(text(), integer(0, 10**6)),
}, optional=("mse", "mse_history", "centers")), same_length("center_values", "weights"))

_FIS = all_of(obj({
    "mf_input": array(None, item=integer(0, 10**4)), "mf_center": array(None),
    "mf_sigma": array(None, item=num(positive=True)),
    "rule_mf": array(None, None, item=integer(0, 10**6)),
    "consequents": array(None, None),
}), same_length("mf_input", "mf_center", "mf_sigma"), same_length("rule_mf", "consequents"))

_NUMS = either(num(), array(None))  # a setting given per input or once
ANFIS = obj({
    "params": obj({"epochs": integer(0, 10**7), "partition": text(),
                   "n_mfs": either(integer(1, 100), array(None, item=integer(1, 100))),
                   "radius": _NUMS, "squash": num(), "accept": num(), "reject": num(),
                   "step_size": num(), "step_inc": num(), "step_dec": num(),
                   "sigma_min": num(0), "error_goal": num(0), "scale": boolean},
                  optional=("epochs", "partition", "n_mfs", "radius", "squash", "accept",
                            "reject", "step_size", "step_inc", "step_dec", "sigma_min",
                            "error_goal", "scale")),
    "x_lo": array(None), "x_span": array(None, item=_SPAN),
    "y_lo": num(), "y_span": _SPAN, "fis": _FIS, "best_epoch": integer(0, 10**7),
}, optional=("best_epoch",))

MLP = obj({  # a constant column or target has span 0 (spec 004 §3.3; handled on use)
    "params": obj({"hidden": integer(1, 10**5)}, optional=("hidden",)),
    "n_features_in": integer(1, 10**5), "theta": array(None, min_len=1),
    "x_min": array(None), "x_span": array(None, item=num(0)),
    "y_min": num(), "y_span": num(0),
})

NAR = obj({
    "settings": obj({}), "order": integer(1, 10**4), "lo": num(), "span": num(0),
    "constant": boolean, "accepted": boolean, "tail": array(None, min_len=1),
    "seed_entropy": integer(0, 2**256, nullable=True),
    "members": array(None, item=obj({"theta": array(None, min_len=1), "resid": array(None),
                                     "val_mse": num(nullable=True)})),
})

_TERM = obj({"value": num(nullable=True), "unit": text(),
             "ci": array(2, item=num(nullable=True)),
             "tau_range_s": array(2, item=num(nullable=True))},
            optional=("ci", "tau_range_s"))

NOISE_TERMS = obj({
    "Q": _TERM, "N": _TERM, "B": _TERM, "K": _TERM, "R": _TERM,
    "kind": text(), "unit": text(), "coefficients": array(5, item=num(nullable=True)),
    "rate_hz": num(positive=True), "confidence": num(0, 1),
    "alpha_model": array(None, item=integer(-4, 2)), "fit_rmse_log": num(0, nullable=True),
    "g_local": num(0.1, 100), "method": text(), "statistic": text(),
    "tau_range_s": array(2, item=num(0, nullable=True)),
}, optional=("coefficients", "confidence", "alpha_model", "fit_rmse_log", "g_local",
             "method", "statistic", "tau_range_s"))

VIBRATION = obj({
    "level": integer(0, 64), "wavelet": text(), "wavelet_level": integer(0, 64),
    "f_range_hz": array(2, item=num(0)), "rbf": RBF, "poly": POLYNOMIAL,
    "centers": either(text(), integer(0, 10**6)), "goal": num(0),
    "max_neurons": integer(0, 10**6, nullable=True), "poly_degree": integer(0, 50),
    "rng": integer(0, 2**64, nullable=True), "spread": num(positive=True),
}, optional=("poly", "f_range_hz", "centers", "goal", "max_neurons", "poly_degree", "rng",
             "spread"))

TENSOR_POLY = all_of(obj({
    "degrees": array(None, item=integer(0, 50), min_len=1), "lo": array(None),
    "span": array(None, item=_SPAN), "coef": array(None, min_len=1),
}), same_length("degrees", "lo", "span"))

POLY_SEP = obj({"degree": integer(0, 50), "k0": POLYNOMIAL, "k1": POLYNOMIAL,
                "ref": mapping(num(), min_len=2)})

#: a thermal model's regressor, by its ``regressor_type``
REGRESSORS = {"anfis": ANFIS, "mlp-lm": MLP, "tensor-poly": TENSOR_POLY, "poly-sep": POLY_SEP}

THERMAL = all_of(obj({
    "method": text(), "ref": obj({k: num() for k in ("k0", "k1", "k2", "kip", "kp")}),
    "input": text("ua", "raw"), "target": text("linear55", "measured55"),
    "learn_drift": boolean, "t_range_c": array(2, item=num(-273.15, 1e4)),
    "n_range_mv": array(2), "reference_temp_c": num(-273.15, 1e4),
    "regressor_type": text(*REGRESSORS), "regressor": obj({}), "unit_id": text(nullable=True),
    "scm": maybe(mapping(_NUMS)), "search": maybe(obj({})), "metrics": obj({}),
    "raw_drift_max_mv": num(0),
}, optional=("unit_id", "scm", "search", "metrics", "raw_drift_max_mv")),
    lambda v, where: tagged("regressor_type", "regressor", REGRESSORS)(v, where))

_SIX = ("bx", "by", "bz", "kx", "ky", "kz", "theta_yz", "theta_zy", "theta_zx")
_COUNT = integer(0, 10**9, nullable=True)
_FIT = {"residual_rms": num(0, nullable=True), "iterations": _COUNT, "nfev": _COUNT,
        "n_records": _COUNT, "static_intervals": _COUNT}
_TRIAXIAL = {
    "method": text(), "objective": text(),
    "params": obj({k: num() for k in _SIX}),
    "correction_matrix": array(3, 3), "offset": array(3), "raw_unit": text(),
    "g_local": num(0.1, 100), **_FIT,
    "stderr": maybe(mapping(num(0, nullable=True))), "phi": maybe(array(3)),
    "flags": array(None, item=text()), "rest_raw": array(None, 3),
}
_OPTIONAL = ("gyro", *_FIT, "stderr", "phi", "flags", "rest_raw")
_GYRO = {"correction_matrix": array(3, 3), "offset": array(3), "raw_unit": text(),
         "method": text(), "params": mapping(num()),
         "stderr": maybe(mapping(num(0, nullable=True))), "cond": num(0, nullable=True),
         **_FIT}
_GYRO_OPTIONAL = ("method", "params", "stderr", "cond", *_FIT)
TRIAXIAL = obj({**_TRIAXIAL, "gyro": obj(_GYRO, nullable=True, optional=_GYRO_OPTIONAL)},
               optional=_OPTIONAL)
_TURN = obj({"sense": integer(-1, 1), "axis": array(3)})
#: A Ferraris calibration: the triaxial payload with its gyro block and g-sensitivity,
#: the turns' senses and axes, and the turn angle.
FERRARIS = obj({**_TRIAXIAL, "gyro": obj({
    **_GYRO, "g_sensitivity": array(3, 3), "turns": mapping(_TURN),
    "rotation_deg": num(1, 1e5)}, optional=(*_GYRO_OPTIONAL, "turns", "rotation_deg"))},
    optional=tuple(k for k in _OPTIONAL if k != "gyro"))

DUAL = obj({
    "method": text(), "coef": mapping(num(), min_len=1), "sd": mapping(num(0, nullable=True)),
    "s_a": integer(-1, 1), "s_b": integer(-1, 1), "g_local_mps2": num(0.1, 100),
    "residual": num(0, nullable=True),
    "estimable": array(None, item=obj({"name": text(), "value": num(nullable=True),
                                       "sd": num(0, nullable=True)},
                                      optional=("sd",))),
    "units": mapping(text()),
}, optional=("residual", "estimable", "units"))

DRIFT = obj({
    "settings": obj({}),
    "entries": mapping(mapping(obj({
        "origin_day": integer(-10**7, 10**7), "step_days": integer(1, 10**5),
        "y_cal": num(), "tolerance": num(positive=True), "nar": NAR,
    }), min_len=1), min_len=1),
})

#: A drone-IMU thermal model (``inertialab.calib.thermal_imu``): sensors with three axes.
_IMU_AXIS = obj({"axis": text("ax", "ay", "az", "gx", "gy", "gz"), "order": integer(0, 9),
                 "tau_s": num(0, 3600), "coef": array(None, min_len=1),
                 "anfis": maybe(ANFIS), "offset_ref": num(),
                 "scale": maybe(array(None, min_len=1))}, optional=("scale",))
THERMAL_IMU = obj({"method": text("poly", "scm-anfis", "iafsa-scm-anfis"), "source": text(),
                   "sensors": array(None, min_len=1, item=obj({
                       "kind": text("accel", "gyro"), "instance": integer(0, 255),
                       "device_id": integer(0, 2**32), "t_min": num(-100, 200),
                       "t_max": num(-100, 200), "t_ref": num(-100, 200),
                       "center": num(-100, 200), "half": _SPAN, "sigma_s": _SPAN,
                       "bin_s": _SPAN, "dtdt_range": array(2), "relative": boolean,
                       "axes": array(3, item=_IMU_AXIS),
                       "px4": obj({"x": array(4, 3),
                                   "forms": array(3, item=text("static", "as-logged",
                                                               "direct"))})}))})

#: type tag -> payload schema (the tags of :data:`inertialab.calib.model_types.MODEL_TYPES`;
#: every registered type has one, tested).
SCHEMAS: dict[str, Check] = {
    "polynomial": POLYNOMIAL,
    "rbf": RBF,
    "anfis": ANFIS,
    "mlp-lm": MLP,
    "nar": NAR,
    "noise-terms": NOISE_TERMS,
    "vibration-compensation": VIBRATION,
    "thermal-compensation": THERMAL,
    "thermal-imu": THERMAL_IMU,
    "triaxial-calibration": TRIAXIAL,
    "ferraris-calibration": FERRARIS,
    "dual-calibration": DUAL,
    "storage-drift": DRIFT,
}


#: Type tag -> the name a user knows the model by (messages).
MODEL_NAMES = {"thermal-compensation": "thermal", "thermal-imu": "drone IMU thermal",
               "triaxial-calibration": "triaxial", "ferraris-calibration": "ferraris",
               "vibration-compensation": "vibration", "dual-calibration": "dual",
               "storage-drift": "drift"}


def model_name(tag) -> str:
    """``"<name> model"`` of a type tag, for messages (``"model"`` when not a string)."""
    return f"{MODEL_NAMES.get(tag, tag)} model" if isinstance(tag, str) else "model"


def check_own_payload(tag: str, payload) -> None:
    """What a model class's ``from_dict`` runs first: ``payload`` (a file's, or a
    ``to_dict`` in memory, taken as a file would hold it: NaN as null, arrays as lists)
    checked against the schema of ``tag``; a mismatch is one :class:`InputError` naming
    the model and the key.

    Examples
    --------
    >>> check_own_payload("polynomial", {"degree": 1})
    Traceback (most recent call last):
    ...
    inertialab.errors.InputError: polynomial model payload: lacks 'interaction'
    """
    nulls: list[str] = []  # the keys of NaN/infinite numbers, null as in a file
    plain = to_jsonable(payload, nulls=nulls)
    try:
        check_payload(tag, plain)
    except SchemaError as exc:
        if exc.where.lstrip(".") in nulls:
            exc = SchemaError(exc.where, "must be finite, got NaN or infinity")
        raise InputError(f"{model_name(tag)} {exc}") from None


def check_payload(tag: str, payload: dict) -> None:
    """Raise :class:`SchemaError` when ``payload`` does not match type ``tag``'s schema
    (a tag without a schema passes: its class's ``from_dict`` is the only check)."""
    schema = SCHEMAS.get(tag)
    if schema is not None:
        schema(payload, "")
