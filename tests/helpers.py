"""Helpers shared by the CLI tests (imported as ``tests.helpers``; pytest's ``pythonpath``
puts the project root on sys.path).

Every CLI test runs the command line in this process (:func:`run_cli`, or
:func:`run_inprocess` with pytest's ``capsys``): a fresh interpreter costs about a
second of start-up per call. Only ``tests/cli/test_smoke.py`` starts real processes
(:func:`run_subprocess`), for what only a process shows: the entry point, the start-up
time and what it imports, the exit status a shell sees.
"""

import contextlib
import io
import os
import subprocess
import sys

import pytest


def run_subprocess(*args, cwd=None, timeout=300):
    """Run ``python -m inertialab ARGS`` in a fresh process (as a user does)."""
    return subprocess.run([sys.executable, "-m", "inertialab", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd, timeout=timeout)


def run_cli(*args, cwd=None, timeout=None) -> subprocess.CompletedProcess:
    """Run ``inertialab ARGS`` in this process, from ``cwd`` when given; return what
    :func:`run_subprocess` returns (``returncode``, ``stdout``, ``stderr``), so a test
    reads the same either way. ``timeout`` is accepted for that symmetry and unused."""
    from inertialab.cli.main import main

    argv = [str(a) for a in args]
    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    code = 0
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            if cwd is not None:
                os.chdir(cwd)
            try:
                main(argv)
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    finally:
        os.chdir(here)  # a --config run changes into its saved directory
    return subprocess.CompletedProcess(["inertialab", *argv], code, out.getvalue(),
                                       err.getvalue())


def run_inprocess(capsys, *args):
    """Run the CLI in this process; return ``(exit code, stdout, stderr)``."""
    from inertialab.cli.main import main

    with pytest.raises(SystemExit) as ex:
        main([str(a) for a in args])
    out, err = capsys.readouterr()
    return ex.value.code, out, err
