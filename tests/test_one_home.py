"""One home per concept, kept so by reading the code with ``ast``:

- the sample rate of a record is decided once, by :class:`inertialab.io.Record`'s time
  base (:func:`inertialab.io.timestamps.decide_timebase`); no module outside ``io/``
  derives a rate or a step from time stamps (``median(diff(t))``, ``(n - 1) / (t[-1] -
  t[0])``) but the listed one, a storage programme's day step, which is no sample rate;
  array-level functions given bare stamps ask :func:`inertialab.io.timestamps.stamps_rate_hz`;
- the default confidence of a record kind is written once
  (:data:`inertialab.config.DEFAULT_CONFIDENCE`);
- the taus grammar is parsed once (:func:`inertialab.workflows.allan.parse_taus`).
"""

import ast
from pathlib import Path

from tests.source_trees import parsed

SRC = Path(__file__).resolve().parent.parent / "src" / "inertialab"

#: Step derivations from a time column outside io/ that are not a log's sample rate: a
#: storage programme's day column (one grid step per unit, in whole days between
#: measurement days, replicates of a day collapsed first) has no Record time base.
RATE_SITES_LEFT = {
    "workflows/drift.py:to_daily_grid",
}


def _is_diff(node) -> bool:
    return (isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", ""))
            == "diff")


def _is_span(node) -> bool:
    """``t[-1] - t[0]`` (a time span from the first and last stamp)."""
    if not (isinstance(node, ast.BinOp) and isinstance(node.op, ast.Sub)):
        return False
    parts = [n.value if isinstance(n, ast.Call) and n.args == [] else n
             for n in (node.left, node.right)]
    parts = [p.args[0] if isinstance(p, ast.Call) and p.args else p for p in parts]
    return all(isinstance(p, ast.Subscript) for p in parts) and \
        ast.unparse(parts[0]).endswith("[-1]") and ast.unparse(parts[1]).endswith("[0]")


def _rate_derivations():
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if rel.startswith("io/"):
            continue
        tree = parsed(path)
        for fn in ast.walk(tree):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            steps = {t.id for n in ast.walk(fn) if isinstance(n, ast.Assign) and _is_diff(n.value)
                     for t in n.targets if isinstance(t, ast.Name)}  # dt = np.diff(t)
            for node in ast.walk(fn):
                median_step = (isinstance(node, ast.Call)
                               and getattr(node.func, "attr", "") in ("median", "mean")
                               and node.args and (_is_diff(node.args[0]) or (
                                   isinstance(node.args[0], ast.Name)
                                   and node.args[0].id in steps)))
                span_rate = (isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div)
                             and _is_span(node.right))
                if median_step or span_rate:
                    yield f"{rel}:{fn.name}"
                    break


def test_the_rate_is_decided_only_by_the_record():
    found = set(_rate_derivations())
    new = sorted(found - RATE_SITES_LEFT)
    assert not new, f"rate derived from time stamps outside io/ (use rec.timebase): {new}"
    gone = sorted(RATE_SITES_LEFT - found)
    assert not gone, f"moved to the time base: remove from RATE_SITES_LEFT: {gone}"


def test_the_rule_sees_a_derivation():
    code = "def f(t):\n    return 1.0 / np.median(np.diff(t)), (len(t) - 1) / (t[-1] - t[0])\n"
    fn = ast.parse(code).body[0]
    calls = [n for n in ast.walk(fn) if isinstance(n, ast.Call)
             and getattr(n.func, "attr", "") == "median" and _is_diff(n.args[0])]
    spans = [n for n in ast.walk(fn) if isinstance(n, ast.BinOp) and _is_span(n)]
    assert calls and spans


def test_bare_stamps_take_the_rate_the_record_would_decide():
    """An array-level call without a rate takes the one io rule (``stamps_rate_hz``, the
    rate ``decide_timebase`` gives the same stamps), not the median step; a given rate
    wins; ``triaxial fit`` detects at the record's time base."""
    import warnings

    import numpy as np

    from inertialab.io.timestamps import decide_timebase, stamps_rate_hz
    from inertialab.noise.segments.static_intervals import detect_static_intervals

    rng = np.random.default_rng(3)
    t = np.arange(3000) / 100.0 + rng.normal(0.0, 2e-4, 3000)  # 2 % rms stamp jitter
    t = np.delete(t, np.arange(1500, 1503))  # three samples lost
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        decided = decide_timebase(t, n=t.size).rate_hz
    assert stamps_rate_hz(t) == decided and abs(decided - 100.0) < 1e-3
    assert abs(1.0 / np.median(np.diff(t)) - decided) > 1e-3  # the rule that moved out differs
    acc = np.array([0.0, 0.0, 9.81]) + rng.normal(0.0, 0.01, (t.size, 3))
    assert detect_static_intervals(t, acc).fs == decided
    assert detect_static_intervals(t, acc, rate_hz=99.0).fs == 99.0


#: ``confidence`` defaults written as a number outside noise/ (whose functions default to
#: Stable32's 0.683 for clocks) other than the one home, inertialab.config.DEFAULT_CONFIDENCE: the six-axis
#: workflow still spells 0.95 itself (owned by the noise work; it should take
#: DEFAULT_CONFIDENCE). Only shrinks.
CONFIDENCE_SITES_LEFT = {
    "workflows/imu_noise.py:analyse_imu",
    "workflows/imu_noise.py:analyse_record",
    "workflows/imu_noise.py:_axis",
}


def _confidence_literals():
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC).as_posix()
        if rel.startswith("noise/"):
            continue
        for fn in ast.walk(parsed(path)):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            defaults = dict(zip([a.arg for a in fn.args.args][::-1], fn.args.defaults[::-1]))
            defaults.update({a.arg: d for a, d in zip(fn.args.kwonlyargs, fn.args.kw_defaults)
                             if d is not None})
            numeric = [d for name, d in defaults.items() if name == "confidence"
                       and isinstance(d, ast.Constant) and isinstance(d.value, float)]
            inline = [n for n in ast.walk(fn) if isinstance(n, ast.Constant)
                      and n.value in (0.95, 0.683) and any(
                          isinstance(p, ast.keyword) and p.arg == "confidence"
                          and p.value is n for p in ast.walk(fn))]
            near = [n for n in ast.walk(fn) if isinstance(n, ast.IfExp)
                    and isinstance(n.body, ast.Constant) and n.body.value in (0.95, 0.683)]
            named = "confidence" in fn.name and any(
                isinstance(n, ast.Constant) and n.value in (0.95, 0.683) for n in ast.walk(fn))
            if numeric or inline or near or named:
                yield f"{rel}:{fn.name}"


def test_one_confidence_default_per_record_kind():
    found = set(_confidence_literals())
    new = sorted(found - CONFIDENCE_SITES_LEFT)
    assert not new, f"a confidence default spelled as a number (use inertialab.config.DEFAULT_CONFIDENCE): {new}"
    gone = sorted(CONFIDENCE_SITES_LEFT - found)
    assert not gone, f"remove from CONFIDENCE_SITES_LEFT: {gone}"


def test_one_saturation_detector():
    """Rails and the test of a sample against them live in io/gaps.py (``rails``,
    ``at_rails``, used by ``detect_saturation`` and the triaxial workflow); no other module
    defines a saturation detector."""
    defs = sorted(f"{p.relative_to(SRC).as_posix()}:{n.name}" for p in SRC.rglob("*.py")
                  for n in ast.walk(parsed(p))
                  if isinstance(n, ast.FunctionDef)
                  and any(w in n.name for w in ("saturat", "rails")))
    assert defs == ["io/gaps.py:at_rails", "io/gaps.py:detect_saturation", "io/gaps.py:rails"]


def test_one_model_load_save_pair(tmp_path):
    """inertialab.calib.load_model / save_model are the pair (the command line reaches them
    through inertialab.workflows.registries); the old io spelling warns and still works."""
    import warnings

    import numpy as np
    import pytest

    from inertialab.calib import load_model, save_model
    from inertialab.learn.poly import PolynomialRegressor

    model = PolynomialRegressor(degree=1).fit(np.c_[np.arange(5.0)], 2.0 * np.arange(5.0) + 1)
    save_model(model, tmp_path / "m.json")
    back = load_model(tmp_path / "m.json", expected_type="polynomial")
    assert np.allclose(back.predict(np.c_[[7.0]]), 15.0)
    with pytest.raises(TypeError, match="not a registered model type"):
        save_model(object(), tmp_path / "x.json")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        from inertialab.io import save_model as old
    assert old is not None and any(issubclass(w.category, DeprecationWarning) for w in caught)
    import inertialab.io

    assert "save_model" not in inertialab.io.__all__
