"""``allan --imu --plan``: the record length for K and for B under the fitted model, a K
held by a Gauss-Markov correlation time (plan, JSON, exports), on a virtual-lab preset
and on a simulated record whose truth is known."""

import json
import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from scipy.signal import lfilter

from inertialab.noise.gmwm.fit import Process
from inertialab.noise.terms.information import processes_bounds
from inertialab.sim.mems_presets import preset
from inertialab.workflows.imu_drift import PLAN_REL, PLAN_Z, DriftOptions, axis_plan
from inertialab.workflows.imu_noise import analyse_imu
from tests.helpers import run_inprocess as run

TARGET = math.log(1 + PLAN_REL) / PLAN_Z
FS, N = 10.0, 100_000           # 2.78 h at 10 Hz
K_TRUE, T_TRUE = 4e-4, 400.0    # m/s^3/sqrt(Hz), s: the bias random walk and its hold


def _preset_axis(name, hours):
    """An axis whose fitted model is the preset's truth, as a GMWM fit holds it."""
    p = preset(name)
    fs = p.rate_hz
    procs = [Process("WN", {"sigma2": p.n_white**2 * fs + p.lsb**2 / 12}),
             Process("RW", {"gamma2": p.k_rw**2 / fs})]
    procs += [Process("GM", {"s2": s * s, "tc_s": tc}) for s, tc in p.gm]
    terms = SimpleNamespace(gmwm={"processes": [q.to_dict() for q in procs]},
                            tau_range_s=(1 / fs, hours * 3600 / 8))
    return SimpleNamespace(terms=terms), procs, fs


def test_plan_on_a_preset_reaches_the_target_at_the_length_it_gives():
    axis, procs, fs = _preset_axis("consumer-100hz", 10.0)
    n = int(10 * 3600 * fs)
    plan = axis_plan(axis, fs, n)
    assert plan["k_process"] == "random walk" and plan["b_process"] == "Gauss-Markov processes"
    rng = axis.terms.tau_range_s
    for term, key in (("K", "needed_h"), ("B", "b_needed_h")):
        m = int(plan[key] * 3600 * fs)
        at = processes_bounds(procs, 1 / fs, m, tau_range_s=rng)[term].free
        assert at == pytest.approx(TARGET, rel=0.03)   # the bound meets +-20 % at 95 % there
        now = processes_bounds(procs, 1 / fs, n, tau_range_s=rng)[term].free
        assert plan[key.replace("needed_h", "long_enough")] == (now <= TARGET)
    # B's three Gauss-Markov processes (4-400 s) are all seen in 10 h: its bound falls like
    # n^-1/2, so the length needed is the record's times (sd now / target)^2
    b_now = plan["b_rel_95_now"] / PLAN_Z
    assert plan["b_needed_h"] == pytest.approx(10.0 * (b_now / TARGET) ** 2, rel=0.05)


def _gm(rng, s2, tc):
    phi = math.exp(-1 / (tc * FS))
    x0 = rng.standard_normal() * math.sqrt(s2)
    e = rng.standard_normal(N) * math.sqrt(s2 * (1 - phi * phi))
    return lfilter([1.0], [1.0, -phi], e, zi=[phi * x0])[0]


@pytest.fixture(scope="module")
def held_k():
    """Two accelerometer axes: white noise, a flicker-like sum of six Gauss-Markov
    processes (0.5-20 s) and a random walk K held by T = 400 s (K^2 = 2 s2 / T)."""
    rng = np.random.default_rng(7)
    cols = {}
    for ax in ("ax", "ay"):
        y = 3e-3 * math.sqrt(FS) * rng.standard_normal(N) + _gm(rng, K_TRUE**2 * T_TRUE / 2,
                                                                 T_TRUE)
        for tc in np.geomspace(0.5, 20, 6):
            y += _gm(rng, (2e-4) ** 2, tc)
        cols[ax] = (f"{ax}_mps2", y, "mps2")
    return cols


def test_a_held_random_walk_is_planned_and_exported_with_its_time(held_k, tmp_path):
    import inertialab.export as ex

    res = analyse_imu(held_k, rate_hz=FS, drift=DriftOptions(horizons_s=(1.0,), plan=True))
    for a in res.axes:
        # the fit holds K by a correlation time (measured 291 s against 400 s), K within 25 %
        t = a.terms.k_gm["t_s"]
        assert 150 < t < 800 and a.random_walk_t_s == t
        assert a.random_walk == pytest.approx(K_TRUE, rel=0.25)
        p = a.plan
        assert p["k_process"] == "Gauss-Markov random walk" and p["k_t_s"] == t
        assert p["needed_h"] > 0 and p["b_needed_h"] > 0 and "reason" not in p
        assert p["long_enough"] == (p["k_rel_95_now"] <= PLAN_Z * TARGET)
        assert p["b_long_enough"] == (p["b_rel_95_now"] <= PLAN_Z * TARGET)
        assert a.to_dict()["random_walk"]["correlation_time_s"] == t
    path = tmp_path / "k.yaml"
    ex.export_noise(res, "kalibr", path)
    text = path.read_text()
    assert "accelerometer bias random walk is held by a first-order Gauss-Markov" in text
    assert f"ax T = {res.axes[0].random_walk_t_s:.4g} s" in text
    assert "gyroscope bias random walk is held" not in text


def test_cli_plan_table_and_json_carry_b_and_the_k_time(held_k, tmp_path, capsys,
                                                        monkeypatch):
    monkeypatch.setenv("COLUMNS", "250")  # the table on one line per row
    f = tmp_path / "acc.csv"
    data = {"t_s": np.arange(N) / FS} | {c: y for c, y, _ in held_k.values()}
    pd.DataFrame(data).to_csv(f, index=False, float_format="%.9g")
    y = tmp_path / "k.yaml"
    code, out, err = run(capsys, "allan", f, "--imu", "--plan", "--json", "--out",
                         tmp_path / "o", "--export", "kalibr", y)
    assert code == 0, err
    axes = json.loads(out)["imu"]["axes"]
    for a in axes:
        p = a["plan"]
        assert {"needed_h", "long_enough", "b_needed_h", "b_long_enough",
                "b_rel_95_now"} <= set(p)
        assert p["k_t_s"] == a["random_walk"]["correlation_time_s"] > 0
    assert "Gauss-Markov" in y.read_text()
    code, out, err = run(capsys, "allan", f, "--imu", "--plan", "--out", tmp_path / "o2")
    assert code == 0, err
    assert "B needs (h)" in out and "K: Gauss-Markov random walk, T =" in out
    row = [line for line in out.splitlines() if line.strip("│ ").startswith("ax ")][-1]
    p = axes[0]["plan"]
    assert f"{p['b_needed_h']:.3g}" in row and f"{p['needed_h']:.3g}" in row
