"""The scikit-learn contract, run over every estimator (issue 13, DESIGN.md "Conventions"):
the constructor only stores its keyword parameters, ``get_params``/``set_params`` round
trip, ``clone`` gives an unfitted copy with equal parameters, ``fit`` returns ``self``,
and ``predict``/``forecast`` before ``fit`` raise the one ``NotFittedError``."""

import importlib
import inspect

import numpy as np
import pytest

from inertialab.errors import NotFittedError
from inertialab.estimator import Estimator, clone

RNG = np.random.default_rng(0)
X1 = np.linspace(0.0, 1.0, 40)[:, None]
Y1 = np.sin(3.0 * X1[:, 0]) + 0.01 * RNG.standard_normal(40)
X2 = RNG.uniform(-1, 1, (60, 2))
Y2 = X2[:, 0] - 0.5 * X2[:, 1] ** 2
X4 = RNG.uniform(-1, 1, (60, 4))
Y4 = X4 @ np.array([1.0, -0.5, 0.25, 2.0]) + 0.01 * RNG.standard_normal(60)
SERIES = 5.0 + np.cumsum(0.1 * RNG.standard_normal(80))

# (module:Class, kwargs for a quick fit, how to fit) ; fit kinds:
#   "xy": fit(X, y) then predict(X); "series": fit(y) then forecast(3); "z": fit(Z)
ESTIMATORS = [
    ("inertialab.learn.poly:PolynomialRegressor", {"degree": 2}, "xy2"),
    ("inertialab.learn.rbf:RBFNetwork", {"max_neurons": 5}, "xy1"),
    ("inertialab.learn.anfis:ANFIS", {"epochs": 2}, "xy2"),
    ("inertialab.learn.mlp_lm:MLPRegressorLM", {"hidden": 3, "max_epochs": 5, "rng": 0}, "xy2"),
    ("inertialab.learn.order_cv:NadarayaWatson", {"bandwidth": 0.3}, "xy1"),
    ("inertialab.learn.subclust:SubtractiveClustering", {}, "z"),
    ("inertialab.regress.ebr:EmpiricalBayesRidge", {}, "xy4"),
    ("inertialab.learn.nar:NARForecaster", {"order": 2, "hidden": 2, "restarts": 1}, "series"),
    ("inertialab.learn.nar_direct:DirectNARForecaster",
     {"horizon": 3, "order": 2, "hidden": 2, "restarts": 1}, "series"),
    ("inertialab.learn.forecast_baselines:Persistence", {}, "series"),
    ("inertialab.learn.forecast_baselines:WindowMean", {"window": 5}, "series"),
    ("inertialab.learn.forecast_baselines:ARLeastSquares", {"order": 2}, "series"),
    ("inertialab.learn.forecast_baselines:PolyTrend", {"degrees": (1,)}, "series"),
    ("inertialab.learn.forecast_baselines:KernelNAR", {"order": 2}, "series"),
    ("inertialab.calib.vibration:VibrationModel", {}, "vibration"),
    ("inertialab.learn.poly:SeparatePolynomials", {"degree": 2}, "none"),
]


def _cls(path):
    mod, _, name = path.partition(":")
    return getattr(importlib.import_module(mod), name)


def _fit(est, kind):
    if kind == "none":  # fit has a study-specific signature, checked in its own tests
        return est, None
    if kind == "xy1":
        return est.fit(X1, Y1), (lambda e: e.predict(X1))
    if kind == "xy2":
        return est.fit(X2, Y2), (lambda e: e.predict(X2))
    if kind == "xy4":
        return est.fit(X4, Y4), (lambda e: e.predict(X4))
    if kind == "z":
        return est.fit(X2), None
    if kind == "series":
        return est.fit(SERIES), (lambda e: e.forecast(3))
    if kind == "vibration":
        f = np.linspace(100.0, 2000.0, 40)
        return est.fit(f, 1.0 + 1e-3 * f), (lambda e: e.predict(f))
    raise AssertionError(kind)


def _unfitted_call(est, kind):
    if kind in ("xy1", "vibration"):
        return lambda: est.predict(X1 if kind == "xy1" else np.array([100.0]))
    if kind in ("xy2", "xy4"):
        return lambda: est.predict(X2 if kind == "xy2" else X4)
    if kind == "series":
        return lambda: est.forecast(3)
    return None


IDS = [p.split(":")[1] for p, _, _ in ESTIMATORS]


def test_every_estimator_is_in_the_suite():
    """Every class in src/inertialab with a ``fit`` method is listed above (or derives
    from one that is), so a new estimator cannot skip the contract."""
    import ast
    from pathlib import Path

    src = Path(__file__).resolve().parents[1] / "src" / "inertialab"
    listed = {p.split(":")[1] for p, _, _ in ESTIMATORS} | {"_Base"}
    missing = []
    for path in src.rglob("*.py"):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.ClassDef) and any(
                    isinstance(m, ast.FunctionDef) and m.name == "fit" for m in node.body):
                bases = {ast.unparse(b) for b in node.bases}
                if node.name not in listed and not bases & listed:
                    missing.append(f"{path.relative_to(src)}:{node.name}")
    assert not missing, "estimators outside the conformance suite: " + ", ".join(missing)


@pytest.mark.parametrize("path, kwargs, kind", ESTIMATORS, ids=IDS)
def test_constructor_stores_only_its_parameters(path, kwargs, kind):
    cls = _cls(path)
    assert issubclass(cls, Estimator)
    sig = inspect.signature(cls.__init__)
    positional = [p for p in sig.parameters.values()
                  if p.name != "self" and p.kind == p.POSITIONAL_OR_KEYWORD]
    assert not positional, "constructor parameters must be keyword-only"
    est = cls(**kwargs)
    names = set(cls._param_names())
    assert set(vars(est)) == names
    for k, v in kwargs.items():
        assert getattr(est, k) is v


@pytest.mark.parametrize("path, kwargs, kind", ESTIMATORS, ids=IDS)
def test_get_set_params_and_clone(path, kwargs, kind):
    est = _cls(path)(**kwargs)
    params = est.get_params()
    assert set(params) == set(type(est)._param_names())
    twin = clone(est)
    assert twin is not est and type(twin) is type(est)
    assert twin.get_params().keys() == params.keys()
    for name, value in params.items():
        assert est.set_params(**{name: value}) is est
        assert getattr(est, name) is value
    with pytest.raises(ValueError, match="no parameter"):
        est.set_params(not_a_parameter=1)


@pytest.mark.parametrize("path, kwargs, kind", ESTIMATORS, ids=IDS)
def test_not_fitted_then_fit_returns_self(path, kwargs, kind):
    est = _cls(path)(**kwargs)
    call = _unfitted_call(est, kind)
    if call is not None:
        with pytest.raises(NotFittedError):
            call()
    fitted, use = _fit(est, kind)
    assert fitted is est
    if use is not None:
        out = use(est)
        values = getattr(out, "values", out)
        assert np.all(np.isfinite(np.asarray(values, dtype=float)))
    # a clone of a fitted estimator is unfitted again
    twin = clone(est)
    call = _unfitted_call(twin, kind)
    if call is not None:
        with pytest.raises(NotFittedError):
            call()
