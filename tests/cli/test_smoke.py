"""The command line as a process: the one CLI module that starts real processes (every
other CLI test runs in this process through ``tests.helpers.run_cli``). It checks what
only a process shows: the entry point and its exit status, and that ``--version`` and a
command's ``--help`` start without the heavy floors (pandas, scipy, matplotlib), so that
every command starts in well under half a second of CPU."""

import json
import subprocess
import sys

from inertialab import __version__
from tests.helpers import run_subprocess

#: Modules a start-up must not import: each costs 0.2-0.4 s of CPU.
HEAVY = ("pandas", "scipy", "matplotlib", "numba", "sklearn", "dask", "pyarrow")

#: One interpreter; each command line runs in a forked child of it, which reports the
#: heavy modules it holds after running (fork: a fresh module table per command line for
#: the price of one start-up).
_PROBE = """
import json, os, sys
for argv in json.loads(sys.argv[1]):
    pid = os.fork()
    if pid == 0:
        from inertialab.cli.main import main
        try:
            main(argv)
        except SystemExit as exc:
            code = exc.code
        sys.stdout.flush()
        print("LOADED", code, *sorted(m for m in {heavy!r} if m in sys.modules), file=sys.stderr)
        sys.stderr.flush()
        os._exit(0)
    os.waitpid(pid, 0)
"""

#: The command lines whose start-up is checked: --version, the top-level help and a
#: command of every module.
START_UPS = [
    ["--version"], ["--help"], ["allan", "--help"], ["triaxial", "fit", "--help"],
    ["thermal", "fit", "--help"], ["drift", "evaluate", "--help"], ["dual", "fit", "--help"],
    ["vibration", "apply", "--help"], ["simulate", "gyro-static", "--help"],
    ["batch", "--help"], ["demo", "--help"], ["validate", "--help"],
]


def test_version_and_exit_status_as_a_process(tmp_path):
    res = run_subprocess("--version")
    assert res.returncode == 0 and res.stdout.strip() == f"inertialab {__version__}"
    res = run_subprocess("no-such-command")
    assert res.returncode == 2 and res.stdout == ""
    assert len(res.stderr.strip().splitlines()) == 1 and "No such command" in res.stderr


def test_a_command_runs_end_to_end_as_a_process(tmp_path):
    p = tmp_path / "g.csv"
    res = run_subprocess("simulate", "gyro-static", "--hours", "0.01", "--rate", "10",
                         "--out", p)
    assert res.returncode == 0, res.stderr
    res = run_subprocess("validate", p, "--kind", "gyro_log", "--json")
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["command"] == "validate"


def test_start_up_loads_no_heavy_floor():
    """A command loads its floors when it runs, not to print its help or version."""
    res = subprocess.run([sys.executable, "-c", _PROBE.format(heavy=HEAVY),
                          json.dumps(START_UPS)], capture_output=True, text=True, timeout=300)
    lines = [x.split()[1:] for x in res.stderr.splitlines() if x.startswith("LOADED")]
    assert len(lines) == len(START_UPS), res.stderr
    for argv, (code, *loaded) in zip(START_UPS, lines, strict=True):
        assert code == "0" and loaded == [], f"inertialab {' '.join(argv)}: exit {code}, {loaded}"
