"""Progress sinks: what long-running workflows report to and the CLI draws as a bar.

A sink has ``update(done, total, note)``; :class:`NullProgress` ignores everything
(library use, tests). Lives at the bottom floor so that workflows and studies share it.
"""

from __future__ import annotations

from typing import Protocol


class Progress(Protocol):
    """Progress sink: ``update(done, total, note)``; the CLI maps it to a bar on stderr."""

    def update(self, done: float, total: float, note: str = "") -> None: ...


class NullProgress:
    """A progress sink that ignores everything (library use, tests)."""

    def update(self, done: float, total: float, note: str = "") -> None:
        return None
