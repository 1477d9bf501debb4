"""The process entry point of the command line (``inertialab`` and ``python -m inertialab``).

The one SIGINT/SIGTERM handler (:mod:`inertialab.signals`) is installed here before
anything heavy is imported: the command line's imports (numpy, pandas, typer, numba's
compiled kernels) take a second or more, and a signal landing in them used to meet
Python's default handling (a ``KeyboardInterrupt`` traceback for SIGINT, a silent
death for SIGTERM). Now such a signal gives the same one line and exit status as one
during the run: ``error: interrupted by SIGTERM; nothing was written``, 143 (130 for
SIGINT). Only the interpreter's own start-up (``site``, tens of milliseconds) comes
before the handler.
"""

from __future__ import annotations

import sys

from inertialab import signals


def _interrupted(signum: int) -> None:
    sys.stderr.write(signals.interrupted_line(signum))
    raise SystemExit(128 + signum)


def main() -> None:
    """Install the signal handler, then import and run :func:`inertialab.cli.main.main`."""
    signals.install()
    try:
        from inertialab.cli.main import main as run

        run()
    except SystemExit as exc:
        if exc.code == 0 and signals.committed():  # a late signal: its line, not -15
            signals.exit_committed(0)
        raise
    except (signals.Terminated, KeyboardInterrupt) as exc:  # a signal before the run's own
        _interrupted(getattr(exc, "signum", 2))
    except Exception:  # an import that wrapped the signal's exception in its own
        if not signals.received():
            raise
        _interrupted(signals.received()[-1])


if __name__ == "__main__":
    main()
