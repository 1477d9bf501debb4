"""Tests of inertialab.export.thermal_c, the C99 export (spec 000 §8.4)."""

from __future__ import annotations

import re
import shutil
import subprocess
import warnings
from dataclasses import replace

import numpy as np
import pytest

from inertialab.calib.thermal import compensate, fit_model
from inertialab.errors import ExtrapolationWarning, InputError
from inertialab.export.thermal_c import export_c
from inertialab.sim.thermal_tumble import simulate
from inertialab.workflows.thermal import FitConfig, make_splits, prepare_samples

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
    frame = simulate("paper", 0, 0).frame
    s = prepare_samples(frame)
    (sp,) = make_splits(s, FitConfig(), rng=0)
    cfg = FitConfig(epochs=20)
    raw_cfg = replace(cfg, input="raw")
    out = {"plain": fit_model(s, sp, "scm-anfis", cfg),
           "drift": fit_model(s, sp, "scm-anfis", replace(cfg, learn_drift=True)),
           "raw": fit_model(prepare_samples(frame, raw_cfg), sp, "scm-anfis", raw_cfg),
           "poly": fit_model(s, sp, "poly-2d", cfg)}
    return s, out


@pytest.fixture(scope="module")
def unit_b():
    """Unit 1 of the lot: its own 55 °C coefficients (spec 000 §3.7 transfer)."""
    return prepare_samples(simulate("paper", 0, 1, seed=1000).frame).ref


def _inputs(model, n=10_000, seed=0):
    rng = np.random.default_rng(seed)
    tlo, thi = model.t_range_c
    T = rng.uniform(tlo - 10, thi + 10, n)  # ~15 % outside: exercises the clamps
    U = rng.uniform(-1200, 1200, n)  # beyond the +-1 g output range too
    ap = rng.uniform(-1, 1, n)
    return T, U, ap


def _compile(ex, tmp_path):
    (tmp_path / ex.header_name).write_text(ex.header)
    (tmp_path / ex.source_name).write_text(ex.source)
    (tmp_path / "main.c").write_text(DRIVER.replace("qfa_", ex.header_name[:-len("_comp.h")] + "_"))
    exe = tmp_path / "comp"
    subprocess.run([CC, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic",
                    "-o", str(exe), str(tmp_path / "main.c"), str(tmp_path / ex.source_name),
                    "-lm"], check=True, capture_output=True)
    return exe


def _run(exe, T, U, ap):
    text = "\n".join(f"{a:.17g} {b:.17g} {c:.17g}" for a, b, c in zip(T, U, ap))
    out = subprocess.run([str(exe)], input=text, capture_output=True, text=True, check=True)
    return np.loadtxt(out.stdout.splitlines())


@pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")
@pytest.mark.parametrize("which", ["plain", "raw"])
def test_compiled_c_carries_the_second_unit_mapping(models, unit_b, which, tmp_path):
    """Code for unit B runs A's model through B's own 55 °C coefficients
    (spec 000 §3.7) and agrees with compensate(..., unit_ref=B) on 10 000 inputs."""
    _, ms = models
    model = ms[which]
    ex = export_c(model, unit_ref=unit_b, unit_id="QFA-0-001")
    assert "MAP_UNIT = 1" in ex.source and "QFA-0-001" in ex.header
    res = _run(_compile(ex, tmp_path), *_inputs(model))
    T, U, ap = _inputs(model)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)
        py = compensate(model, T, U, ap, unit_ref=unit_b)
        own = compensate(model, T, U, ap)
    assert np.max(np.abs(res[:, 0] - py.nc_mv)) <= 1e-9
    assert np.max(np.abs(res[:, 1] - py.a_g)) <= 1e-12
    np.testing.assert_array_equal(res[:, 2].astype(int), py.status)
    # the mapping matters: unit B's K0c/K1c differ from A's by mg-level amounts
    assert np.median(np.abs(py.a_g - own.a_g)) > 1e-4


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


HOSTILE = [
    "U */ int evil(void){return 1;} /*",
    "A\n#define K1C 0\n",
    "x\\",
    "??/ trigraph ??= here",
    "caf\u00e9 \u2603 */",
    "*/" * 200,
]


@pytest.mark.skipif(CC is None, reason="no C compiler (cc) on this machine")
@pytest.mark.parametrize("text", HOSTILE)
def test_data_derived_text_cannot_inject_code(models, unit_b, text, tmp_path):
    """Unit ids and the method name come from records and model files;
    in the generated C they are reduced to a safe character set, so the code compiles
    with -Werror -pedantic and defines no symbol of the payload."""
    _, ms = models
    model = replace(ms["plain"], unit_id=text, method=text)
    ex = export_c(model, unit_ref=unit_b, unit_id=text)
    for code in (ex.header, ex.source):
        assert code.isascii()
        assert "\\" not in code and "??" not in code
        # every comment closes where the generator closes it: one "*/" per "/*", and
        # outside the comments nothing of the payload is left
        assert code.count("/*") == code.count("*/")
        bare = re.sub(r"/\*.*?\*/", "", code, flags=re.S)
        assert "evil" not in bare and "define K1C" not in bare and "trigraph" not in bare
    exe = _compile(ex, tmp_path)
    syms = subprocess.run(["nm", str(exe)], capture_output=True, text=True).stdout
    assert "evil" not in syms
    # and the code still computes what Python computes
    T, U, ap = (np.array([20.0]), np.array([500.0]), np.array([0.1]))
    py = compensate(model, T, U, ap, unit_ref=unit_b)
    assert abs(_run(exe, T, U, ap)[0] - py.nc_mv[0]) <= 1e-9


@pytest.mark.parametrize("where", ["k0", "consequent", "sigma", "range"])
@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_constants_are_refused(models, where, value):
    """NaN/Infinity would be written as 'nan'/'inf', which is not C."""
    from inertialab.learn.anfis import ANFIS

    _, ms = models
    m = ms["plain"]
    reg = ANFIS.from_dict(m.regressor.to_dict())
    if where == "k0":
        bad = replace(m, ref=replace(m.ref, k0=value))
    elif where == "consequent":
        reg.fis_.consequents[1, 2] = value
        bad = replace(m, regressor=reg)
    elif where == "sigma":
        reg.fis_.mf_sigma[0] = value
        bad = replace(m, regressor=reg)
    else:
        bad = replace(m, t_range_c=(m.t_range_c[0], value))
    with pytest.raises(InputError, match="not finite"):
        export_c(bad)


def test_degenerate_constants_are_refused(models):
    _, ms = models
    m = ms["plain"]
    with pytest.raises(InputError, match="K1C"):
        export_c(replace(m, ref=replace(m.ref, k1=0.0)))
    with pytest.raises(InputError, match="range is empty"):
        export_c(replace(m, t_range_c=(10.0, 10.0)))
