"""The one SIGINT/SIGTERM handler of a command-line run.

While a command runs, :func:`install` makes SIGINT and SIGTERM raise :class:`Terminated`
in the main thread (a ``BaseException`` that is not ``KeyboardInterrupt``, so neither an
``except Exception`` in a command nor click's own ``KeyboardInterrupt`` handling swallows
it, and the output transaction unwinds and removes what it staged). The command line
then prints one line, ``error: interrupted by SIGTERM; nothing was written``, and exits
``128 + signal`` (130 for SIGINT, 143 for SIGTERM).

What else a signal may meet, handled here so that there is one line and no traceback:

- a signal landing in code that wraps exceptions (an import, a C callback, a
  finaliser) is remembered (:func:`received`) and Python's "Exception ignored in ..."
  report of it is silenced;
- a signal after the outputs were committed (:func:`mark_committed`) ends the process
  at once with ``error: interrupted by SIGTERM after the outputs were complete`` and
  ``128 + signal``, instead of dying silently with -15;
- worker processes (:func:`ignore_in_worker`) ignore SIGINT: the parent is
  interrupted, shuts its workers down and reports once;
- a start that must not be cut in half (a Dask cluster's) runs under :func:`deferred`,
  which holds the signal until the start is complete and then raises it.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys

__all__ = ["SIGNALS", "Terminated", "committed", "deferred", "exit_committed",
           "ignore_in_worker", "install", "interrupted_line", "mark_committed", "received",
           "restore"]

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Terminated(BaseException):
    """Raised in the main thread by the handler (see the module docstring)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


_STATE: dict = {"received": [], "committed": False, "old": {}, "hook": None}


def received() -> list[int]:
    """The signals received since :func:`install` (oldest first)."""
    return list(_STATE["received"])


def interrupted_line(signum: int, *, after_commit: bool = False) -> str:
    """The one line an interrupted run prints (with its newline)."""
    name = signal.Signals(signum).name
    if after_commit:
        return f"error: interrupted by {name} after the outputs were complete\n"
    return f"error: interrupted by {name}; nothing was written\n"


def _handler(signum, frame):  # pragma: no cover - exercised in subprocess tests
    _STATE["received"].append(signum)
    if _STATE["committed"]:
        with contextlib.suppress(Exception):
            sys.stdout.flush()
        with contextlib.suppress(Exception):
            sys.stderr.write(interrupted_line(signum, after_commit=True))
            sys.stderr.flush()
        os._exit(128 + signum)
    raise Terminated(signum)


def _unraisable(unraisable):  # pragma: no cover - exercised in subprocess tests
    """Silence "Exception ignored in ..." for the handler's own exception."""
    if _STATE["received"] or isinstance(unraisable.exc_value, (Terminated, KeyboardInterrupt)):
        return
    sys.__unraisablehook__(unraisable)


def install() -> None:
    """Install the handler for SIGINT and SIGTERM (main thread only; elsewhere a no-op)."""
    _STATE["received"].clear()
    _STATE["committed"] = False
    for signum in SIGNALS:
        with contextlib.suppress(ValueError):  # not the main thread: leave signals alone
            old = signal.signal(signum, _handler)
            _STATE["old"].setdefault(signum, old)
    if _STATE["hook"] is None:
        _STATE["hook"] = sys.unraisablehook
        sys.unraisablehook = _unraisable


def mark_committed() -> None:
    """The outputs are in place: a signal from now on exits at once with its line."""
    _STATE["committed"] = True


def committed() -> bool:
    """Whether :func:`mark_committed` was called since :func:`install`."""
    return bool(_STATE["committed"])


def exit_committed(code: int) -> None:
    """End a committed run's process without the interpreter's teardown: the exit
    functions run (under the handler: a signal gets its line and 143/130), then the
    process exits at once. Python's finalisation resets the signal handlers to the
    default first and then spends half a second and more unloading numpy, pandas and
    the rest, a window in which SIGTERM killed the finished run with no line (-15)."""
    import atexit

    run = getattr(atexit, "_run_exitfuncs", None)
    if run is not None:
        run()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code)


def restore() -> None:
    """Put back the handlers :func:`install` replaced (in-process callers, tests)."""
    for signum, old in _STATE["old"].items():
        with contextlib.suppress(ValueError, TypeError):
            signal.signal(signum, old)
    _STATE["old"].clear()
    if _STATE["hook"] is not None:
        sys.unraisablehook = _STATE["hook"]
        _STATE["hook"] = None
    _STATE["committed"] = False


@contextlib.contextmanager
def deferred():
    """Hold SIGINT/SIGTERM for the block: a start that must not be cut in half (a Dask
    cluster whose worker processes are being started) runs to its end, then the first
    signal received in it is raised as :class:`Terminated`, so the caller's cleanup
    (closing the cluster) runs on a whole object. An error of the block after a signal
    is replaced by the signal. Outside the main thread a no-op."""
    got: list[int] = []

    def hold(signum, frame):  # pragma: no cover - exercised in subprocess tests
        got.append(signum)
        _STATE["received"].append(signum)

    try:
        old = {signum: signal.signal(signum, hold) for signum in SIGNALS}
    except ValueError:  # not the main thread
        yield
        return
    try:
        yield
    finally:
        for signum, handler in old.items():
            signal.signal(signum, handler)
        if got:
            raise Terminated(got[0])


def ignore_in_worker() -> None:
    """In a worker process: ignore SIGINT, the terminal's Ctrl-C that reaches the whole
    process group (the parent run is interrupted, stops its workers and reports once)."""
    with contextlib.suppress(ValueError, OSError):
        signal.signal(signal.SIGINT, signal.SIG_IGN)
