"""Learning methods: clustering, fuzzy inference, ANFIS, RBF and LM-trained networks,
NAR forecasting, order selection, regression and forecast baselines. Every estimator
follows :mod:`inertialab.estimator` (scikit-learn's contract).

The public face, imported on first use::

    PolynomialRegressor (poly)  RBFNetwork (rbf)  ANFIS (anfis)  MLPRegressorLM (mlp_lm)
    NARForecaster (nar)  DirectNARForecaster (nar_direct)
"""

__all__ = ["ANFIS", "DirectNARForecaster", "MLPRegressorLM", "NARForecaster",
           "PolynomialRegressor", "RBFNetwork"]


def __getattr__(name):  # PEP 562: the public face, imported on first use
    if name == "PolynomialRegressor":
        from inertialab.learn import poly as mod
    elif name == "RBFNetwork":
        from inertialab.learn import rbf as mod
    elif name == "ANFIS":
        from inertialab.learn import anfis as mod
    elif name == "MLPRegressorLM":
        from inertialab.learn import mlp_lm as mod
    elif name == "NARForecaster":
        from inertialab.learn import nar as mod
    elif name == "DirectNARForecaster":
        from inertialab.learn import nar_direct as mod
    else:
        raise AttributeError(f"module 'inertialab.learn' has no attribute {name!r}")
    return getattr(mod, name)


def __dir__():
    return sorted(__all__)
