"""Options shared by every command, declared once (DESIGN.md "Command line", issue 13).

Two forms:

- ``Annotated`` aliases for single options every command spells the same way
  (``JsonOpt``, ``QuietOpt``, ``SeedOpt``, ``OutDirOpt``, ``OutFileOpt``); a command
  writes ``as_json: JsonOpt = False``.
- :func:`reading_options`, a decorator that adds the whole set of reading options (the
  one front door of :mod:`inertialab.io.mapping`) to a command and hands the command one
  ``read: ReadOptions`` argument instead of the separate flags. A new reading option is
  added here once and every command that reads a record gets it.

Library code below ``cli/`` never names a flag; :data:`FLAG_OF` maps the argument names
used in library messages to the flags that set them, and :func:`flagged` rewrites an
error message for the command line.
"""

from __future__ import annotations

import functools
import inspect
import re
from pathlib import Path
from typing import Annotated, Any

import typer

from inertialab.io.mapping import ReadOptions

JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON object alone on stdout.")]
QuietOpt = Annotated[bool, typer.Option("--quiet", help="No progress bar or warnings on stderr.")]
SeedOpt = Annotated[int, typer.Option("--seed", help="Random seed (same seed, same numbers).")]
OutDirOpt = Annotated[Path | None, typer.Option(
    "--out", help="Output directory (figures, model.json, result.json); built aside and "
                  "moved into place only when complete.")]
OutFileOpt = Annotated[Path | None, typer.Option(
    "--out", help="Output file (a sidecar .meta.json is written beside it); replaces only "
                  "a regular file.")]


def _opt(name: str, annotation, default=None) -> inspect.Parameter:
    return inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default,
                             annotation=annotation)


#: The reading options (name -> Parameter); ReadOptions.from_cli receives them by name.
READING_PARAMS: list[inspect.Parameter] = [
    _opt("map_text", Annotated[str | None, typer.Option(
        "--map", help="Column map target=source[:unit],... (e.g. gx_dps='Gyro X');")]),
    _opt("map_file", Annotated[Path | None, typer.Option(
        "--map-file", help="Column map and parse options from a JSON/TOML file.")]),
    _opt("sep", Annotated[str | None, typer.Option(
        "--sep", help="Field separator (default: sniffed).")]),
    _opt("decimal", Annotated[str | None, typer.Option(
        "--decimal", help="Decimal mark . or , (default: sniffed).")]),
    _opt("skip_rows", Annotated[int | None, typer.Option(
        "--skip-rows", help="Preamble lines before the header (default: # lines).")]),
]


def _build_read(values: dict[str, Any]) -> ReadOptions:
    return ReadOptions.from_cli(values.pop("map_text"), values.pop("map_file"), **values)


def reading_options(fn):
    """Decorator: add the reading options to command ``fn``, which takes ``read``.

    ``fn`` must declare a parameter named ``read``; it receives the
    :class:`~inertialab.io.mapping.ReadOptions` built from the flags.
    """
    sig = inspect.signature(fn)
    if "read" not in sig.parameters:
        raise TypeError(f"{fn.__name__} needs a 'read' parameter for reading_options")
    names = [p.name for p in READING_PARAMS]

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        values = {n: kwargs.pop(n, None) for n in names}
        kwargs["read"] = _build_read(values)
        return fn(*args, **kwargs)

    params = [p for p in sig.parameters.values() if p.name != "read"]
    kw_only = [p for p in params if p.kind == inspect.Parameter.KEYWORD_ONLY]
    others = [p for p in params if p.kind != inspect.Parameter.KEYWORD_ONLY]
    wrapper.__signature__ = sig.replace(parameters=others + kw_only + READING_PARAMS)
    ann = {k: v for k, v in getattr(fn, "__annotations__", {}).items() if k != "read"}
    ann.update({p.name: p.annotation for p in READING_PARAMS})
    wrapper.__annotations__ = ann
    return wrapper


#: Library argument name -> command-line flag, for messages raised below cli/.
FLAG_OF: dict[str, str] = {
    "objective": "--objective",
    "rate_hz": "--rate",
    "column_map": "--map",
    "skip_rows": "--skip-rows",
    "unit": "--unit",
    "g_local": "--g-local",
    "method": "--method",
    "taus": "--taus",
    "reference": "--reference",
    "horizon": "--horizon",
    "seed": "--seed",
    "input": "--input",
    "stats": "--stat",
    "export": "--export",
    "gaps": "--gaps",
    "model": "--model",
    "workers": "--workers",
    "scheduler": "--scheduler",
    "nominal_hz": "--nominal",
    "fit_terms": "--terms",
    "column": "--column",
}


def flagged(message: str) -> str:
    """Rewrite ``argument 'objective'``-style mentions in a library message as flags."""
    def sub(m: re.Match) -> str:
        flag = FLAG_OF.get(m.group(1))
        return flag if flag else m.group(0)

    return re.sub(r"argument '([a-z_]+)'", sub, message)
