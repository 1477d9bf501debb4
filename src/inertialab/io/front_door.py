"""Which files the reading front door opened in this process, for error messages.

:func:`inertialab.io.readers.read_record` notes every record file it opens here
(:func:`note`); the command line asks :func:`since` which files a run read, so that an
error raised after reading (a workflow finding too few samples, an implausible fit)
names the record it came from. A light module (no numpy, no pandas): the command line
imports it before any command runs.
"""

from __future__ import annotations

__all__ = ["mark", "note", "since"]

_OPENED: list[str] = []


def note(path) -> None:
    """Record that the front door opened ``path``."""
    _OPENED.append(str(path))


def mark() -> int:
    """A position to pass to :func:`since` (the number of files opened so far)."""
    return len(_OPENED)


def since(position: int = 0) -> list[str]:
    """The distinct files opened after ``position``, in the order first opened."""
    return list(dict.fromkeys(_OPENED[position:]))
