"""Helpers shared by the CLI tests (imported as ``tests.helpers``; pytest's ``pythonpath``
puts the project root on sys.path)."""

import subprocess
import sys

import pytest


def run_subprocess(*args, cwd=None, timeout=300):
    """Run ``python -m inertialab ARGS`` in a fresh process (as a user does)."""
    return subprocess.run([sys.executable, "-m", "inertialab", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd, timeout=timeout)


def run_inprocess(capsys, *args):
    """Run the CLI in this process; return ``(exit code, stdout, stderr)``."""
    from inertialab.cli.main import main

    with pytest.raises(SystemExit) as ex:
        main([str(a) for a in args])
    out, err = capsys.readouterr()
    return ex.value.code, out, err
