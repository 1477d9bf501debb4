"""Tests of inertialab.calib.thermal_export (spec 000 §8.4, issue 5 item 4)."""

from __future__ import annotations

import shutil
import subprocess
import warnings
from dataclasses import replace

import numpy as np
import pytest

from inertialab.calib.thermal import ThermalConfig, compensate, fit_model, make_splits
from inertialab.calib.thermal_export import export_c
from inertialab.errors import ExtrapolationWarning, InputError
from inertialab.sim.thermal_tumble import simulate
from inertialab.workflows.thermal import prepare_samples

CC = shutil.which("cc") or shutil.which("gcc")

DRIVER = r"""
#include <stdio.h>
#include "qfa_comp.h"
int main(void) {
    double t, u, ap;
    int st;
    while (scanf("%lf %lf %lf", &t, &u, &ap) == 3) {
        double y = qfa_comp_mV(t, u, ap, &st);
        double g = qfa_comp_g(t, u, ap, NULL);
        printf("%.17g %.17g %d\n", y, g, st);
    }
    return 0;
}
"""


@pytest.fixture(scope="module")
def models():
    s = prepare_samples(simulate("paper", 0, 0).frame)
    (sp,) = make_splits(s, ThermalConfig(), rng=0)
    cfg = ThermalConfig(epochs=20)
    out = {"plain": fit_model(s, sp, "scm-anfis", cfg),
           "drift": fit_model(s, sp, "scm-anfis", replace(cfg, learn_drift=True)),
           "poly": fit_model(s, sp, "poly-2d", cfg)}
    return s, out


def _inputs(model, n=10_000, seed=0):
    rng = np.random.default_rng(seed)
    tlo, thi = model.t_range_c
    T = rng.uniform(tlo - 10, thi + 10, n)  # ~15 % outside: exercises the clamps
    U = rng.uniform(-1200, 1200, n)  # beyond the +-1 g output range too
    ap = rng.uniform(-1, 1, n)
    return T, U, ap


@pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")
@pytest.mark.parametrize("which", ["plain", "drift"])
def test_compiled_c_agrees_with_python_on_10000_inputs(models, which, tmp_path):
    _, ms = models
    model = ms[which]
    ex = export_c(model)
    (tmp_path / ex.header_name).write_text(ex.header)
    (tmp_path / ex.source_name).write_text(ex.source)
    (tmp_path / "main.c").write_text(DRIVER)
    exe = tmp_path / "comp"
    subprocess.run([CC, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic",
                    "-o", str(exe), str(tmp_path / "main.c"), str(tmp_path / ex.source_name),
                    "-lm"], check=True, capture_output=True)
    T, U, ap = _inputs(model)
    text = "\n".join(f"{a:.17g} {b:.17g} {c:.17g}" for a, b, c in zip(T, U, ap))
    out = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    res = np.loadtxt(out.stdout.splitlines())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)
        py = compensate(model, T, U, ap)
    # the C code repeats the Python arithmetic; only summation order differs (~1e-13 mV)
    assert np.max(np.abs(res[:, 0] - py.nc_mv)) <= 1e-9
    assert np.max(np.abs(res[:, 1] - py.a_g)) <= 1e-12
    np.testing.assert_array_equal(res[:, 2].astype(int), py.status)
    assert set(np.unique(py.status)) == {0, 1, 2, 3}


def test_source_is_dependency_free(models):
    _, ms = models
    ex = export_c(ms["plain"], prefix="unit7")
    assert "malloc" not in ex.source and "#include <stdlib.h>" not in ex.source
    includes = [ln for ln in ex.source.splitlines() if ln.startswith("#include")]
    assert includes == ["#include <math.h>", '#include "unit7_comp.h"']
    assert "unit7_comp_mV" in ex.header and "unit7_comp_g" in ex.header
    assert ex.exp_calls == ms["plain"].n_rules


def test_non_fuzzy_models_and_bad_prefix_are_refused(models):
    _, ms = models
    with pytest.raises(InputError, match="fuzzy models"):
        export_c(ms["poly"])
    with pytest.raises(InputError, match="identifier"):
        export_c(ms["plain"], prefix="9-bad")
