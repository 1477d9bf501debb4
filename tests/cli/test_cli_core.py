"""CLI conventions: --help, --version, exit codes, one-line errors, JSON alone on stdout."""

import json

import pytest

from inertialab import __version__
from tests.helpers import run_cli as run


def assert_user_error(res, pattern=None):
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1, res.stderr
    assert "Traceback" not in res.stderr
    if pattern:
        assert pattern in lines[0], lines[0]


def test_version_and_help():
    res = run("--version")
    assert res.returncode == 0 and res.stdout.strip() == f"inertialab {__version__}"
    res = run("--help")
    assert res.returncode == 0 and "demo" in res.stdout and "validate" in res.stdout


def test_the_top_level_table_names_what_the_modules_register():
    """cli/main.TOP_LEVEL (what a run imports for each name) is what a build of every
    command module registers, in --help's order."""
    from inertialab.cli.main import TOP_LEVEL, _registered, command_module, command_modules

    assert list(_registered(command_modules())) == list(TOP_LEVEL)
    for name, modules in TOP_LEVEL.items():
        assert name in _registered(command_module(m) for m in modules)


def test_unknown_command_and_option_exit_2_with_one_line():
    assert_user_error(run("no-such-command"), "No such command")
    assert_user_error(run("demo", "--no-such-option"), "No such option")


@pytest.mark.parametrize(
    "text, pattern",
    [
        (None, "no such file"),
        ("", "empty file"),
        ("t_s,temp_c\n0,1\n1,2\n", "needs at least one of the columns"),
        ("t_s,rate_dph\n0,1\n0.1,abc\n", "column 'rate_dph', row 2: non-numeric value 'abc'"),
        ("t_s,rate_dph\n0,1\n0.1,nan\n", "row 2: empty cell or NaN"),
        ("t_s,rate_dph\n0,1\n0.1,-inf\n", "row 2: infinite value"),
        ("t_s,rate_dph\n0,1\n0.2,2\n0.1,3\n", "column 't_s', row 3: time stamps decrease"),
        ("t_s,rate_dph\n0,1\n", "too few samples"),
        ("t_s,rate_xx\n0,1\n1,2\n", "unknown unit suffix 'xx'"),
    ],
)
def test_input_errors_through_the_cli(tmp_path, text, pattern):
    p = tmp_path / "log.csv"
    if text is not None:
        p.write_text(text)
    res = run("validate", p, "--kind", "gyro_log")
    assert_user_error(res, pattern)
    assert str(p) in res.stderr
    assert res.stdout == ""


def test_validate_json_is_one_object_alone_on_stdout(tmp_path):
    p = tmp_path / "log.csv"
    p.write_text("t_s,rate_dph\n0,1\n0.1,2\n0.2,3\n")
    res = run("validate", p, "--kind", "gyro_log", "--json")
    assert res.returncode == 0, res.stderr
    obj = json.loads(res.stdout)
    for key in ("command", "schema_version", "inertialab_version", "inputs", "settings",
                "units", "warnings"):
        assert key in obj
    assert obj["rows"] == 3 and obj["column_units"] == {"rate_dph": "dph"}
    import hashlib

    assert obj["inputs"][0]["sha256"] == hashlib.sha256(p.read_bytes()).hexdigest()


def test_demo_writes_the_report_and_refuses_unknown_study(tmp_path):
    res = run("demo", "--study", "nonsense", "--out", tmp_path / "r")
    assert_user_error(res, "unknown study 'nonsense'")
    assert not (tmp_path / "r").exists()
