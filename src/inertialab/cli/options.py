"""Options shared by every command, declared once (docs/cli.md).

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
from typing import TYPE_CHECKING, Annotated, Any

import typer

from inertialab.io.formats.registry import formats_with_option

if TYPE_CHECKING:
    from inertialab.io.mapping import ReadOptions

JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON object alone on stdout.")]
QuietOpt = Annotated[bool, typer.Option("--quiet", help="No progress bar or warnings on stderr.")]
SeedOpt = Annotated[int, typer.Option("--seed", help="Random seed (same seed, same numbers).")]
OutDirOpt = Annotated[Path | None, typer.Option(
    "--out", help="Output directory (figures, model.json, result.json); built aside and "
                  "moved into place only when complete. A directory inertialab wrote before "
                  "is replaced whole; a file, device or FIFO there is refused.")]
OutFileOpt = Annotated[Path | None, typer.Option(
    "--out", help="Output file (a sidecar .meta.json is written beside it); overwrites only "
                  "a regular file (a directory, device or FIFO there is refused).")]


def _for(option: str) -> str:
    """Help suffix naming the file formats a reading option applies to (the registry of
    :mod:`inertialab.io.formats.registry`)."""
    return f" [{', '.join(formats_with_option(option))}]"


def _opt(name: str, annotation, default=None) -> inspect.Parameter:
    return inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default,
                             annotation=annotation)


#: The reading options (name -> Parameter); ReadOptions.from_cli receives them by name.
READING_PARAMS: list[inspect.Parameter] = [
    _opt("map_text", Annotated[str | None, typer.Option(
        "--map", help="Column map target=source[:unit],... (e.g. gx_rps='Gyro X:dps'; "
                      "colN = N-th column of a headerless file).")]),
    _opt("map_file", Annotated[Path | None, typer.Option(
        "--map-file", help="Column map and parse options from a JSON/TOML file.")]),
    _opt("sep", Annotated[str | None, typer.Option(
        "--sep", help="Field separator , ; tab or ' ' for blanks (default: sniffed)."
                      + _for("parse"))]),
    _opt("decimal", Annotated[str | None, typer.Option(
        "--decimal", help="Decimal mark . or , (default: sniffed).")]),
    _opt("skip_rows", Annotated[int | None, typer.Option(
        "--skip-rows", help="Preamble lines before the header (default: sniffed).")]),
    _opt("time_col", Annotated[str | None, typer.Option(
        "--time-col", help="Column holding the time stamps (becomes t_s).")]),
    _opt("time_unit", Annotated[str | None, typer.Option(
        "--time-unit", help="Unit of the time stamps: s, ms, us or ns (default s).")]),
    _opt("rate", Annotated[float | None, typer.Option(
        "--rate", help="Sample rate in Hz when the file has no time column.")]),
    _opt("unit", Annotated[str | None, typer.Option(
        "--unit", help="Unit of columns without one: a suffix (dps), one per dimension "
                       "(g,dps) or per column (gx=dps,ax=g).")]),
    _opt("topic", Annotated[str | None, typer.Option(
        "--topic", help="ROS bag topic or PX4 ULog message (sensor_combined, sensor_gyro, "
                        "sensor_accel); default: the only IMU topic." + _for("topic"))]),
    _opt("instance", Annotated[int | None, typer.Option(
        "--instance", help="ULog multi-instance (sensor_gyro 0, 1, 2 ...); default 0."
                           + _for("instance"))]),
    _opt("dataset", Annotated[str | None, typer.Option(
        "--dataset", help="MATLAB variable or HDF5 dataset path (imu/gyro)."
                          + _for("dataset"))]),
    _opt("join", Annotated[list[Path] | None, typer.Option(
        "--join", help="Further time x y z file joined on time (imu_tk: gyro beside "
                       "accelerometer); repeatable.")]),
    _opt("resample", Annotated[float | None, typer.Option(
        "--resample", help="Resample onto a uniform grid at this rate, Hz (linear; only "
                           "when given).")]),
]


def _build_read(values: dict[str, Any]) -> ReadOptions:
    from inertialab.io.mapping import ReadOptions  # pandas: loaded when a command runs

    return ReadOptions.from_cli(values.pop("map_text"), values.pop("map_file"), **values)


def _flags_of(param: inspect.Parameter) -> set[str]:
    """The option flags a command parameter declares (default or Annotated form)."""
    infos = [param.default]
    ann = param.annotation
    if getattr(ann, "__metadata__", None):
        infos.extend(ann.__metadata__)
    flags = set()
    for info in infos:
        if not hasattr(info, "param_decls"):
            continue
        decls = list(info.param_decls or ())
        if isinstance(info.default, str):  # Annotated form: the first flag sits in default
            decls.append(info.default)
        flags.update(d for d in decls if isinstance(d, str) and d.startswith("--"))
    return flags


def _main_flag(param: inspect.Parameter) -> str:
    return sorted(_flags_of(param))[0]


def reading_options(fn):
    """Decorator: add the reading options to command ``fn``, which takes ``read``.

    ``fn`` must declare a parameter named ``read``; it receives the
    :class:`~inertialab.io.mapping.ReadOptions` built from the flags. Where ``fn``
    already declares one of the reading flags itself (``--rate``, ``--unit`` in commands
    that had them before the front door), its own option stays (help text and name) and
    the value is handed to ``fn`` and copied into ``read``.
    """
    try:  # evaluated annotations (commands use `from __future__ import annotations`)
        sig = inspect.signature(fn, eval_str=True)
    except NameError:
        sig = inspect.signature(fn)
    if "read" not in sig.parameters:
        raise TypeError(f"{fn.__name__} needs a 'read' parameter for reading_options")
    own = {}
    for p in sig.parameters.values():
        for flag in _flags_of(p):
            own[flag] = p.name
    added = [p for p in READING_PARAMS if _main_flag(p) not in own]
    shared = {p.name: own[_main_flag(p)] for p in READING_PARAMS if _main_flag(p) in own}
    names = [p.name for p in added]

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        values = {n: kwargs.pop(n, None) for n in names}
        for rname, fname in shared.items():
            values[rname] = kwargs.get(fname)
        kwargs["read"] = _build_read(values)
        return fn(*args, **kwargs)

    params = [p for p in sig.parameters.values() if p.name != "read"]
    kw_only = [p for p in params if p.kind == inspect.Parameter.KEYWORD_ONLY]
    others = [p for p in params if p.kind != inspect.Parameter.KEYWORD_ONLY]
    wrapper.__signature__ = sig.replace(parameters=others + kw_only + added)
    ann = {p.name: p.annotation for p in params}
    ann.update({p.name: p.annotation for p in added})
    wrapper.__annotations__ = ann
    return wrapper


#: Library argument name -> command-line flag, for messages raised below cli/: the names
#: that differ from a command's settings; every setting of a workflow ``Config`` adds its
#: own name when its command is registered (:func:`inertialab.cli.runner.config_command`).
FLAG_OF: dict[str, str] = {
    "rate_hz": "--rate", "column_map": "--map", "skip_rows": "--skip-rows",
    "time_column": "--time-col", "time_unit": "--time-unit", "topic": "--topic",
    "instance": "--instance", "dataset": "--dataset", "resample_hz": "--resample",
    "stats": "--stat", "export": "--export", "to": "--to", "rostopic": "--rostopic",
    "imu_topic": "--rostopic", "nominal_hz": "--nominal", "fit_terms": "--terms",
    "t_init_s": "--t-init", "min_duration_s": "--min-duration", "window_s": "--window",
    "n_positions": "--positions", "inputs": "--inputs",
    "force": "--force",
}


def flagged(message: str) -> str:
    """Rewrite ``argument 'objective'``-style mentions in a library message as flags."""
    def sub(m: re.Match) -> str:
        flag = FLAG_OF.get(m.group(1))
        return flag if flag else m.group(0)

    return re.sub(r"argument '([a-z_][a-z0-9_]*)'", sub, message)


#: Options that name an output (file or directory); see :func:`check_out_targets`.
#: (flag -> position of the path among its values: ``--export STYLE FILE`` -> 2).
OUTPUT_FLAGS = {"--out": 1, "--c": 1, "--truth": 1, "--save-config": 1, "--export": 2}


def check_out_targets(args: list[str]) -> None:
    """Refuse, before any work, an output option naming an existing device, FIFO or
    socket (or a link to one): an output replaces only a regular file or fills a
    directory. Which of the two a command wants it checks itself."""
    import os
    import stat

    from inertialab.errors import InputError
    from inertialab.io import outputs

    named = []
    for i, a in enumerate(args):
        flag, eq, value = a.partition("=")
        if flag not in OUTPUT_FLAGS:
            continue
        k = i + OUTPUT_FLAGS[flag]
        target = value if eq else (args[k] if k < len(args) else None)
        if target is not None and not target.strip():  # Path('') is the current directory
            raise InputError(f"{flag} is empty; name a file or directory")
        if not target:
            continue
        named.append((flag, target))
        try:
            mode = os.stat(target).st_mode
        except (OSError, ValueError):
            continue
        if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
            kind = ("a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else
                    "a FIFO" if stat.S_ISFIFO(mode) else "a socket")
            raise InputError(f"{flag} is {kind}; an output replaces only a regular file or "
                             "fills a directory", path=target)
    outputs.plan(named)
