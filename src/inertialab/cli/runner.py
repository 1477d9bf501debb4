"""The one command runner: read -> run -> write -> print or emit, for every command built
on it, and the options every such command shares, declared here once.

A command module declares its settings as a workflow :class:`~inertialab.config.Config`
and writes a function taking ``config`` (built from the flags the config's fields
declare) and ``run`` (the shared ``--out/--json/--quiet`` of this invocation)::

    @group.command("fit")
    @reading_options
    @config_command(wf.FitConfig, out="dir")
    def fit(file: Path = typer.Argument(...), *, config, run, read):
        run.execute("drift fit", lambda progress: wf.run_fit(read_record(file, ...),
                    config, progress=progress), inputs=[file], figures=...)

:meth:`Run.execute` runs the workflow inside the warning collector and progress bar,
builds the one JSON envelope (``command``, ``inputs`` with their sha256, ``settings``,
``units``, ``warnings``, ``meta.timestamps``, then the result's own keys) and prints it
with ``--json`` or writes it as ``--out DIR/result.json`` (with the models and figures
of the result); otherwise it prints the result's summary tables.

A result (from the workflow) is a :class:`inertialab.result.Result`: ``to_json()`` (its
keys), ``settings`` and ``units`` (dicts), ``artifacts()`` (``{"models": [(file name,
model, units)], "files": {file name: text}}``), ``summary_rows()`` (a list of ``(title,
columns, rows)`` tables and plain lines), ``inputs`` (set here, through
``with_inputs``), ``sha256`` (the training record's canonical hash, written into the
model files) and ``warnings`` (the result's own lines, reported with the Python warnings
raised while it ran); :meth:`Run.execute` refuses anything else. A command whose ``--out`` is one record
(``out="file"``) writes the result's ``artifacts()["records"]`` (``[(path, frame,
meta)]``, the record and its sidecar) and ``["files"]`` (``{path: text}``, beside it),
all after the result is complete.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import functools
import inspect
import json
import time
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import typer

from inertialab.cli.common import (
    atomic_write_text,
    collect_warnings,
    envelope,
    json_ready,
    prepare_out_dir,
    print_table,
    progress_bar,
    write_figures,
)
from inertialab.cli.options import FLAG_OF, JsonOpt, OutDirOpt, OutFileOpt, QuietOpt, flagged
from inertialab.errors import InputError
from inertialab.result import check_result

__all__ = ["Run", "config_command", "load_model", "read_imu_thermal_log", "read_record"]

_COMMON = {name: inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=False,
                                   annotation=ann)
           for name, ann in (("as_json", JsonOpt), ("quiet", QuietOpt))}


def _utc() -> str:
    return _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%S.%fZ")


@dataclass
class Run:
    """The shared options of one invocation: ``out`` (a directory, or a file for commands
    that write one record: ``out_kind="file"``), ``as_json``, ``quiet``."""

    out: Path | None = None
    as_json: bool = False
    quiet: bool = False
    out_kind: str = "dir"

    def execute(self, command: str, produce, *, inputs=(), figures=None, after=None) -> dict:
        """Run ``produce(progress) -> result``, then write, print or emit (module
        docstring). ``figures(result)`` gives the figures written to ``--out``;
        ``after(result, out_dir)`` writes anything else there; ``inputs`` may be a
        function of the result (to name a record's canonical hash). Returns the envelope."""
        if self.out is not None and self.out_kind == "file" and Path(self.out).is_dir():
            raise InputError("--out must be a file for this command", path=self.out)
        out_dir = (prepare_out_dir(self.out) if self.out is not None and self.out_kind == "dir"
                   else None)
        started, t0 = _utc(), time.perf_counter()
        with collect_warnings(quiet=self.quiet or self.as_json) as warns:
            with progress_bar(command, quiet=self.quiet or self.as_json) as bar:
                result = check_result(produce(bar), command)
        meta = {"timestamps": {"started_utc": started, "finished_utc": _utc(),
                               "wall_s": round(time.perf_counter() - t0, 6)}}
        result.with_inputs(inputs(result) if callable(inputs) else inputs)
        own = [w for w in result.warnings if not any(w in x for x in warns)]
        if own and not (self.quiet or self.as_json):  # the result's own, not Python warnings
            import sys

            for w in own:
                sys.stderr.write(f"warning: {flagged(' '.join(w.split()))}\n")
        warns = list(warns) + own
        env = envelope(command, result.to_json(), inputs=result.inputs, settings=result.settings,
                       units=result.units, warnings_=warns, meta=meta)
        if out_dir is not None:
            self._write(out_dir, result, env, figures, after)
        elif self.out is not None and self.out_kind == "file":
            _write_records(result.artifacts())
            if after is not None:
                after(result, None)
        if self.as_json:
            import sys

            sys.stdout.write(json.dumps(env, indent=2, allow_nan=False) + "\n")
            return env
        for item in result.summary_rows():
            if isinstance(item, str):
                print(flagged(item))  # library lines name arguments; users see flags
            else:
                title, columns, rows = item
                print_table(columns, rows, title=title)
        if out_dir is not None:
            print(f"written: {out_dir}")
        return env

    @staticmethod
    def _write(out_dir, result, env, figures, after) -> None:
        from inertialab.workflows.registries import save_model

        sha = result.sha256  # the training record's canonical hash
        art = result.artifacts()
        for name, model, units in art.get("models", ()):
            if "/" in name:
                (out_dir / name).parent.mkdir(parents=True, exist_ok=True)
            save_model(model, out_dir / name, units=units, training_data_sha256=sha,
                       settings=env["settings"])
        for name, text in art.get("files", {}).items():
            atomic_write_text(out_dir / name, text)
        atomic_write_text(out_dir / "result.json",
                          json.dumps(json_ready(env), indent=2, allow_nan=False) + "\n")
        if figures is not None:
            write_figures(figures(result), out_dir)
        if after is not None:
            after(result, out_dir)


def _write_records(art: dict) -> None:
    """The records (data and sidecar) and side files of a one-record command."""
    from inertialab.io import write_record

    for path, frame, meta in art.get("records", ()):
        write_record(frame, path, meta)
    for path, text in art.get("files", {}).items():
        atomic_write_text(path, text)


def read_record(path, kind, **kw):
    """The record a command reads, through the one front door
    (:func:`inertialab.io.readers.read_record`), imported here when the command runs so
    that ``--help`` and ``--version`` start without pandas."""
    from inertialab.io import readers

    return readers.read_record(path, kind, **kw)


def read_imu_thermal_log(path):
    """A drone IMU temperature-ramp log (:mod:`inertialab.io.formats.thermal_logs`), the
    input of ``thermal fit --imu`` and ``thermal apply`` with a six-axis model, loaded
    when the command runs."""
    from inertialab.io.formats.thermal_logs import read_imu_thermal_log as _read

    return _read(path)


def load_model(path, *, expected_type: str | None = None):
    """The model file a command reads (:func:`inertialab.calib.load_model` through
    :func:`inertialab.workflows.registries.load_model`), loaded when the command runs."""
    from inertialab.workflows.registries import load_model as _load

    return _load(path, expected_type=expected_type)


def _hints(cls) -> dict:
    import inertialab.config as _config_module  # the Config base's names, for get_type_hints

    module = inspect.getmodule(cls)
    ns = {**vars(_config_module), **(vars(module) if module else {})}
    return typing.get_type_hints(cls, globalns=ns)


def _option(f: dataclasses.Field, meta: dict, hint) -> inspect.Parameter:
    text = flagged(meta["help"]) + (f" [{meta['unit']}]" if meta.get("unit") else "")
    default = None if f.default is dataclasses.MISSING else f.default
    decl = "/".join("--" + part for part in meta["flag"].split("/"))  # "a/no-a": a switch
    return inspect.Parameter(f.name, inspect.Parameter.KEYWORD_ONLY, default=default,
                             annotation=Annotated[hint, typer.Option(decl, help=text)])


def config_command(config_cls, *, out: str | None = "dir", out_help: str | None = None):
    """Decorator: add the options of ``config_cls``'s settings and the shared
    ``--out`` (``out="dir"`` or ``"file"``, ``"file!"`` when required; None: none),
    ``--json`` and ``--quiet`` to a command, which receives ``config`` (validated) and
    ``run`` (:class:`Run`). ``out_help`` replaces the help of ``--out``."""
    hints = _hints(config_cls)
    fields = [(f, m) for f, m in config_cls.fields() if m["cli"]]
    for f, m in fields:
        FLAG_OF.setdefault(f.name, "--" + m["flag"].split("/")[0])
    params = [_option(f, m, hints[f.name]) for f, m in fields]
    common = dict(_COMMON)
    if out is not None:
        ann = OutDirOpt if out == "dir" else OutFileOpt
        if out_help is not None or out == "file!":
            ann = Annotated[ann.__origin__, typer.Option(
                "--out", help=out_help or ann.__metadata__[0].help)]
        common["out"] = inspect.Parameter("out", inspect.Parameter.KEYWORD_ONLY,
                                          default=... if out == "file!" else None,
                                          annotation=ann)

    def deco(fn):
        sig = inspect.signature(fn, eval_str=True)
        own = [p for p in sig.parameters.values() if p.name not in ("config", "run")]

        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            values = {f.name: kwargs.pop(f.name) for f, _ in fields}
            run = Run(out=kwargs.pop("out", None) if "out" in common else None,
                      as_json=kwargs.pop("as_json"), quiet=kwargs.pop("quiet"),
                      out_kind="file" if out in ("file", "file!") else "dir")
            return fn(*args, config=config_cls(**values).validate(), run=run, **kwargs)

        pos = [p for p in own if p.kind != inspect.Parameter.KEYWORD_ONLY]
        kw = [p for p in own if p.kind == inspect.Parameter.KEYWORD_ONLY]
        wrapper.__config__ = config_cls  # the settings this command offers (tests walk them)
        wrapper.__signature__ = sig.replace(parameters=pos + params + list(common.values()) + kw)
        wrapper.__annotations__ = {p.name: p.annotation for p in
                                   pos + params + list(common.values()) + kw}
        return wrapper

    return deco
