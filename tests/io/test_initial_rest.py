"""validate = analyse for the initial rest of a raw log: ``validate FILE --kind triaxial``
and ``triaxial fit FILE`` run the same test (:func:`inertialab.io.rest.initial_rest`) and
print the same one line naming the file."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from tests.fuzz import catalogue as cat

from inertialab.errors import InputError
from inertialab.io.rest import initial_rest


def _log(moving_s: float, *, fs: float = 100.0, seconds: float = 30.0, seed: int = 0):
    """A log at rest (0.01 m/s^2 noise about g on z) with a 2 m/s^2 swing on x from
    t = 2 s lasting ``moving_s`` seconds."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(seconds * fs)) / fs
    acc = np.column_stack([np.zeros_like(t), np.zeros_like(t), np.full_like(t, 9.81)])
    acc += rng.normal(0.0, 0.01, acc.shape)
    swing = (t >= 2.0) & (t < 2.0 + moving_s)
    acc[swing, 0] += 2.0 * np.sin(2 * np.pi * 0.5 * (t[swing] - 2.0))
    return t, acc


def test_a_log_at_rest_passes_and_a_moving_start_is_refused():
    t, acc = _log(0.0)
    rest = initial_rest(t, acc, path="a.csv")
    assert rest.fs == pytest.approx(100.0) and rest.init.sum() == 1000
    # a 2 s swing moves ~30 % of the first 10 s (with the 1 s window's spread)
    t, acc = _log(2.0)
    with pytest.raises(InputError, match=r"^a\.csv: no initial rest: more than 5 % of the "
                                         r"first 10 s move"):
        initial_rest(t, acc, path="a.csv")
    # unchecked (an absolute threshold): the statistic without the verdict
    assert initial_rest(t, acc, check=False).s.shape == (t.size,)
    # a shorter initial window that ends before the swing (and its 1 s window) passes
    initial_rest(t, acc, t_init_s=1.4)


def test_the_detector_runs_the_same_test():
    from inertialab.noise.segments.static_intervals import detect_static_intervals

    t, acc = _log(2.0)
    with pytest.raises(InputError) as det:
        detect_static_intervals(t, acc)
    with pytest.raises(InputError) as pre:
        initial_rest(t, acc)
    assert str(det.value) == str(pre.value)
    detect_static_intervals(t, acc, threshold=1e-2)  # an absolute threshold needs no rest


@pytest.fixture(scope="module")
def raw_logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("rest")
    o = cat.run_inprocess(["simulate", "triaxial-poses", "--scenario", "rawlog62", "--out",
                           str(d / "raw.csv")], d)
    assert o.code == 0, o.stderr
    df = pd.read_csv(d / "raw.csv")
    cut = df[df.t_s >= 12.0].copy()  # 3 s of the first pose's dwell, then the first turn
    cut["t_s"] -= 12.0
    cut.to_csv(d / "moving.csv", index=False)
    return d


def test_validate_and_triaxial_fit_give_the_same_line(raw_logs):
    d = raw_logs
    ok = cat.run_inprocess(["validate", str(d / "raw.csv"), "--kind", "triaxial"], d)
    assert ok.code == 0, ok.stderr
    lines = []
    for argv in (["validate", str(d / "moving.csv"), "--kind", "triaxial"],
                 ["triaxial", "fit", str(d / "moving.csv"), "--quiet"]):
        o = cat.run_inprocess(argv, d)
        assert o.code == 2, o.stderr
        lines.append([ln for ln in o.stderr.splitlines() if ln.startswith("error:")])
    assert lines[0] == lines[1] and len(lines[0]) == 1
    assert lines[0][0].startswith(f"error: {d / 'moving.csv'}: no initial rest")
    # the record kind alone (read by triaxial apply too) does not ask for a rest
    assert cat.run_inprocess(["validate", str(d / "moving.csv"), "--kind", "triaxial_raw"],
                             d).code == 0
