"""Figures the CLI writes outside the demo are laid out in one pass with no text problem
(write_figures draws them through report.html.figure_png)."""

from types import SimpleNamespace

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from inertialab.report import layout
from inertialab.report.figures import drift, thermal, triaxial


def _sections():
    t = np.arange(0, 120, 0.01)
    rng = np.random.default_rng(4)
    acc = rng.normal(0, 30, (t.size, 3)) + [0, 0, 16384]
    gyro = rng.normal(0, 5, (t.size, 3))
    sections = {f"face{k}": (k * 2000, k * 2000 + 1500) for k in range(6)}
    sections.update({f"face{k}_rot": (k * 2000 + 1500, k * 2000 + 2000) for k in range(5)})
    return triaxial.sections_figure(t, acc, gyro, sections, title="session 1")


def _methods():
    poses = [f"{s}{a}" for a in "xyz" for s in "+-"]
    rows = [{"method": m, "pose": p, "vector_error_mps2": 0.01 * (i + 1) * (j % 3 - 1),
             "norm_error_mps2": 0.0} for i, m in enumerate(["lm-s12", "six-position", "acs"])
            for j, p in enumerate(poses)]
    return triaxial.method_errors_figure(pd.DataFrame(rows))


def _coverage():
    d = np.random.default_rng(1).normal(size=(40, 3))
    return triaxial.coverage_figure(d)


def _error_curve():
    k = np.arange(1, 21)
    return drift.error_curve_figure({"nar": list(1e-4 * np.sqrt(k)), "ar": list(1.3e-4 * k ** 0.6),
                                     "persistence": list(2e-4 * k ** 0.5)},
                                    unit_id="QA001", quantity="bias", unit="ug", n_origins=6)


def _bias():
    T = np.linspace(-40, 70, 23)
    bsf = SimpleNamespace(temp_c=T, bias_drift_mg=0.02 * (T - 25) + 1e-4 * (T - 25) ** 2,
                          reference_temp_c=25.0)
    return thermal.bias_figure(bsf, title="unit 7")


def _scale_factor():
    T = np.linspace(-40, 70, 23)
    lev = np.array([-1.0, -0.5, 0.5, 1.0])
    bsf = SimpleNamespace(temp_c=T, levels_g=lev, reference_temp_c=25.0,
                          scale_factor_drift_mv_per_g=0.3 * np.outer(T - 25, lev) / 50)
    return thermal.scale_factor_figure(bsf, title="unit 7")


BUILDERS = [_sections, _methods, _coverage, _error_curve, _bias, _scale_factor]


@pytest.mark.parametrize("build", BUILDERS, ids=[b.__name__.strip("_") for b in BUILDERS])
def test_cli_figures_fit_without_text_problems(build):
    fig = build().figure
    fig.set_dpi(110)  # write_figures' dpi
    try:
        assert layout.fit(fig) is True
        assert layout.text_problems(fig) == []
    finally:
        plt.close(fig)
