"""Every registered command returns a :class:`inertialab.result.Result` to the runner:
each command runs once here, in this process, on small virtual-lab records, and the test
records what reached :func:`inertialab.result.check_result` (the runner refuses anything
else with a TypeError). The run of every command is ``slow`` (CI's second step); every
other CLI test passes through the same check. ``allan``'s three modes (one series, six
axes, several logs pooled), all reported as "allan", each reach the runner as one Result
naming their inputs (a fast case per mode)."""

import json

import numpy as np
import pandas as pd
import pytest

from inertialab.result import Result, ResultBase, check_result
from tests.helpers import run_cli

#: One small successful run per registered command (``{d}``: the shared directory).
SETUP = [
    ["simulate", "gyro-static", "--preset", "allan-test", "--hours", "0.05", "--rate", "10",
     "--seed", "1", "--out", "{d}/gyro.csv"],
    ["simulate", "thermal-tumble", "--out", "{d}/thermal.csv"],
    ["simulate", "triaxial-poses", "--scenario", "sphere100-clean", "--out", "{d}/tri.csv"],
    ["simulate", "dual-tumble", "--scenario", "S1", "--out", "{d}/dual.csv"],
    ["simulate", "storage-drift", "--units", "2", "--days", "60", "--out", "{d}/drift.csv"],
    ["simulate", "fog-vibration", "--experiment", "sweep", "--p1-s", "40", "--p3-s", "40",
     "--sweep-oct-per-min", "60", "--out", "{d}/vs.csv"],
    ["simulate", "fog-vibration", "--experiment", "fixed", "--p1-s", "40", "--p3-s", "40",
     "--p2-s", "40", "--out", "{d}/vf.csv"],
    ["simulate", "ferraris-session", "--out", "{d}/fer.raw.csv"],
]
CASES = {
    "validate": ["validate", "{d}/gyro.csv", "--kind", "gyro_log"],
    "allan": ["allan", "{d}/gyro.csv"],
    "batch": ["batch", "allan", "--inputs", "{d}/gyro.csv", "--scheduler", "serial"],
    "thermal fit": ["thermal", "fit", "{d}/thermal.csv", "--method", "fis", "--out",
                    "{d}/thermal_fit"],
    "thermal apply": ["thermal", "apply", "{d}/thermal_fit/model.json", "{d}/thermal.csv",
                      "--out", "{d}/thermal_comp.csv"],
    "thermal export": ["thermal", "export", "{d}/thermal_fit/model.json", "--c", "{d}/c"],
    "triaxial fit": ["triaxial", "fit", "{d}/tri.csv", "--method", "lm", "--out",
                     "{d}/tri_fit"],
    "triaxial apply": ["triaxial", "apply", "{d}/tri_fit/model.json", "{d}/tri.csv", "--out",
                       "{d}/tri_cal.csv"],
    "triaxial export": ["triaxial", "export", "{d}/tri_fit/model.json", "--to", "kalibr",
                        "--out", "{d}/tri.yaml"],
    "triaxial ferraris": ["triaxial", "ferraris", "{d}/fer.raw.csv"],
    "dual fit": ["dual", "fit", "{d}/dual.csv", "--method", "ls"],
    "dual design": ["dual", "design", "--positions", "12"],
    "drift fit": ["drift", "fit", "{d}/drift.csv", "--quantity", "bias", "--order", "1",
                  "--restarts", "1", "--horizon", "5", "--out", "{d}/drift_fit"],
    "drift evaluate": ["drift", "evaluate", "{d}/drift.csv", "--quantity", "bias", "--order",
                       "1", "--restarts", "1", "--horizon", "5", "--first", "40", "--step",
                       "10"],
    "drift forecast": ["drift", "forecast", "{d}/drift_fit/model.json"],
    "drift apply": ["drift", "apply", "{d}/drift_fit/model.json", "{d}/drift.csv", "--out",
                    "{d}/drift_comp.csv"],
    "vibration fit": ["vibration", "fit", "{d}/vs.csv", "--out", "{d}/vib_fit"],
    "vibration apply": ["vibration", "apply", "{d}/vib_fit/model.json", "{d}/vf.csv",
                        "--out", "{d}/vib_comp.csv"],
}


def _commands() -> set[str]:
    from inertialab.cli.main import full_command

    names = set()
    for name, cmd in full_command().commands.items():
        subs = getattr(cmd, "commands", None)
        names |= {f"{name} {s}" for s in subs} if subs else {name}
    return names


@pytest.fixture(scope="module")
def seen(tmp_path_factory, monkeypatch_module):
    """command -> the type that reached check_result, over one run of every command."""
    from inertialab.cli import runner

    d = tmp_path_factory.mktemp("conformance")
    got = {}

    def recording(result, command):
        got[command] = result
        return check_result(result, command)

    monkeypatch_module.setattr(runner, "check_result", recording)
    for argv in SETUP + list(CASES.values()):
        res = run_cli(*[a.format(d=d) for a in argv])
        assert res.returncode == 0, f"{argv}: {res.stderr}"
    return got


@pytest.fixture(scope="module")
def monkeypatch_module():
    mp = pytest.MonkeyPatch()
    yield mp
    mp.undo()


def test_every_registered_command_is_run_here():
    expected = {" ".join(a[:2]) if a[0] in ("simulate",) else k for k, a in CASES.items()}
    missing = sorted(c for c in _commands()
                     if c not in expected and not c.startswith("simulate ") and c != "demo")
    assert not missing, f"commands without a conformance case: {missing}"


@pytest.mark.slow  # one run of every command: about 40 s on a loaded 2-core machine
def test_every_command_returns_a_result(seen):
    labels = {"vibration fit": "vibration"}  # the envelope's command name
    for command in CASES:
        label = labels.get(command, command)
        assert label in seen, f"{command}: nothing reached the runner"
        result = seen[label]
        assert isinstance(result, Result) and isinstance(result, ResultBase), command
        json.dumps(result.inputs, default=str)
        takes_input = command != "dual design"
        assert bool(result.inputs) == takes_input, f"{command}: inputs {result.inputs}"
    kinds = [c for c in _commands() if c.startswith("simulate ")]
    assert {f"simulate {k.split()[1]}" for k in kinds} >= {"simulate gyro-static"}
    assert any(k.startswith("simulate") for k in seen)


def test_a_result_that_is_not_one_is_refused():
    from inertialab.cli.runner import Run

    with pytest.raises(TypeError, match="allan returned a dict, not a Result"):
        Run(quiet=True).execute("allan", lambda bar: {"adev": 1.0})


def _imu_log(path, seed, axes="xyz", n=6000, accel=True):
    """A static IMU log at 100 Hz on ``axes`` (gyro, and accelerometer with ``accel``):
    white rate noise 1e-3 rad/s and 2e-3 m/s^2 per sample, gravity on z."""
    rng = np.random.default_rng(seed)
    cols = {"t_s": np.arange(n) / 100.0}
    for ax in axes:
        cols[f"g{ax}_rps"] = 1e-3 * rng.standard_normal(n)
    for ax in axes if accel else ():
        cols[f"a{ax}_mps2"] = 2e-3 * rng.standard_normal(n) + (9.80665 if ax == "z" else 0.0)
    pd.DataFrame(cols).to_csv(path, index=False)
    return str(path)


@pytest.fixture(scope="module")
def imu_logs(tmp_path_factory):
    """One six-axis log, and two logs of the x gyro alone to pool (a pooled axis's
    leave-one-log-out model choice fits each candidate per log: one axis keeps the case
    near a second)."""
    d = tmp_path_factory.mktemp("allan_modes")
    return {1: [_imu_log(d / "imu.csv", seed=0)],
            2: [_imu_log(d / f"x{i}.csv", seed=i + 1, axes="x", accel=False)
               for i in range(2)]}


#: ``allan``'s modes, all reported under the command name "allan": the arguments after
#: the log(s), how many logs, the result's type and the axes of its six-axis JSON
ALLAN_MODES = {
    "series": (["--column", "gx_rps"], 1, "AllanRun", None),
    "six-axis": (["--imu"], 1, "SixAxisRun", ["gx", "gy", "gz", "ax", "ay", "az"]),
    "pooled": (["--imu", "--pool"], 2, "PoolResult", ["gx"]),
}


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize("mode", list(ALLAN_MODES))
def test_every_allan_mode_returns_a_result(mode, imu_logs, monkeypatch):
    from inertialab.cli import runner

    args, n_logs, type_name, axes = ALLAN_MODES[mode]
    got = []

    def recording(result, command):
        got.append((command, result))
        return check_result(result, command)

    monkeypatch.setattr(runner, "check_result", recording)
    logs = imu_logs[n_logs]
    res = run_cli("allan", *logs, *args, "--json")
    assert res.returncode == 0, res.stderr
    assert [c for c, _ in got] == ["allan"]
    result = got[0][1]
    assert isinstance(result, Result) and isinstance(result, ResultBase)
    assert type(result).__name__ == type_name
    env = json.loads(res.stdout)
    assert env["command"] == "allan"
    assert [i["path"] for i in env["inputs"]] == logs
    assert env["settings"] == json.loads(json.dumps(result.settings, default=str))
    if axes is not None:
        assert bool(env["imu"].get("pooled")) == (mode == "pooled")
        assert [a["axis"] for a in env["imu"]["axes"]] == axes
    if mode == "pooled":
        assert [lg["file"] for lg in env["imu"]["logs"]] == logs
