"""Shared CLI plumbing: the JSON envelope, error handling, progress bars, output files.

The command line's output rules (docs/cli.md): ``--json`` prints one object alone on stdout with
``command``, ``schema_version``, ``inertialab_version``, ``inputs`` (path and sha256),
``settings``, ``units``, ``warnings`` and then the command's own keys; NaN/inf become
``null`` with a ``non_estimable`` flag listing their keys. User errors exit 2 with one
line on stderr; warnings go to stderr and never change the exit code.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import shutil
import sys
import warnings
from pathlib import Path

from inertialab import __version__
from inertialab.cli.options import flagged
from inertialab.io import outputs
from inertialab.io.names import safe_slug
from inertialab.io.writers import atomic_write_bytes, atomic_write_text

JSON_SCHEMA_VERSION = 1

__all__ = [
    "JSON_SCHEMA_VERSION",
    "atomic_write_bytes",
    "atomic_write_text",
    "collect_warnings",
    "emit_json",
    "envelope",
    "file_sha256",
    "json_ready",
    "prepare_out_dir",
    "print_table",
    "progress_bar",
    "write_figures",
]


def file_sha256(path) -> str:
    """SHA-256 of a file's bytes (streamed)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def json_ready(obj, path: str = "", nulls: list[str] | None = None):
    """Plain-JSON copy of ``obj`` (see :func:`inertialab.jsonable.to_jsonable`); the key
    paths of non-finite floats are appended to ``nulls``."""
    from inertialab.jsonable import to_jsonable  # numpy: loaded when a result is written

    return to_jsonable(obj, nulls=nulls, path=path)


def envelope(command: str, payload: dict, *, inputs=(), settings: dict | None = None,
             units: dict | None = None, warnings_: list[str] | None = None,
             meta: dict | None = None) -> dict:
    """The one JSON object of a command: ``command``, ``schema_version``,
    ``inertialab_version``, ``dependencies``, ``inputs`` (paths are hashed here;
    ``{"path", "sha256"}`` dicts pass through), ``settings``, ``units``, ``warnings``,
    ``meta`` (when given: ``timestamps``), then the payload's keys, and
    ``non_estimable`` listing the keys whose non-finite numbers became null."""
    from inertialab.io import modelfile  # pydantic: loaded when a result is written

    ins = []
    for item in inputs:
        if isinstance(item, dict):
            ins.append(item)
        else:
            p = Path(item)
            ins.append({"path": str(p), "sha256": file_sha256(p) if p.is_file() else None})
    nulls: list[str] = []
    body = json_ready(payload, "", nulls)
    obj = {
        "command": command,
        "schema_version": JSON_SCHEMA_VERSION,
        "inertialab_version": __version__,
        "dependencies": modelfile.dependency_versions(),
        "inputs": ins,
        "settings": json_ready(settings or {}),
        "units": dict(units or {}),
        "warnings": list(warnings_ or []),
    }
    if meta is not None:
        obj["meta"] = json_ready(meta)
    obj.update(body)
    if nulls:
        obj["non_estimable"] = nulls
    return obj


def emit_json(command: str, payload: dict, *, inputs=(), settings: dict | None = None,
              units: dict | None = None, warnings_: list[str] | None = None,
              stream=None) -> dict:
    """Print the :func:`envelope` of a command on stdout (and return it)."""
    obj = envelope(command, payload, inputs=inputs, settings=settings, units=units,
                   warnings_=warnings_)
    text = json.dumps(obj, indent=2, allow_nan=False)
    (stream or sys.stdout).write(text + "\n")
    return obj


@contextlib.contextmanager
def collect_warnings(quiet: bool = False):
    """Capture Python warnings raised inside; print each once to stderr (unless quiet)
    and yield the list of their one-line messages (for the JSON ``warnings`` key).

    When the block raises, nothing is printed: a failing command writes exactly one
    line, its error."""
    messages: list[str] = []
    failed = False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            yield messages
        except BaseException:
            # the command fails: its one error line is all the user gets
            failed = True
            raise
        finally:
            seen = set()
            for w in caught:
                if issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning)):
                    continue
                text = f"{w.category.__name__}: {flagged(' '.join(str(w.message).split()))}"
                if text in seen:
                    continue
                seen.add(text)
                messages.append(text)
                if not quiet and not failed:
                    sys.stderr.write(f"warning: {text}\n")


class _Bar:
    """A rich progress bar on stderr implementing the workflows' Progress protocol."""

    def __init__(self, label: str, enabled: bool):
        self.enabled = enabled
        self.label = label
        self._progress = None
        self._task = None

    def __enter__(self):
        if self.enabled:
            from rich.console import Console
            from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

            self._progress = Progress(TextColumn("{task.description}"), BarColumn(),
                                      TextColumn("{task.fields[note]}"), TimeElapsedColumn(),
                                      console=Console(stderr=True), transient=False)
            self._progress.__enter__()
            self._task = self._progress.add_task(self.label, total=1.0, note="")
        return self

    def update(self, done: float, total: float, note: str = "") -> None:
        if self._progress is not None:
            frac = 0.0 if total <= 0 else min(1.0, max(0.0, done / total))
            self._progress.update(self._task, completed=frac, note=note)

    def __exit__(self, *exc):
        if self._progress is not None:
            self._progress.update(self._task, completed=1.0)
            self._progress.__exit__(*exc)
        return False


def progress_bar(label: str, *, quiet: bool = False) -> _Bar:
    """A progress sink for a workflow: a bar on stderr when stderr is a terminal and not
    ``--quiet``; silent otherwise. Use as a context manager."""
    enabled = (not quiet) and sys.stderr.isatty()
    return _Bar(label, enabled)


def prepare_out_dir(path) -> Path:
    """Register the ``--out`` directory of a command; nothing is created here.

    Under the command line (:func:`inertialab.cli.main.main` runs every command in an
    output transaction) the directory is built in a temporary sibling on the first write
    and moved into place when the command succeeds; a directory inertialab wrote before
    is replaced whole, one it did not write only receives the new files. A path that
    exists and is not a directory is refused. The returned path prints as ``path``.
    """
    try:
        return outputs.stage_dir(path)
    except outputs.OutputError as exc:
        raise outputs.OutputError(f"--out must be a directory for this command "
                                  f"({_after_path(exc, path)})", path=path) from None


def _after_path(exc: Exception, path) -> str:
    text = str(exc)
    prefix = f"{os.path.abspath(path)}: "
    return text[len(prefix):] if text.startswith(prefix) else text


def write_figures(figures, out_dir, *, dpi: int = 110) -> list[Path]:
    """Write ``report.section.Figure`` objects (or (name, matplotlib figure) pairs) as PNG
    files into ``out_dir``; return the paths. Names become file names only through
    :func:`~inertialab.io.names.safe_slug` (a figure named from data cannot leave
    ``out_dir``). Each figure is laid out once and drawn once
    (:func:`inertialab.report.html.figure_png`)."""
    from inertialab.report.html import figure_png

    paths = []
    taken: set[str] = set()
    out = Path(out_dir)
    for i, f in enumerate(figures):
        fig = getattr(f, "figure", None) or (f[1] if isinstance(f, tuple) else f)
        name = getattr(f, "name", None) or (f[0] if isinstance(f, tuple) else f"figure{i + 1}")
        data = figure_png(fig, dpi=dpi)
        target = out / f"{safe_slug(name, taken=taken)}.png"
        atomic_write_bytes(target, data)
        paths.append(target)
    return paths


def print_table(columns: list[str], rows: list[list], *, title: str | None = None,
                stream=None) -> None:
    """Print a plain table (numbers with 4 significant digits) to stdout."""
    from rich.console import Console
    from rich.table import Table

    t = Table(title=title)
    for c in columns:
        t.add_column(str(c))
    for r in rows:
        t.add_row(*[_fmt(v) for v in r])
    width = shutil.get_terminal_size((120, 20)).columns
    Console(file=stream or sys.stdout, width=max(width, 100)).print(t)


def _fmt(v) -> str:
    if v is None:
        return "-"
    import numpy as np  # loaded by then: a result is being printed

    if isinstance(v, (float, np.floating)):
        return "nan" if not math.isfinite(v) else f"{v:.4g}"
    return str(v)
