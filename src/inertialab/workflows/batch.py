"""The fleet runner: one command over many files or units on Dask (docs/batch.md).

``run_batch(command, paths, ...)`` runs ``allan``, ``calibrate-triaxial`` or
``thermal-compensate`` on every file and returns a :class:`BatchResult`: one row per
unit with its key figures, pass/fail against :class:`Tolerance` checks, and the
one-line reason when a unit failed to process (the batch goes on). The engine is
``dask.distributed``: a ``LocalCluster`` (one single-threaded worker process per
``workers``) by default, or an existing scheduler at ``scheduler="tcp://host:8786"``.
``scheduler="serial"`` runs the same per-unit function in this process, which is the
reference the parallel path is tested against (same numbers, unit for unit).

The command ``batch CMD --inputs GLOB`` is one prepared job and one call:
:class:`BatchConfig` (the settings the command line offers), :func:`parse_tolerance`
(the pass/fail rules), :func:`prepare` (command, files and rules checked before any
work) and :func:`run` (:func:`run_batch`) -> :class:`BatchRun`, whose ``artifacts()``
are ``units.csv`` and ``summary.json``.

Checks are parsed from the rule text (:func:`parse_tolerance`) or built directly; :func:`~inertialab.noise.statistics.allan_dask.open_client` opens the Dask client and the
out-of-core Allan kernel of a single long log is
:func:`inertialab.noise.statistics.allan_dask.oadev_dask`.
"""

from __future__ import annotations

import contextlib
import fnmatch
import json
import math
import os
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from inertialab.config import Config as _Settings
from inertialab.config import setting
from inertialab.errors import InputError
from inertialab.jsonable import to_jsonable
from inertialab.limits import MAX_WORKERS, bounded_int
from inertialab.noise.statistics.allan_dask import open_client
from inertialab.progress import NullProgress
from inertialab.result import ResultBase

__all__ = [
    "COMMANDS",
    "BatchConfig",
    "BatchJob",
    "BatchResult",
    "BatchRun",
    "Check",
    "UnitResult",
    "open_client",
    "parse_tolerance",
    "prepare",
    "run",
    "run_batch",
    "run_unit",
]

# ----------------------------------------------------------------------------- tolerances

@dataclass(frozen=True)
class Check:
    """One pass/fail rule on a key figure: ``key <= hi``, ``key >= lo``, ``|key| <= hi``
    (``abs`` True, written ``abs(key)<=hi``) or ``lo <= key <= hi`` (``key=lo..hi``)."""

    key: str
    lo: float = -math.inf
    hi: float = math.inf
    abs: bool = False

    def text(self) -> str:
        k = f"abs({self.key})" if self.abs else self.key
        if math.isfinite(self.lo) and math.isfinite(self.hi):
            return f"{k}={self.lo:g}..{self.hi:g}"
        return f"{k}<={self.hi:g}" if math.isfinite(self.hi) else f"{k}>={self.lo:g}"

    def passes(self, value) -> bool:
        if value is None or not np.isfinite(value):
            return False
        v = abs(value) if self.abs else value
        return bool(self.lo <= v <= self.hi)


# ----------------------------------------------------------------------------- per unit
#
# Each unit runs the single command's own workflow call on its file (the same reading,
# with the batch's full reading options, and the same ``run*`` function), then takes its
# key figures from that command's result: a unit's figures are what the command gives on
# the file alone.

def _reading(options: dict, read=None):
    """The reading options of a unit: ``read`` (the batch command's, every reading flag)
    or, for a caller that gives only plain ``options``, those built from them."""
    if read is not None:
        return read
    from inertialab.io.mapping import ReadOptions

    return ReadOptions.from_cli(options.get("map"), options.get("map_file"),
                                sep=options.get("sep"), decimal=options.get("decimal"),
                                skip_rows=options.get("skip_rows"))


def _unit_allan(path: Path, options: dict, read=None) -> dict:
    """Key figures of one gyro/IMU log from ``allan FILE`` (one series,
    :func:`inertialab.workflows.allan.run`, noise terms off: the figures are the
    curve's): ADEV at 1 s and 100 s (log-log interpolation of the octave OADEV), its
    minimum and where (bias-instability floor), in the log's unit."""
    from inertialab.workflows import allan as wa

    cfg = wa.AllanConfig(column=options.get("column"), rate=options.get("rate"),
                         unit=options.get("unit"), gaps=options.get("gaps"),
                         g_local=options.get("g_local"), taus=options.get("taus", "octave"),
                         terms=False)
    run = wa.run(path, cfg, options=_reading(options, read))
    res = run.res.result("oadev")
    lt, ld = np.log(res.taus_s), np.log(res.dev)

    def at(tau):
        if tau < res.taus_s[0] or tau > res.taus_s[-1]:
            return float("nan")
        return float(np.exp(np.interp(math.log(tau), lt, ld)))

    k = int(np.argmin(res.dev))
    return {"column": run.log.column, "column_unit": run.log.unit, "rate_hz": run.log.rate_hz,
            "n_samples": int(res.n_samples), "adev_1s": at(1.0), "adev_100s": at(100.0),
            "adev_min": float(res.dev[k]), "tau_min_s": float(res.taus_s[k]),
            "sha256": run.sha256}


def _unit_triaxial(path: Path, options: dict, read=None) -> dict:
    """Calibration of one triaxial unit's record from ``triaxial fit FILE``
    (:func:`inertialab.workflows.triaxial.run_fit_file`: default Levenberg-Marquardt on
    the norm objective, ``options["method"]``/``["objective"]`` choose others): bias b
    (working unit), scale k, non-orthogonality theta (rad), the residual RMS and whether
    the solver converged."""
    import warnings

    from inertialab.workflows import triaxial as wt

    cfg = wt.FitConfig(method=options.get("method", "lm"), objective=options.get("objective"),
                       unit=options.get("unit"), g_local=options.get("g_local"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # per-unit warnings would flood a lot's stderr
        res = wt.run_fit_file(path, cfg, options=_reading(options, read))
    if not isinstance(res, wt.FitResult):
        raise InputError("the file holds several units; give one unit per file", path=path)
    p = res.to_json()
    out = {k: float(v) for k, v in p["params"].items()}
    out["resid_rms"] = float(p["residual_rms"])
    out["converged"] = bool(p["converged"])
    out["method"] = f"{p['method']}/{p['objective']}"
    out["n_positions"] = int(p["n_records"])
    out["sha256"] = res.sha256
    return out


def _unit_thermal(path: Path, options: dict, read=None) -> dict:
    """Thermal compensation of one unit's tumble record from ``thermal apply MODEL FILE``
    (:func:`inertialab.workflows.thermal.run_apply`): RMS and largest error of the
    compensated acceleration against the nominal input (ug), and the clamped rows."""
    from inertialab.io import read_record
    from inertialab.workflows import thermal as wt
    from inertialab.workflows.registries import load_model

    model_path = options.get("model")
    if not model_path:
        raise InputError("thermal-compensate needs argument 'model' (a model file)")
    model = load_model(model_path, expected_type="thermal-compensation")
    rec = read_record(path, "thermal_tumble", options=_reading(options, read))
    res = wt.run_apply(model, rec, wt.ApplyConfig(), out=None, source=str(model_path))
    frame = res.res.frame
    out = {"sha256": res.sha256}
    if "a_in_g" in frame:
        err = (frame["comp_a_g"].to_numpy(dtype=float) - frame["a_in_g"].to_numpy()) * 1e6
        out["resid_rms_ug"] = float(np.sqrt(np.mean(err ** 2)))
        out["resid_max_ug"] = float(np.max(np.abs(err)))
    out["n_clamped"] = int(res.to_json()["n_clamped"])
    return out


#: command -> per-unit function(path, options, read) -> dict of key figures
COMMANDS: dict[str, Callable[..., dict]] = {
    "allan": _unit_allan,
    "calibrate-triaxial": _unit_triaxial,
    "thermal-compensate": _unit_thermal,
}


@dataclass(frozen=True)
class UnitResult:
    """One row of the batch table.

    ``status`` is ``"pass"`` (all checks hold), ``"fail"`` (a check failed; ``failed``
    lists them) or ``"error"`` (the unit could not be processed; ``reason`` is the
    one-line message)."""

    unit: str
    path: str
    status: str
    figures: dict = field(default_factory=dict)
    failed: tuple[str, ...] = ()
    reason: str = ""
    wall_s: float = 0.0

    def to_dict(self) -> dict:
        return {"unit": self.unit, "path": self.path, "status": self.status,
                "figures": dict(self.figures), "failed": list(self.failed),
                "reason": self.reason, "wall_s": self.wall_s}


def run_unit(command: str, path, options: dict | None = None,
             checks: Sequence[Check] = (), read=None) -> UnitResult:
    """Process one file (read with ``read``, the command's
    :class:`~inertialab.io.mapping.ReadOptions`, else the reading keys of ``options``);
    never raises for a bad file (the row says why)."""
    p = Path(path)
    unit = p.stem
    t0 = time.perf_counter()
    fn = COMMANDS.get(command)
    if fn is None:
        raise InputError(f"batch command must be one of {', '.join(COMMANDS)}, got '{command}'")
    try:
        figs = fn(p, dict(options or {}), read)
    except InputError as exc:
        return UnitResult(unit, str(p), "error", reason=" ".join(str(exc).split()),
                          wall_s=time.perf_counter() - t0)
    except Exception as exc:  # a worker failure must not stop the lot
        return UnitResult(unit, str(p), "error",
                          reason=f"{type(exc).__name__}: {' '.join(str(exc).split())}",
                          wall_s=time.perf_counter() - t0)
    failed = []
    for c in checks:
        if c.key not in figs:
            failed.append(f"{c.text()} (no figure '{c.key}')")
        elif not c.passes(figs[c.key]):
            failed.append(f"{c.text()} (got {figs[c.key]:.6g})")
    return UnitResult(unit, str(p), "fail" if failed else "pass", figs, tuple(failed),
                      wall_s=time.perf_counter() - t0)


def _run_units(command: str, paths: Sequence[str], options: dict,
               checks: Sequence[Check], read=None) -> list[UnitResult]:
    return [run_unit(command, p, options, checks, read) for p in paths]


# ----------------------------------------------------------------------------- result

@dataclass(frozen=True)
class BatchResult:
    """All units of a batch run.

    Attributes
    ----------
    command : str
    units : tuple of UnitResult (input order)
    checks : tuple of Check
    scheduler : str  (``"serial"``, ``"local"`` or the address used)
    workers : int
    wall_s : float
    """

    command: str
    units: tuple[UnitResult, ...]
    checks: tuple[Check, ...] = ()
    scheduler: str = "serial"
    workers: int = 1
    wall_s: float = 0.0

    @property
    def counts(self) -> dict:
        c = {"pass": 0, "fail": 0, "error": 0}
        for u in self.units:
            c[u.status] += 1
        return c

    @property
    def yield_fraction(self) -> float:
        """Passing units over all units (errors count as not passing)."""
        return self.counts["pass"] / len(self.units) if self.units else float("nan")

    def figure_keys(self) -> list[str]:
        keys: list[str] = []
        for u in self.units:
            for k, v in u.figures.items():
                if k not in keys and isinstance(v, (int, float)) and not isinstance(v, bool):
                    keys.append(k)
        return keys

    def values(self, key: str) -> np.ndarray:
        """The numeric figure ``key`` per unit (NaN where missing or errored)."""
        return np.array([float(u.figures.get(key, np.nan)) if isinstance(
            u.figures.get(key, np.nan), (int, float)) else np.nan for u in self.units])

    def summary(self) -> dict:
        """Yield summary: counts, yield, failures per check, statistics per figure."""
        c = self.counts
        per_check = {ch.text(): sum(1 for u in self.units if any(
            f.startswith(ch.text() + " ") for f in u.failed)) for ch in self.checks}
        stats = {}
        for k in self.figure_keys():
            v = self.values(k)
            v = v[np.isfinite(v)]
            if v.size == 0 or k in ("n_samples", "n_positions"):
                continue
            stats[k] = {"mean": float(v.mean()), "sd": float(v.std(ddof=1)) if v.size > 1 else
                        float("nan"), "min": float(v.min()), "max": float(v.max()),
                        "p05": float(np.percentile(v, 5)), "p95": float(np.percentile(v, 95))}
        return {"n_units": len(self.units), "n_pass": c["pass"], "n_fail": c["fail"],
                "n_error": c["error"], "yield": self.yield_fraction,
                "failures_per_check": per_check, "figures": stats}

    def table(self):
        """pandas DataFrame: unit, status, the figures, failed checks, reason."""
        import pandas as pd

        rows = []
        for u in self.units:
            r = {"unit": u.unit, "status": u.status}
            # a figure never replaces the unit's id or status columns
            r.update({k: v for k, v in u.figures.items() if k != "sha256" and k not in r})
            r["failed"] = "; ".join(u.failed)
            r["reason"] = u.reason
            r["path"] = u.path
            rows.append(r)
        return pd.DataFrame(rows)

    def to_dict(self) -> dict:
        return {"command": self.command, "scheduler": self.scheduler, "workers": self.workers,
                "tolerance": [c.text() for c in self.checks], "summary": self.summary(),
                "units": [u.to_dict() for u in self.units]}


# ----------------------------------------------------------------------------- inputs

#: Most directories one ``--inputs`` pattern may scan (``/**/*.csv`` would walk the whole
#: file system for minutes).
MAX_SCANNED_DIRS = 20_000
#: Most files one batch may take.
MAX_INPUTS = 1_000_000
_MAGIC = re.compile(r"[*?[]")


def expand_inputs(patterns, *, max_dirs: int = MAX_SCANNED_DIRS) -> list[Path]:
    """Sorted regular files matching the glob pattern(s) (``**`` recurses, names
    starting with a dot only when the pattern says so); sidecars (``*.meta.json``),
    schedules and directories are left out. A pattern scanning more than ``max_dirs``
    directories is refused (one line naming it) instead of walking a whole disk;
    nothing matched is an InputError."""
    pats = [patterns] if isinstance(patterns, (str, Path)) else list(patterns)
    found: set[Path] = set()
    budget = [int(max_dirs)]
    for pat in pats:
        text = str(pat)
        parts = Path(text).parts
        k = next((i for i, part in enumerate(parts) if _MAGIC.search(part)), len(parts))
        if k == len(parts):  # no wildcard: the file itself
            hits = [Path(text)]
        else:
            root = Path(*parts[:k]) if k else Path(".")
            hits = _match(root, list(parts[k:]), budget, text)
            if not hits and Path(text).is_file():  # a name holding [ ] or ? itself
                hits = [Path(text)]
        for p in hits:
            if p.is_file() and not fnmatch.fnmatch(p.name, "*.meta.json") \
                    and not p.name.endswith(".schedule.csv"):
                found.add(p)
                if len(found) > MAX_INPUTS:
                    raise InputError(f"argument 'inputs' {text}: more than {MAX_INPUTS} files")
    if not found:
        raise InputError(f"argument 'inputs' {' '.join(map(str, pats))!s}: the glob matches "
                         "no file")
    return sorted(found)


def _match(root: Path, rest: list[str], budget: list[int], pattern: str) -> list[Path]:
    """Paths below ``root`` matching the components ``rest`` (``**``: any depth),
    counting every directory listed against ``budget[0]``."""
    if not rest:
        return [root]
    head, tail = rest[0], rest[1:]
    if head == "**":
        out = _match(root, tail, budget, pattern)
        for e in _listdir(root, budget, pattern, dirs_only=bool(tail)):
            if e.name.startswith("."):  # as glob: ** does not enter hidden names
                continue
            if e.is_dir() and not e.is_symlink():
                out += _match(e, rest, budget, pattern)
            elif not tail:  # a final **: every file below
                out.append(e)
        return out
    if not _MAGIC.search(head):
        nxt = root / head
        return _match(nxt, tail, budget, pattern) if (tail and nxt.is_dir()) or \
            (not tail and nxt.exists()) else []
    out = []
    for entry in _listdir(root, budget, pattern, dirs_only=bool(tail)):
        name = entry.name
        if name.startswith(".") and not head.startswith("."):
            continue
        if fnmatch.fnmatchcase(name, head):
            out += _match(entry, tail, budget, pattern)
    return out


def _listdir(d: Path, budget: list[int], pattern: str, *, dirs_only: bool) -> list[Path]:
    budget[0] -= 1
    if budget[0] < 0:
        raise InputError(f"argument 'inputs' {pattern}: the pattern scans more than "
                         f"{MAX_SCANNED_DIRS} directories; give a narrower one")
    try:
        with os.scandir(d) as it:
            entries = [(e.name, e.is_dir(follow_symlinks=False)) for e in it]
    except OSError:
        return []
    return sorted(d / n for n, is_dir in entries if is_dir or not dirs_only)


@contextlib.contextmanager
def _scratch_dir():
    """A scratch directory for the Dask workers inside the current output's staging
    area (removed with it, or at the end of the run), else a temporary directory
    removed at the end: a batch never leaves ``dask-scratch-space/`` behind."""
    import shutil
    import tempfile

    from inertialab.io import outputs

    tx = outputs.current()
    base = None
    if tx is not None and tx.dirs:
        base = tx.route(next(iter(tx.dirs)))
    path = Path(tempfile.mkdtemp(prefix=".dask-scratch-", dir=base))
    try:
        yield path
    finally:
        shutil.rmtree(path, ignore_errors=True)


#: bytes of a Unix socket's path (``sun_path``, its final NUL included) on Linux
UNIX_PATH_MAX = 108
#: what multiprocessing adds to the temporary directory for the fork server's socket
#: (``/pymp-XXXXXXXX/listener-XXXXXXXX``), with a margin
_SOCKET_SUFFIX = 40


@contextlib.contextmanager
def short_temp_dir(short: str = "/tmp"):
    """While active, :func:`tempfile.gettempdir` is ``short`` when the temporary
    directory (``TMPDIR``) is too long for the fork server's Unix socket under it (the
    socket's path must fit :data:`UNIX_PATH_MAX` bytes); restored on exit. The directory
    multiprocessing makes there (``pymp-*``) is its own, removed by it at exit."""
    import tempfile

    base = tempfile.gettempdir()
    too_long = len(os.fsencode(base)) + _SOCKET_SUFFIX >= UNIX_PATH_MAX
    if not too_long or not (os.path.isdir(short) and os.access(short, os.W_OK | os.X_OK)):
        yield base
        return
    old, tempfile.tempdir = tempfile.tempdir, short
    try:
        yield short
    finally:
        tempfile.tempdir = old


def _start_forkserver(ensure_running) -> None:
    """``ensure_running()`` of multiprocessing's fork server, its socket under a short
    temporary directory (:func:`short_temp_dir`); a socket path still too long is
    refused in one line naming ``TMPDIR``."""
    import tempfile

    with short_temp_dir():
        try:
            ensure_running()
        except OSError as exc:
            if "AF_UNIX path too long" not in str(exc):
                raise
            raise InputError(f"the temporary directory is too long for the local cluster's "
                             f"Unix socket (TMPDIR={tempfile.gettempdir()}): set TMPDIR to "
                             f"a path of at most {UNIX_PATH_MAX - _SOCKET_SUFFIX - 1} "
                             "bytes") from None


@contextlib.contextmanager
def _local_client(scheduler: str, workers: int):
    """:func:`open_client` with its workers' scratch space inside :func:`_scratch_dir`.

    The workers are forked from multiprocessing's fork server, which is started with
    SIGINT ignored for the few milliseconds of its launch: it and every worker forked
    from it (restarted ones too) ignore SIGINT, so a Ctrl-C to the process group reaches
    only this process, which stops the workers and reports once. A Ctrl-C during the
    cluster's start is held until the start is complete (a second or two), then stops
    the run, which closes the whole cluster (:func:`inertialab.signals.deferred`)."""
    import signal
    from multiprocessing import forkserver

    import dask

    from inertialab import signals

    with _scratch_dir() as scratch, dask.config.set({
            "temporary-directory": str(scratch),
            "distributed.worker.multiprocessing-method": "forkserver"}):
        if scheduler == "local":
            # SIGINT blocked and ignored while the fork server starts: it inherits both
            # (and so every worker), while a Ctrl-C in that window stays pending here and
            # is delivered to this process's handler when the mask is restored (ignored
            # alone, it was lost: the run went on to exit 0)
            try:
                mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
                old = signal.signal(signal.SIGINT, signal.SIG_IGN)
            except ValueError:  # not the main thread: leave signals alone
                old = mask = None
            try:
                _start_forkserver(forkserver.ensure_running)
            finally:
                if old is not None:
                    signal.signal(signal.SIGINT, old)
                    signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        with contextlib.ExitStack() as stack:
            with signals.deferred():  # a Ctrl-C in the start stops the run right after it
                cl = stack.enter_context(open_client(scheduler, workers))
            if scheduler == "local":  # belt and braces: a worker ignores it in any case
                with contextlib.suppress(Exception):
                    cl.run(signals.ignore_in_worker)
            yield cl


# ----------------------------------------------------------------------------- engine

def run_batch(command: str, paths: Sequence, *, options: dict | None = None,
              checks: Sequence[Check] = (), scheduler: str = "local", workers: int = 2,
              client=None, progress=None, per_task: int | None = None,
              read=None) -> BatchResult:
    """Run ``command`` on every path and collect a :class:`BatchResult`.

    Parameters
    ----------
    command : {"allan", "calibrate-triaxial", "thermal-compensate"}
    paths : sequence of paths (see :func:`expand_inputs`)
    options : dict
        Per-unit options: the command's settings (``unit``, ``rate``, ``gaps``,
        ``g_local``, ``taus``, ``method``, ``model`` ...) and, without ``read``, the
        reading (``map``, ``map_file``, ``sep``, ``decimal``, ``skip_rows``).
    read : ReadOptions, optional
        The reading options of every unit (all of the single command's reading flags).
    checks : sequence of Check
        Pass/fail rules (``--tolerance``).
    scheduler : {"local", "serial"} or address, default "local"
        ``"serial"`` runs in this process (reference path, no Dask).
    workers : int, default 2
        Worker processes of the LocalCluster.
    client : dask.distributed.Client, optional
        An open client to reuse (then ``scheduler``/``workers`` are only recorded).
    per_task : int, optional
        Units per Dask task (default: about four tasks per worker).
    """
    if command not in COMMANDS:
        raise InputError(f"batch command must be one of {', '.join(COMMANDS)}, got '{command}'")
    workers = bounded_int("workers", workers, 1, MAX_WORKERS)
    progress = progress or NullProgress()
    paths = [Path(p) for p in paths]
    if not paths:
        raise InputError("no input files")
    opts = dict(options or {})
    checks = tuple(checks)
    t0 = time.perf_counter()
    n = len(paths)
    if client is None and scheduler == "serial":
        rows = []
        for i, p in enumerate(paths):
            rows.append(run_unit(command, p, opts, checks, read))
            progress.update(i + 1, n, p.name)
        return BatchResult(command, tuple(rows), checks, "serial", 1, time.perf_counter() - t0)
    ctx = contextlib.nullcontext(client) if client is not None else _local_client(scheduler,
                                                                                    workers)
    with ctx as cl:
        from dask.distributed import as_completed

        nw = len(cl.scheduler_info().get("workers", {})) or int(workers)
        # a few tasks per worker: per-task scheduling costs more than a small unit
        size = max(1, min(per_task or math.ceil(n / (4 * nw)), n))
        groups = [list(range(a, min(a + size, n))) for a in range(0, n, size)]
        futs = [cl.submit(_run_units, command, [str(paths[i]) for i in g], opts, checks,
                          read, pure=False) for g in groups]
        index = {f.key: g for f, g in zip(futs, groups)}
        rows: list = [None] * n
        done = 0
        for fut in as_completed(futs):
            g = index[fut.key]
            if fut.status == "error":  # the worker itself died: mark its units, go on
                exc = fut.exception()
                for i in g:
                    rows[i] = UnitResult(paths[i].stem, str(paths[i]), "error",
                                         reason=f"worker failed: {type(exc).__name__}: "
                                                f"{' '.join(str(exc).split())}")
            else:
                for i, r in zip(g, fut.result()):
                    rows[i] = r
            done += len(g)
            progress.update(done, n, paths[g[-1]].name)
    return BatchResult(command, tuple(rows), checks, scheduler, int(nw), time.perf_counter() - t0)


# ----------------------------------------------------------------------- the command

#: The commands a batch runs (and their old spellings, one release) -> the runner's name.
ALIASES = {"allan": "allan", "triaxial fit": "calibrate-triaxial",
           "thermal apply": "thermal-compensate",
           "calibrate-triaxial": "calibrate-triaxial", "calibrate triaxial": "calibrate-triaxial",
           "thermal-compensate": "thermal-compensate", "thermal compensate": "thermal-compensate"}

_CHECK = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_.]*)\s*(<=|>=|<|>|=)\s*(.+?)\s*$")


def _check(raw: str) -> Check:
    s, is_abs = raw.strip(), False
    m_abs = re.match(r"^abs\(\s*([^)]+?)\s*\)(.*)$", s)
    if m_abs:
        is_abs, s = True, m_abs.group(1) + m_abs.group(2)
    m = _CHECK.match(s)
    if m is None:
        raise InputError(f"argument 'tolerance': {raw.strip()!r} is not KEY<=VALUE, "
                         "KEY>=VALUE or KEY=LO..HI")
    key, op, val = m.groups()
    try:
        if op == "=":
            lo, hi = (_finite(v) for v in val.split(".."))
            if lo > hi:
                raise ValueError
            return Check(key, lo, hi, is_abs)
        if op in ("<=", "<"):
            return Check(key, hi=_finite(val), abs=is_abs)
        return Check(key, lo=_finite(val), abs=is_abs)
    except ValueError:
        raise InputError(f"argument 'tolerance': bad number or range in "
                         f"{raw.strip()!r} (bounds are finite numbers)") from None


def _finite(text: str) -> float:
    """A rule's bound: a finite number (``nan`` or ``inf`` would make the rule always
    fail or always pass)."""
    v = float(text)
    if not math.isfinite(v):
        raise ValueError(text)
    return v


def parse_tolerance(text: str | Sequence[str] | None) -> tuple:
    """The pass/fail rules of ``"adev_1s<=0.01,abs(bx)<=0.05,kx=0.99..1.01"`` (repeated
    texts or a list are joined) as :class:`inertialab.workflows.batch.Check` rules."""
    if text is None:
        return ()
    parts = [text] if isinstance(text, str) else list(text)
    return tuple(_check(raw) for part in parts for raw in str(part).split(",") if raw.strip())


@dataclass(frozen=True)
class BatchConfig(_Settings):
    """Settings of ``batch``."""

    scheduler: str = setting("local", help="local (a LocalCluster), serial (no Dask), or a "
                                           "scheduler address tcp://host:8786.")
    workers: int = setting(2, help="Worker processes of the LocalCluster.", lo=1, hi=256)
    tolerance: list[str] | None = setting(None, help="Pass/fail rules: KEY<=V, KEY>=V, "
                                                     "abs(KEY)<=V, KEY=LO..HI (comma-separated "
                                                     "or repeated).")
    strict: bool = setting(False, help="Exit 2 when any unit could not be processed.")
    unit: str | None = setting(None, help="Unit suffix for columns without one.")
    rate: float | None = setting(None, help="Sample rate in Hz (allan).", lo=1e-9, hi=1e9)
    gaps: str = setting("error", help="error | split (allan logs).", choices=("error", "split"))
    g_local: float | None = setting(None, help="Local gravity, m/s^2.", lo=1.0, hi=100.0)
    model: Path | None = setting(None, help="Model file (thermal compensate).")


@dataclass(frozen=True)
class BatchJob:
    """A checked batch: the command's name, the files, the rules and the per-unit
    options (the settings and reading options in their plain-text form, for the JSON
    settings) and ``read``, the :class:`~inertialab.io.mapping.ReadOptions` every unit is
    read with."""

    name: str
    paths: list
    checks: tuple
    options: dict
    config: BatchConfig
    read: object = None


def prepare(command: Sequence[str], inputs, config: BatchConfig, read) -> BatchJob:
    """Check a batch before any work: the command (``allan``, ``triaxial fit``, ``thermal
    apply``), the files of the ``inputs`` globs, the rules and the model file; ``read``
    (:class:`~inertialab.io.mapping.ReadOptions`, built and checked once here: a bad map
    is one error, not one per unit)."""
    c = config.validate()
    name = ALIASES.get(" ".join(command).strip().lower())
    if name is None:
        raise InputError(f"batch: unknown command '{' '.join(command)}' (allan, triaxial fit, "
                         "thermal apply)")
    paths = expand_inputs(inputs)
    checks = parse_tolerance(c.tolerance)
    if c.unit is not None:
        from inertialab.io.mapping import parse_unit_option

        parse_unit_option(c.unit)  # ',,' or an unknown unit: one line, before any unit
    options = {k: v for k, v in {
        "map": read.column_map.to_text() or None, "sep": read.parse.sep,
        "decimal": read.parse.decimal, "skip_rows": read.parse.skip_rows, "unit": c.unit,
        "rate": c.rate, "gaps": c.gaps if name == "allan" else None, "g_local": c.g_local,
        "model": str(c.model) if c.model else None}.items() if v is not None}
    if c.model is not None and not Path(c.model).is_file():
        raise InputError("no such model file", path=c.model)
    if c.model is not None and name == "thermal-compensate":  # once, before any unit
        from inertialab.calib.model_checks import refuse_or_flag, thermal_findings
        from inertialab.workflows.registries import load_model

        model = load_model(c.model, expected_type="thermal-compensation")
        refuse_or_flag(thermal_findings(model), "thermal", force=False, path=c.model,
                       forceable=False)
    return BatchJob(name=name, paths=paths, checks=checks, options=options, config=c,
                    read=read)


@dataclass
class BatchRun(ResultBase):
    """The fleet's :class:`~inertialab.workflows.batch.BatchResult` and its settings."""

    res: object
    settings: dict
    units = {"wall_s": "s", "yield": "1"}

    @property
    def warnings(self) -> list:
        return [f"unit {u.unit}: {u.reason}" for u in self.res.units if u.status == "error"]

    def to_json(self) -> dict:
        return {"summary": self.res.summary(), "units": [u.to_dict() for u in self.res.units]}

    def artifacts(self) -> dict:
        return {"files": {"units.csv": self.res.table().to_csv(index=False),
                          "summary.json": json.dumps(to_jsonable(self.res.to_dict()),
                                                     indent=2, allow_nan=False)}}

    def summary_rows(self) -> list:
        res, s = self.res, self.res.summary()
        keys = [k for k in res.figure_keys() if k not in ("n_samples", "n_positions")][:6]
        rows = [[u.unit, u.status, *[u.figures.get(k) for k in keys],
                 "; ".join(u.failed) or u.reason] for u in res.units]
        return [(f"batch {self.settings['command']}: {s['n_pass']}/{s['n_units']} pass "
                 f"(yield {100 * s['yield']:.1f} %)", ["unit", "status", *keys, "why"], rows)]


def run(job: BatchJob, *, progress=None) -> BatchRun:
    """Run the job's command on every file (Dask, or serially); with ``strict`` a unit
    that could not be processed fails the whole batch (one line)."""
    c = job.config
    res = run_batch(job.name, job.paths, options=job.options, checks=job.checks,
                    scheduler=c.scheduler, workers=c.workers, progress=progress,
                    read=job.read)
    errors = [u for u in res.units if u.status == "error"]
    if errors and c.strict:
        raise InputError(f"{len(errors)} of {len(res.units)} units could not be processed "
                         f"(argument 'strict'); first: {errors[0].unit}: {errors[0].reason}")
    settings = {"command": job.name, "scheduler": c.scheduler, "workers": c.workers,
                "tolerance": [k.text() for k in job.checks], "strict": c.strict,
                **job.options}
    return BatchRun(res=res, settings=settings)
