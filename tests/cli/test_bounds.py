"""Bounds are declared once, on the commands' Configs (there is no table of flag bounds
in cli/): every bounded setting of every registered command refuses a value outside
its bounds with exit 2 and one line naming the flag, before any file is read."""

import ast
from pathlib import Path

import pytest

from tests.helpers import run_cli

CLI = Path(__file__).resolve().parents[2] / "src" / "inertialab" / "cli"


def _leaves():
    from inertialab.cli.main import full_command

    def walk(cmd, path):
        subs = getattr(cmd, "commands", None)
        if subs:
            for name, sub in subs.items():
                yield from walk(sub, [*path, name])
        else:
            yield path, cmd

    yield from walk(full_command(), [])


def _cases():
    for path, cmd in _leaves():
        config = getattr(cmd.callback, "__config__", None)
        if config is None:
            continue
        fixed = []
        for p in cmd.params:
            if p.param_type_name == "argument":
                fixed.append("x.csv")
            elif p.required:
                fixed += [p.opts[0], "x"]
        for f, m in config.fields():
            if not m["cli"] or (m["lo"] is None and m["hi"] is None):
                continue
            flag = "--" + m["flag"].split("/")[0]
            bad = m["hi"] * 10 + 1 if m["hi"] is not None else m["lo"] - 1
            n = 2 if "tuple" in str(f.type) else 1
            value = [str(int(bad) if float(bad).is_integer() and abs(bad) < 1e15 else bad)] * n
            yield pytest.param([*path, *fixed, flag, *value], flag, id=f"{' '.join(path)} {flag}")


CASES = list(_cases())


def test_every_bounded_setting_is_checked_here():
    assert len(CASES) > 40


@pytest.mark.parametrize("argv, flag", CASES)
def test_out_of_bounds_exits_2_naming_the_flag(argv, flag, tmp_path):
    res = run_cli(*argv, cwd=tmp_path)
    assert res.returncode == 2, (argv, res.stderr)
    assert res.stderr.count("\n") == 1 and flag in res.stderr, res.stderr
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_cli_declares_no_table_of_bounds():
    """No dict in cli/ maps flags to numbers (a second home for a Config's bounds)."""
    bad = []
    for path in CLI.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Dict):
                continue
            keys = [k.value for k in node.keys if isinstance(k, ast.Constant)]
            vals = [v for v in node.values if isinstance(v, ast.Tuple)]
            if any(isinstance(k, str) and k.startswith("--") for k in keys) and vals:
                bad.append(f"{path.name}:{node.lineno}")
    assert not bad, bad
