"""``--config run.toml`` / ``--save-config``: a saved run reproduces its JSON."""

import json

import pytest

from inertialab.cli.main import expand_config
from inertialab.errors import InputError
from inertialab.sim.triaxial_poses import simulate_line
from tests.helpers import run_cli as run


def _strip(obj):
    """Drop what may differ between runs: wall times and the run's timestamps."""
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items()
                if k not in ("wall_s", "created_utc", "started_utc", "finished_utc")}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


@pytest.fixture(scope="module")
def lot(tmp_path_factory):
    d = tmp_path_factory.mktemp("cfg")
    (d / "lot").mkdir()
    sim = simulate_line(3, seed=4)
    for uid, frame in sim.data.groupby("unit_id", sort=True):
        frame.to_csv(d / "lot" / f"{uid}.csv", index=False)
    return d


def test_save_config_then_rerun_reproduces_json(lot, tmp_path):
    args = ["batch", "calibrate", "triaxial", "--inputs", "lot/*.csv", "--scheduler", "serial",
            "--g-local", "9.8", "--tolerance", "abs(bx)<=0.1", "--json"]
    first = run(*args, "--save-config", tmp_path / "run.toml", cwd=lot)
    assert first.returncode == 0, first.stderr
    text = (tmp_path / "run.toml").read_text()
    assert "argv = [" in text and "--save-config" not in text
    # re-run from another directory: the saved cwd makes the relative glob resolve
    again = run("--config", tmp_path / "run.toml", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    a, b = json.loads(first.stdout), json.loads(again.stdout)
    assert a["inputs"] and a["inputs"] == b["inputs"]          # same files, same SHA-256
    assert a["dependencies"] == b["dependencies"] and a["settings"] == b["settings"]
    assert _strip(a) == _strip(b)


def test_command_form_and_override(lot, tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(f'command = ["batch", "calibrate-triaxial"]\ncwd = "{lot}"\n[options]\n'
                   'inputs = "lot/*.csv"\nscheduler = "serial"\ng_local = 9.8\njson = true\n'
                   'tolerance = ["abs(bx)<=0.1", "kx=0.9..1.1"]\n')
    res = run("--config", cfg, "--g-local", "9.81", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    obj = json.loads(res.stdout)
    # options expand to flags; a value given beside --config wins (given after it)
    assert obj["settings"]["g_local"] == 9.81
    assert obj["settings"]["tolerance"] == ["abs(bx)<=0.1", "kx=0.9..1.1"]


def test_expand_config_errors(tmp_path):
    with pytest.raises(InputError, match="no such configuration"):
        expand_config(["--config", str(tmp_path / "none.toml")])
    bad = tmp_path / "bad.toml"
    bad.write_text("argv = [")
    with pytest.raises(InputError, match="not valid TOML"):
        expand_config(["--config", str(bad)])
    empty = tmp_path / "empty.toml"
    empty.write_text("x = 1\n")
    with pytest.raises(InputError, match="'argv' or 'command'"):
        expand_config(["--config", str(empty)])
    assert expand_config(["demo", "--quick"]) == ["demo", "--quick"]
    res = run("--config")
    assert res.returncode == 2 and "needs a TOML file" in res.stderr
