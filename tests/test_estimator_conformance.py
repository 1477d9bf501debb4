"""The two contracts of inertialab.calib.base, run over everything they cover.

Estimators (scikit-learn's contract, inertialab.estimator): the constructor only stores
its keyword parameters, ``get_params``/``set_params`` round trip, ``clone`` gives an
unfitted copy with equal parameters, ``fit`` returns ``self``, and ``predict``/``forecast``
before ``fit`` raise the one ``NotFittedError``.

Results (every registered model type that is not an estimator): no ``fit``, made by the
one function its registry entry names, used at once by its registered ``apply``,
rebuilt with the same payload by ``from_dict(to_dict())``.

Every registered model type is one or the other, and every estimator of the registry is
in the estimator suite below."""

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

    from tests.source_trees import parsed

    src = Path(__file__).resolve().parents[1] / "src" / "inertialab"
    listed = {p.split(":")[1] for p, _, _ in ESTIMATORS} | {"_Base"}
    missing = []
    for path in src.rglob("*.py"):
        for node in parsed(path).body:
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


# ----------------------------------------------------------------- model types

def test_every_registered_model_type_follows_one_contract():
    from inertialab.calib.model_types import MODEL_TYPES

    listed = {_cls(p) for p, _, _ in ESTIMATORS}
    for tag, e in MODEL_TYPES.items():
        if e.estimator:
            assert e.made_by is None, f"{tag}: an estimator is made by its fit"
            assert e.cls in listed, f"{tag}: estimator outside the estimator suite"
        else:
            assert callable(e.made_by), f"{tag}: a result names the function that makes it"
            assert tag in RESULTS, f"{tag}: result outside the result suite"
            assert not hasattr(e.cls, "fit"), f"{tag}: a result has no fit"
            # named in the statement of inertialab.calib.base
            from inertialab.calib import base

            assert e.cls.__name__ in base.__doc__, tag


def _triaxial(made_by):
    from inertialab.calib.triaxial import calibrate
    from inertialab.sim.triaxial_poses import simulate
    from inertialab.workflows.triaxial import static_data_from_frame

    rec = simulate("turntable62-realistic", seed=1)
    sd = static_data_from_frame(rec.data, rec.meta)
    fit = calibrate(sd.a, objective="norm", g=sd.g)
    # apply: the raw means map to the fit's own corrected vectors (m/s^2 records)
    return made_by(fit, sd), lambda m: m.apply(sd.a), fit.corrected, 1e-9


def _ferraris(made_by):
    from inertialab.calib import ferraris as fr
    from inertialab.sim.ferraris_session import simulate_ferraris

    rec = simulate_ferraris(seed=1, placement_deg=0.5)
    x = rec.data[["ax_mps2", "ay_mps2", "az_mps2", "gx_dps", "gy_dps", "gz_dps"]].to_numpy()
    acc, gyr = x[:, :3], x[:, 3:]
    f = fr.fit_ferraris(acc, gyr, 102.4, fr.detect_sections(acc, gyr, 102.4).sections, g=9.81)
    model = made_by(f, acc_unit="mps2", gyro_unit="dps", g=9.81, n_samples=len(acc))
    i, j = rec.truth["sections"]["z_p"]["start"], rec.truth["sections"]["z_p"]["end"]
    return model, lambda m: m.apply(acc[i:j]), (f.faces.M @ (acc[i:j] - f.faces.b).T).T, 1e-9


def _thermal(made_by):
    from inertialab.calib.thermal import compensate
    from inertialab.sim.thermal_tumble import simulate
    from inertialab.workflows.thermal import FitConfig, make_splits, prepare_samples

    f = simulate("paper", 0, 0).frame
    samples = prepare_samples(f)
    cfg = FitConfig(method=("poly-2d",))
    split = make_splits(samples, cfg, rng=0)[0]
    model = made_by(samples, split, "poly-2d", cfg)
    # the compensated acceleration against the tumble's true input (g); measured max
    # error 3.1e-4 g
    return model, lambda m: compensate(m, f.temp_meas_c, f.output_mv, f.a_pend_g).a_g, \
        f.true_a_in_g.to_numpy(), 1e-3


def _thermal_imu(made_by):
    from inertialab.io.formats.thermal_logs import streams_from_frame
    from inertialab.sim.thermal_imu import simulate

    log = simulate(2, rate_hz=1.0, n_instances=1)
    fit = made_by(streams_from_frame(log.frame))
    g = log.frame
    s = fit.model.sensor("gyro", 0)
    raw = g[["gx_rps", "gy_rps", "gz_rps"]].to_numpy()
    truth = g[["true_off_gx", "true_off_gy", "true_off_gz"]].to_numpy()
    # the corrected gyro against the rig's rate (0) plus its random walk and noise: the
    # estimated offset's error on its own ramp; measured max 1.1e-4 rad/s (1 Hz log)
    return fit, lambda m: m.correct(s, g.t_s, g.temp_c, raw)[0] - (raw - truth), \
        np.zeros_like(raw), 3e-4


def _dual(made_by):
    from inertialab.sensors.dual_meter import meter_outputs
    from inertialab.sim.dual import scenario_config, simulate_run
    from inertialab.studies.dual import reduce_run

    run = simulate_run(scenario_config("S1"), 4)
    fit = made_by(reduce_run(run), methods=("ls",), cross_fit=False)
    phi = np.linspace(0.0, 2 * np.pi, 9)
    # the meters' outputs (g) against the unit's true coefficients; measured max error
    # 1.5e-4 g (head errors of S1)
    return fit, lambda m: np.asarray(m.predict_outputs(phi)), \
        np.asarray(meter_outputs(phi, run.truth, s_a=fit.model.s_a, s_b=fit.model.s_b)), 5e-4


def _drift(made_by):
    import pandas as pd

    from inertialab.calib.drift import fit_series
    from inertialab.workflows.drift import FitConfig, to_daily_grid

    y = 5.0 + np.cumsum(np.random.default_rng(3).normal(0, 0.1, 120))
    s = to_daily_grid(pd.DataFrame({"unit_id": "U1", "day": np.arange(120), "bias_ug": y}),
                      quantity="bias")["U1"]
    st = FitConfig(restarts=2, n_paths=50, horizon=5, baselines=("persistence",))
    r = fit_series(s, st, origin_day=119, rng=1)
    model = made_by({"U1": {"bias": r}}, {"horizon": 5})
    return model, lambda m: np.asarray(m.forecast()["U1"]["bias"]["forecast"]["value"]), \
        np.asarray(r.forecast["value"][:5]), 1e-9


def _noise(made_by):
    from inertialab.noise.statistics.allan import oadev

    x = np.random.default_rng(0).standard_normal(2 ** 14) * 0.01
    return made_by(oadev(x, rate_hz=100.0), unit="rad/s"), None, None, None


#: tag -> builder(made_by) -> (model or fit holding it, apply on arrays, what apply must
#: give (the fit's own numbers or the simulation's truth), absolute tolerance); None:
#: a model only reported
RESULTS = {"triaxial-calibration": _triaxial, "ferraris-calibration": _ferraris,
           "thermal-compensation": _thermal, "thermal-imu": _thermal_imu,
           "dual-calibration": _dual,
           "storage-drift": _drift, "noise-terms": _noise}


@pytest.mark.parametrize("tag", sorted(RESULTS))
def test_every_result_is_made_used_at_once_and_rebuilt(tag):
    import json

    from inertialab.calib.model_types import MODEL_TYPES
    from inertialab.jsonable import to_jsonable

    e = MODEL_TYPES[tag]
    out, use, want, atol = RESULTS[tag](e.made_by)
    model = getattr(out, "model", out)
    assert type(model) is e.cls
    if use is not None:
        got = np.asarray(use(model), dtype=float)
        assert np.all(np.isfinite(got))
        np.testing.assert_allclose(got, want, rtol=0, atol=atol)
    payload = json.dumps(to_jsonable(model.to_dict()), sort_keys=True)
    back = e.cls.from_dict(json.loads(payload))
    assert type(back) is e.cls
    assert json.dumps(to_jsonable(back.to_dict()), sort_keys=True) == payload
    if use is not None:  # the rebuilt model is used at once, with the same numbers
        np.testing.assert_allclose(np.asarray(use(back), dtype=float), got, rtol=1e-12,
                                   atol=1e-15)
