"""``inertialab`` command line entry point.

Every command module of :func:`command_modules` defines ``register(app, groups)`` and
adds its commands; ``groups`` holds one group per study (``vibration thermal triaxial dual
drift``, command shape ``inertialab <study> fit|apply|...``) plus ``simulate``, so that
modules can share a group; :data:`TOP_LEVEL` says which modules a top-level name needs,
and only those are imported when it runs. User errors
(:class:`~inertialab.errors.InputError`, usage errors) exit 2 with one line on stderr;
set ``INERTIALAB_DEBUG=1`` to see tracebacks of unexpected errors.
"""

from __future__ import annotations

import os

# Small dense linear algebra (LM steps, ARIMA fits, per-tau sums) runs up to 10-100x slower
# with a threaded BLAS on a shared machine (measured: a 90x41 SVD 4.3 ms threaded vs 0.46 ms
# single; one ARIMA fit 1.6-5 s vs 0.03 s). The CLI therefore pins BLAS to one thread
# unless the user set it; must happen before numpy is imported.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import contextlib  # noqa: E402
import errno  # noqa: E402
import signal  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402

import typer  # noqa: E402

from inertialab import __version__  # noqa: E402
from inertialab import signals as _signals  # noqa: E402
from inertialab.cli.options import check_out_targets, flagged  # noqa: E402
from inertialab.config import read_run_config  # noqa: E402
from inertialab.errors import InputError  # noqa: E402
from inertialab.studies import STUDIES  # noqa: E402

#: The command groups: ``simulate`` and every study of :data:`inertialab.studies.STUDIES`
#: with a group of its own, with the group's help.
_GROUP_HELP = {"simulate": "Write a record from the virtual lab (one rig per study).",
               **{s.name: s.group for s in STUDIES if s.group is not None}}
#: Groups whose bare form ``inertialab GROUP FILE ...`` runs ``GROUP fit FILE ...``
#: (the old ``inertialab vibration SWEEP [FIXED]`` spelling).
_DEFAULT_FIT_GROUPS = {"vibration"}
#: Every top-level command or group, in the order ``--help`` lists them, with the command
#: modules that register into it. The command line imports only the modules of the one
#: name it runs, so a command loads its floors when it runs (tests/cli/test_main.py holds
#: this table against a build of every module).
#: (``allan`` and the study groups come from :data:`inertialab.studies.STUDIES`; each
#: study's command module has the study's name.)
TOP_LEVEL: dict[str, tuple[str, ...]] = {
    "allan": ("allan",), "batch": ("batch",), "demo": ("demo",), "validate": ("validate",),
    "simulate": ("simulate",),
    **{s.name: (s.name,) for s in STUDIES if s.group is not None},
}


def _version_callback(value: bool):
    if value:
        typer.echo(f"inertialab {__version__}")
        raise typer.Exit(0)


def command_module(name: str):
    """The command module ``inertialab.cli.<name>`` (each imported explicitly, on first use)."""
    if name == "allan":
        from inertialab.cli import allan as mod
    elif name == "batch":
        from inertialab.cli import batch as mod
    elif name == "demo":
        from inertialab.cli import demo as mod
    elif name == "drift":
        from inertialab.cli import drift as mod
    elif name == "dual":
        from inertialab.cli import dual as mod
    elif name == "simulate":
        from inertialab.cli import simulate as mod
    elif name == "thermal":
        from inertialab.cli import thermal as mod
    elif name == "triaxial":
        from inertialab.cli import triaxial as mod
    elif name == "validate":
        from inertialab.cli import validate as mod
    elif name == "vibration":
        from inertialab.cli import vibration as mod
    else:
        raise KeyError(f"no command module {name!r}")
    return mod


def command_modules() -> tuple:
    """The command modules, each with ``register(app, groups)``, in registration order."""
    names = dict.fromkeys(m for mods in TOP_LEVEL.values() for m in mods)
    return tuple(command_module(n) for n in names)


def _typer(**kw) -> typer.Typer:
    return typer.Typer(add_completion=False, pretty_exceptions_enable=False,
                       rich_markup_mode=None, **kw)


def _registered(modules) -> dict:
    """The click commands and groups that ``modules`` register, by top-level name."""
    from typer.core import TyperGroup

    class _DefaultFitGroup(TyperGroup):
        def parse_args(self, ctx, args):
            if args and args[0] not in self.commands and not args[0].startswith("-"):
                args = ["fit", *args]
            return super().parse_args(ctx, args)

    app = _typer()
    groups = {name: _typer(help=text, no_args_is_help=True,
                           **({"cls": _DefaultFitGroup} if name in _DEFAULT_FIT_GROUPS else {}))
              for name, text in _GROUP_HELP.items()}
    for mod in modules:
        mod.register(app, groups)
    for name, sub in groups.items():
        if sub.registered_commands or sub.registered_groups:
            app.add_typer(sub, name=name)
    return dict(typer.main.get_group(app).commands)


def _root_class():
    from typer.core import TyperGroup

    class _LazyRoot(TyperGroup):
        """The root group: lists :data:`TOP_LEVEL` and imports a command's modules only
        when the command line names it (or ``--help`` lists them)."""

        def list_commands(self, ctx):
            return list(TOP_LEVEL)

        def get_command(self, ctx, name):
            if name not in self.commands and name in TOP_LEVEL:
                built = _registered(command_module(m) for m in TOP_LEVEL[name])
                self.commands[name] = built[name]
            return self.commands.get(name)

    return _LazyRoot


def build_app() -> typer.Typer:
    """The typer app: the root group and its ``--version``; each command's module is
    imported when the command line names that command (:data:`TOP_LEVEL`).

    Examples
    --------
    >>> import typer
    >>> root = typer.main.get_command(build_app())
    >>> root.list_commands(None)[:4], root.commands
    (['allan', 'batch', 'demo', 'validate'], {})
    """
    app = _typer(name="inertialab",
                 help="Inertial-sensor test records to noise figures, calibration, error "
                      "models, compensation and forecasts.",
                 no_args_is_help=True, cls=_root_class())

    @app.callback()
    def _root(version: bool = typer.Option(False, "--version", callback=_version_callback,
                                           is_eager=True, help="Print the version and exit.")):
        """inertialab command line."""

    return app


def full_command():
    """The root click group with every command loaded (for the documentation and the
    tests that walk the whole command line).

    Examples
    --------
    >>> sorted(full_command().commands["drift"].commands)
    ['apply', 'evaluate', 'fit', 'forecast']
    """
    root = typer.main.get_command(build_app())
    for name in root.list_commands(None):
        root.get_command(None, name)
    return root


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def _click_exit(exc: BaseException) -> int | None:
    """Exit code for the exceptions of typer's (vendored or external) click; None when
    ``exc`` is not one of them. Matched by name because typer >= 0.2x vendors click."""
    name = type(exc).__name__
    if name == "NoArgsIsHelpError":
        ctx = getattr(exc, "ctx", None)
        if ctx is not None:
            sys.stderr.write(ctx.get_help() + "\n")
        return 2
    if name == "Exit" and hasattr(exc, "exit_code"):
        return int(exc.exit_code)
    if name == "Abort":
        sys.stderr.write("error: interrupted; nothing was written\n")
        return 128 + signal.SIGINT
    if hasattr(exc, "format_message") and hasattr(exc, "exit_code"):
        ctx = getattr(exc, "ctx", None)
        hint = f" (see '{ctx.command_path} --help')" if ctx is not None else ""
        sys.stderr.write(f"error: {_one_line(exc.format_message())}{hint}\n")
        return 2
    return None


def _config_value(key: str, value) -> list[str]:
    flag = "--" + str(key).replace("_", "-")
    if isinstance(value, bool):
        return [flag] if value else []
    if isinstance(value, list):
        return [a for v in value for a in _config_value(key, v)]
    return [flag, str(value)]


def expand_config(args: list[str]) -> list[str]:
    """Expand ``--config run.toml`` into arguments and honour ``--save-config FILE``.

    A configuration is TOML: either ``argv = [...]`` (what ``--save-config`` writes,
    with ``cwd`` = the directory it ran in) or ``command = ["batch", "allan"]`` with
    optional ``args = [...]`` (positional) and an ``[options]`` table (``json = true``
    -> ``--json``; lists repeat the option). Arguments given beside ``--config`` follow
    the expanded ones, so a single-valued option given there wins. A relative path in
    a saved configuration is relative to its ``cwd``, which the run changes into.
    """
    if "--save-config" in args:
        i = args.index("--save-config")
        if i + 1 >= len(args):
            raise InputError("--save-config needs a file name")
        target = args[i + 1]
        rest = args[:i] + args[i + 2:]
        import json as _json

        from inertialab.io.writers import atomic_write_text

        lines = ["# inertialab run configuration: inertialab --config THIS_FILE re-runs it",
                 f"inertialab_version = {_json.dumps(__version__)}",
                 f"cwd = {_json.dumps(os.getcwd())}",
                 "argv = [" + ", ".join(_json.dumps(a) for a in rest) + "]"]
        if "--config" in rest:
            raise InputError("--save-config and --config cannot be combined")
        atomic_write_text(target, "\n".join(lines) + "\n")
        args = rest
    if "--config" not in args:
        return args
    i = args.index("--config")
    if i + 1 >= len(args):
        raise InputError("--config needs a TOML file")
    path = args[i + 1]
    doc = read_run_config(path)
    if "argv" in doc:
        expanded = [str(a) for a in doc["argv"]]
    elif "command" in doc:
        cmd = doc["command"]
        expanded = [str(c) for c in (cmd if isinstance(cmd, list) else str(cmd).split())]
        expanded += [str(a) for a in doc.get("args", [])]
        for k, v in (doc.get("options") or {}).items():
            expanded += _config_value(k, v)
    else:
        raise InputError("configuration needs 'argv' or 'command'", path=path)
    cwd = doc.get("cwd")
    if cwd and os.path.isdir(cwd):
        os.chdir(cwd)
    return expanded + args[:i] + args[i + 2:]


#: The one handler and its exception live in :mod:`inertialab.signals`.
Terminated = _signals.Terminated


def _input_files(args: list[str]) -> list[str]:
    """The arguments that name existing regular files (the run's inputs, for messages and
    so that no output replaces one); the values of output options are not inputs."""
    from inertialab.cli.options import OUTPUT_FLAGS

    outs = {i + OUTPUT_FLAGS[a] for i, a in enumerate(args) if a in OUTPUT_FLAGS}
    out = []
    for i, a in enumerate(args):
        if i in outs or a.startswith("-") or len(a) > 4096 or "\0" in a:
            continue
        with contextlib.suppress(OSError, ValueError):
            if os.path.isfile(a):
                out.append(a)
    return out


def _about(files: list[str]) -> str:
    return f" ({', '.join(files[:3])})" if files else ""


#: errno values of an ``OSError`` that are the user's environment, not a bug: exit 2.
_USER_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM,
                errno.EISDIR, errno.ENOTDIR, errno.ENOENT, errno.ENAMETOOLONG, errno.ELOOP,
                errno.EFBIG, errno.EEXIST, errno.ENOTEMPTY, errno.EBUSY, errno.ETXTBSY,
                errno.EXDEV, errno.EMFILE, errno.ENFILE, errno.EIO, errno.EINVAL,
                errno.ENXIO, errno.ENODEV}


def user_error(exc: BaseException, files: list[str], read=()) -> str | None:
    """The one-line message of an exception that bad input or the environment caused (exit 2,
    not an internal error; data errors name ``read``, the records opened), or None for a bug."""
    files = list(read) or files
    if isinstance(exc, InputError):
        text = flagged(_one_line(exc))  # library messages name arguments; users see flags
        if exc.path is None and files and not text.startswith("-"):  # name the inputs
            text = f"{', '.join(files[:3])}: {text}" if read else text + _about(files)
        return text
    if isinstance(exc, MemoryError):
        return (f"not enough memory for this input{_about(files)}; use a smaller file or "
                "smaller size arguments")
    if isinstance(exc, RecursionError):
        return f"input nested too deeply{_about(files)}"
    if isinstance(exc, UnicodeDecodeError):
        return (f"input is not UTF-8 text{_about(files)} (byte 0x{exc.object[exc.start]:02x} "
                f"at offset {exc.start})") if exc.object else f"input is not UTF-8 text{_about(files)}"
    if isinstance(exc, UnicodeError):
        return f"input has an encoding error{_about(files)}: {_one_line(exc)}"
    if isinstance(exc, OverflowError):
        return f"a number is too large{_about(files)} ({_one_line(exc)})"
    if isinstance(exc, ValueError) and "integer string conversion" in str(exc):
        return f"an integer has too many digits{_about(files)}"
    if isinstance(exc, OSError) and not isinstance(exc, BrokenPipeError) and \
            exc.errno in _USER_ERRNOS:
        where = exc.filename if exc.filename is not None else (files[0] if files else None)
        reason = exc.strerror or _one_line(exc)
        return f"{where}: {reason}" if where is not None else reason
    return None


def _one_line_warning(message, category, filename, lineno, file=None, line=None):
    """warnings.showwarning for the CLI: one line, no source line."""
    stream = file if file is not None else sys.stderr
    with contextlib.suppress(OSError, ValueError):
        stream.write(f"warning: {category.__name__}: {flagged(_one_line(message))}\n")


def _interrupted(signum: int) -> int:
    sys.stderr.write(_signals.interrupted_line(signum))
    return 128 + signum


def main(argv: list[str] | None = None) -> None:
    """Run the CLI; exit 0 on success, 2 on bad input or usage (or an output that cannot
    be written), 130/143 when interrupted by SIGINT/SIGTERM, 1 on an internal error.

    The command runs inside an output transaction (:mod:`inertialab.io.outputs`): its
    outputs are committed when it returns and removed when it fails or is interrupted.
    """
    from inertialab.io import front_door, outputs

    args = sys.argv[1:] if argv is None else list(argv)
    files, opened = _input_files(args), front_door.mark()
    _signals.install()
    code = 1
    old_show = warnings.showwarning
    warnings.showwarning = _one_line_warning
    try:
        args = expand_config(args)
        files = _input_files(args)
        check_out_targets(args)
        cmd = typer.main.get_command(build_app())
        with outputs.transaction(protect=files) as tx:
            rv = cmd.main(args=args, prog_name="inertialab", standalone_mode=False)
            code = rv if isinstance(rv, int) else 0
            if code != 0:  # a command that exits non-zero writes nothing
                tx.rollback()
    except (Terminated, KeyboardInterrupt) as exc:
        code = _interrupted(getattr(exc, "signum", signal.SIGINT))
    except BrokenPipeError:
        code = 1
    except Exception as exc:
        read = front_door.since(opened)
        message = None if _signals.received() else user_error(exc, files, read)
        if _signals.received():  # the signal landed inside code that wrapped it (an import)
            code = _interrupted(_signals.received()[-1])
        elif message is not None:
            sys.stderr.write(f"error: {message}\n")
            code = 2
        else:
            code = _click_exit(exc)
        if code is None:  # an inertialab bug: say so in one line
            if os.environ.get("INERTIALAB_DEBUG"):
                raise
            sys.stderr.write(f"error: internal error{_about(read or files)} ({type(exc).__name__}"
                             f": {_one_line(exc)}); rerun with INERTIALAB_DEBUG=1 and report it\n")
            code = 1
    finally:
        warnings.showwarning = old_show
        if argv is None and code == 0:  # a process: a late signal gets its line too
            _signals.mark_committed()
        else:
            _signals.restore()
    with contextlib.suppress(BrokenPipeError, ValueError):
        sys.stdout.flush()
    raise SystemExit(code)
