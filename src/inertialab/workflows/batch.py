"""Fleets: one command over many files or units, and long logs in chunks, on Dask (issue 10 item 5).

``run_batch(command, paths, ...)`` runs ``allan``, ``calibrate-triaxial`` or
``thermal-compensate`` on every file and returns a :class:`BatchResult`: one row per
unit with its key figures, pass/fail against :class:`Tolerance` checks, and the
one-line reason when a unit failed to process (the batch goes on). The engine is
``dask.distributed``: a ``LocalCluster`` (one single-threaded worker process per
``workers``) by default, or an existing scheduler at ``scheduler="tcp://host:8786"``.
``scheduler="serial"`` runs the same per-unit function in this process, which is the
reference the parallel path is tested against (same numbers, unit for unit).

``oadev_dask(path, rate_hz=...)`` computes the overlapping Allan deviation of a
rate log too long for memory (a ``.npy`` file, memory-mapped by each task): a parallel
pass of per-chunk sums gives the mean exactly as :mod:`inertialab.noise.allan` forms
it, one sequential pass stores the angle at every chunk boundary (the same recurrence
as the noise core, so the angle values are bit-identical), and then tasks of
``(summand range, tau)`` sum the squared second differences in parallel. Only the
order in which the partial sums are added differs from the serial path, so the
deviations agree to about 1e-15 relative (tested at 1e-12). The noise type, EDF and
confidence interval come from the noise core's functions on the same angle values.

Why hand-written: Dask schedules the work, but no library splits an Allan variance
into independent partial sums that reproduce a serial implementation; the kernel here
is a few lines of numpy on top of the noise core's definitions.
"""

from __future__ import annotations

import contextlib
import fnmatch
import glob as _glob
import math
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from inertialab.errors import InputError
from inertialab.workflows.base import NullProgress

__all__ = [
    "COMMANDS",
    "BatchResult",
    "Check",
    "UnitResult",
    "expand_inputs",
    "oadev_dask",
    "open_client",
    "parse_tolerance",
    "run_batch",
    "run_unit",
]

# ----------------------------------------------------------------------------- tolerances

_CHECK = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_.]*)\s*(<=|>=|<|>|=)\s*(.+?)\s*$")


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


def parse_tolerance(text: str | Sequence[str] | None) -> tuple[Check, ...]:
    """Parse ``--tolerance`` (``"adev_1s<=0.01,abs(bx)<=0.05,kx=0.99..1.01"``; repeated
    options or a list are joined)."""
    if text is None:
        return ()
    parts = [text] if isinstance(text, str) else list(text)
    checks = []
    for part in parts:
        for raw in str(part).split(","):
            if not raw.strip():
                continue
            s = raw.strip()
            is_abs = False
            m_abs = re.match(r"^abs\(\s*([^)]+?)\s*\)(.*)$", s)
            if m_abs:
                is_abs = True
                s = m_abs.group(1) + m_abs.group(2)
            m = _CHECK.match(s)
            if m is None:
                raise InputError(f"--tolerance: {raw.strip()!r} is not KEY<=VALUE, KEY>=VALUE "
                                 "or KEY=LO..HI")
            key, op, val = m.groups()
            try:
                if op == "=":
                    lo_s, hi_s = val.split("..")
                    lo, hi = float(lo_s), float(hi_s)
                    if lo > hi:
                        raise ValueError
                    checks.append(Check(key, lo, hi, is_abs))
                elif op in ("<=", "<"):
                    checks.append(Check(key, hi=float(val), abs=is_abs))
                else:
                    checks.append(Check(key, lo=float(val), abs=is_abs))
            except ValueError:
                raise InputError(f"--tolerance: bad number or range in {raw.strip()!r}") from None
    return tuple(checks)


# ----------------------------------------------------------------------------- inputs

def expand_inputs(patterns: str | Sequence[str]) -> list[Path]:
    """Sorted files matching the glob pattern(s) (``**`` recurses); sidecars
    (``*.meta.json``) and directories are left out. Nothing matched is an InputError."""
    pats = [patterns] if isinstance(patterns, str) else list(patterns)
    found: set[Path] = set()
    for pat in pats:
        hits = _glob.glob(str(pat), recursive=True)
        if not hits and Path(pat).is_file():
            hits = [str(pat)]
        for h in hits:
            p = Path(h)
            if p.is_file() and not fnmatch.fnmatch(p.name, "*.meta.json") \
                    and not p.name.endswith(".schedule.csv"):
                found.add(p)
    if not found:
        raise InputError(f"--inputs {' '.join(map(str, pats))!s}: the glob matches no file")
    return sorted(found)


# ----------------------------------------------------------------------------- per unit

def _read_options(options: dict) -> dict:
    from inertialab.io.mapping import ReadOptions

    ro = ReadOptions.from_cli(options.get("map"), options.get("map_file"),
                              sep=options.get("sep"), decimal=options.get("decimal"),
                              skip_rows=options.get("skip_rows"))
    return {"column_map": ro.column_map or None, "parse": ro.parse,
            "unit": options.get("unit"), "g_local": options.get("g_local")}


def _unit_allan(path: Path, options: dict) -> dict:
    """Key figures of one gyro/IMU log: ADEV at 1 s and 100 s (log-log interpolation of
    the octave OADEV), its minimum and where (bias-instability floor), in the log's
    unit; plus the noise terms N, B, K of the noise core when they fit."""
    from inertialab.io import read_record
    from inertialab.noise.allan import oadev

    rec = read_record(path, "gyro_log", rate_hz=options.get("rate"), gaps=options.get("gaps"),
                      **_read_options(options))
    col = options.get("column") or next(
        (c for base in ("rate", "gx", "gy", "gz", "accel", "ax", "ay", "az")
         if (c := rec.find(base)) is not None), None)
    if col is None:
        raise InputError("no rate or acceleration column to analyse", path=path)
    y = rec.column(col)
    if "fs_hz" in rec.meta:
        fs = float(rec.meta["fs_hz"])
    elif options.get("rate"):
        fs = float(options["rate"])
    elif "t_s" in rec.data.columns:
        fs = 1.0 / float(np.median(np.diff(rec.data["t_s"].to_numpy())))
    else:
        raise InputError("needs t_s or --rate", path=path)
    res = oadev(y, rate_hz=fs, taus=options.get("taus", "octave"))
    lt, ld = np.log(res.taus_s), np.log(res.dev)

    def at(tau):
        if tau < res.taus_s[0] or tau > res.taus_s[-1]:
            return float("nan")
        return float(np.exp(np.interp(math.log(tau), lt, ld)))

    k = int(np.argmin(res.dev))
    unit = rec.units.get(col, "")
    out = {"column": col, "unit": unit, "rate_hz": fs, "n_samples": int(res.n_samples),
           "adev_1s": at(1.0), "adev_100s": at(100.0), "adev_min": float(res.dev[k]),
           "tau_min_s": float(res.taus_s[k]), "sha256": rec.sha256}
    return out


def _unit_triaxial(path: Path, options: dict) -> dict:
    """Calibration of one triaxial unit's static record with the triaxial workflow
    (:func:`inertialab.workflows.field_calibration.calibrate`, spec 002; default
    Levenberg-Marquardt on the norm objective, ``options["method"]``/``["objective"]``
    choose others): bias b (working unit), scale k, non-orthogonality theta (rad), the
    residual RMS and whether the solver converged."""
    import warnings

    from inertialab.io import read_record
    from inertialab.workflows import triaxial as fc

    rec = read_record(path, "triaxial_static", **_read_options(options))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # per-unit warnings would flood a lot's stderr
        data = fc.static_data_from_frame(rec.data, rec.meta, g=options.get("g_local"),
                                         path=path)
    fit = fc.calibrate(data.a, ref=data.ref, method=options.get("method", "lm"),
                       objective=options.get("objective", "norm"), g=data.g, rng=0,
                       counts=data.counts)
    out = {k: float(v) for k, v in fit.params.items()}
    out["resid_rms"] = float(fit.residual_rms)
    out["converged"] = bool(fit.converged)
    out["method"] = f"{fit.method}/{fit.objective}"
    out["n_positions"] = int(fit.n_records)
    out["sha256"] = rec.sha256
    return out


def _unit_thermal(path: Path, options: dict) -> dict:
    """Thermal compensation of one unit's tumble record with a saved model: RMS of the
    compensated residual against the nominal input (ug) before and after."""
    from inertialab.io import load_model, read_record

    model_path = options.get("model")
    if not model_path:
        raise InputError("thermal-compensate needs --model MODEL.json")
    try:
        from inertialab.workflows.thermal import compensate
    except ImportError:  # pragma: no cover - the thermal workflow ships with inertialab
        raise InputError("the thermal workflow is not available in this installation") from None
    model = load_model(model_path)
    rec = read_record(path, "thermal_tumble", **_read_options(options))
    d = rec.data
    comp = compensate(model, d["temp_meas_c"].to_numpy(), d["output_mv"].to_numpy(),
                      d["a_pend_g"].to_numpy() if "a_pend_g" in d else None)
    out = {"sha256": rec.sha256}
    for name in ("a_in_g", "a_g", "output_g", "value"):
        v = getattr(comp, name, None)
        if v is not None:
            v = np.asarray(v, dtype=float)
            if "a_in_g" in d:
                err = (v - d["a_in_g"].to_numpy()) * 1e6
                out["resid_rms_ug"] = float(np.sqrt(np.mean(err ** 2)))
                out["resid_max_ug"] = float(np.max(np.abs(err)))
            break
    status = getattr(comp, "status", None)
    if status is not None:
        out["n_clamped"] = int(np.count_nonzero(np.asarray(status)))
    return out


#: command -> per-unit function(path, options) -> dict of key figures
COMMANDS: dict[str, Callable[[Path, dict], dict]] = {
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
             checks: Sequence[Check] = ()) -> UnitResult:
    """Process one file; never raises for a bad file (the row says why)."""
    p = Path(path)
    unit = p.stem
    t0 = time.perf_counter()
    fn = COMMANDS.get(command)
    if fn is None:
        raise InputError(f"batch command must be one of {', '.join(COMMANDS)}, got '{command}'")
    try:
        figs = fn(p, dict(options or {}))
    except InputError as exc:
        return UnitResult(unit, str(p), "error", reason=" ".join(str(exc).split()),
                          wall_s=time.perf_counter() - t0)
    except Exception as exc:  # a worker failure must not stop the lot (issue 10 item 6)
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
               checks: Sequence[Check]) -> list[UnitResult]:
    return [run_unit(command, p, options, checks) for p in paths]


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
            r.update({k: v for k, v in u.figures.items() if k != "sha256"})
            r["failed"] = "; ".join(u.failed)
            r["reason"] = u.reason
            r["path"] = u.path
            rows.append(r)
        return pd.DataFrame(rows)

    def to_dict(self) -> dict:
        return {"command": self.command, "scheduler": self.scheduler, "workers": self.workers,
                "tolerance": [c.text() for c in self.checks], "summary": self.summary(),
                "units": [u.to_dict() for u in self.units]}


# ----------------------------------------------------------------------------- engine

@contextlib.contextmanager
def open_client(scheduler: str = "local", workers: int = 2):
    """A ``dask.distributed.Client``: a new ``LocalCluster`` of ``workers``
    single-threaded worker processes for ``"local"``, else a connection to the
    scheduler at the address given. Closed on exit (a LocalCluster is shut down)."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise InputError("batch needs dask.distributed: pip install 'inertialab[dask]'") from None
    if scheduler == "local":
        if int(workers) < 1:
            raise InputError(f"--workers must be >= 1, got {workers}")
        cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=50)
        client = Client(cluster)
        try:
            yield client
        finally:
            client.close()
            cluster.close()
    else:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise InputError(f"--scheduler {scheduler}: cannot connect ({type(exc).__name__})") \
                from None
        try:
            yield client
        finally:
            client.close()


def run_batch(command: str, paths: Sequence, *, options: dict | None = None,
              checks: Sequence[Check] = (), scheduler: str = "local", workers: int = 2,
              client=None, progress=None, per_task: int | None = None) -> BatchResult:
    """Run ``command`` on every path and collect a :class:`BatchResult`.

    Parameters
    ----------
    command : {"allan", "calibrate-triaxial", "thermal-compensate"}
    paths : sequence of paths (see :func:`expand_inputs`)
    options : dict
        Per-unit options: reading (``map``, ``map_file``, ``unit``, ``rate``, ``gaps``,
        ``g_local`` ...) and the command's own (``taus``, ``model``).
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
            rows.append(run_unit(command, p, opts, checks))
            progress.update(i + 1, n, p.name)
        return BatchResult(command, tuple(rows), checks, "serial", 1, time.perf_counter() - t0)
    ctx = contextlib.nullcontext(client) if client is not None else open_client(scheduler,
                                                                                  workers)
    with ctx as cl:
        from dask.distributed import as_completed

        nw = len(cl.scheduler_info().get("workers", {})) or int(workers)
        # a few tasks per worker: per-task scheduling costs more than a small unit
        size = max(1, min(per_task or math.ceil(n / (4 * nw)), n))
        groups = [list(range(a, min(a + size, n))) for a in range(0, n, size)]
        futs = [cl.submit(_run_units, command, [str(paths[i]) for i in g], opts, checks,
                          pure=False) for g in groups]
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


# ----------------------------------------------------------------------------- chunked Allan

class _NpyPhase:
    """Angle points of a ``.npy`` rate log, recomputed from chunk checkpoints exactly as
    :class:`inertialab.noise.allan` does (so values are bit-identical to its angle).
    Pickles as the file path: each Dask task memory-maps the file itself."""

    def __init__(self, path: str, tau0: float, mean: float, ck: np.ndarray, chunk: int):
        self.path = str(path)
        self.tau0 = float(tau0)
        self.mean = float(mean)
        self.ck = ck
        self.chunk = int(chunk)
        self._y = None
        self.n = int(self.y.size) + 1
        self.block = chunk

    @property
    def y(self) -> np.ndarray:
        if self._y is None:
            self._y = np.load(self.path, mmap_mode="r")
            if self._y.ndim == 2:
                self._y = self._y[:, 0]
        return self._y

    def __getstate__(self):
        d = dict(self.__dict__)
        d["_y"] = None
        return d

    def window(self, start: int, length: int, step: int = 1) -> np.ndarray:
        from inertialab.noise.allan import phase_window

        return phase_window(self.y, self.ck, self.mean, self.tau0, start, length, step=step,
                            checkpoint=self.chunk, block=self.chunk)


def _chunk_sums(path: str, c0: int, c1: int, chunk: int) -> list[float]:
    y = np.load(path, mmap_mode="r")
    y = y[:, 0] if y.ndim == 2 else y
    out = []
    for s in range(c0 * chunk, min(c1 * chunk, y.size), chunk):
        blk = y[s:s + chunk]
        if not np.issubdtype(blk.dtype, np.integer) and not np.isfinite(blk).all():
            bad = int(np.flatnonzero(~np.isfinite(blk))[0]) + s
            raise InputError(f"NaN or infinity at sample index {bad}", path=path)
        out.append(float(np.sum(blk, dtype=np.float64)))
    return out


def _checkpoints(path: str, mean: float, tau0: float, chunk: int) -> tuple[np.ndarray, bool]:
    """Angle at every chunk boundary (the noise core's sequential recurrence) and
    whether the data are constant."""
    y = np.load(path, mmap_mode="r")
    y = y[:, 0] if y.ndim == 2 else y
    ck = np.empty(y.size // chunk + 2, dtype=np.float64)
    ck[0] = 0.0
    x_prev = 0.0
    lo = hi = None
    for i, s in enumerate(range(0, y.size, chunk)):
        u = np.subtract(y[s:s + chunk], mean, dtype=np.float64)
        bmin, bmax = float(u.min()), float(u.max())
        lo = bmin if lo is None else min(lo, bmin)
        hi = bmax if hi is None else max(hi, bmax)
        u *= tau0
        u[0] += x_prev
        x_prev = float(np.cumsum(u)[-1])
        ck[i + 1] = x_prev
    return ck, bool(lo == hi)


def _oadev_partial(src: _NpyPhase, ms: Sequence[int], a: int, b: int,
                   block: int = 1 << 15) -> list[float]:
    """``sum_{i in [a, b)} (x[i+2m] - 2 x[i+m] + x[i])^2`` for each m (summands beyond
    ``n - 2m`` are left out), with the noise core's operation order per element."""
    out = []
    nx = src.n
    base = None
    small = [m for m in ms if 2 * m <= b - a]
    reach = 2 * max(small) if small else 0
    for m in ms:
        stop = min(b, nx - 2 * m)
        if stop <= a:
            out.append(0.0)
            continue
        cnt = stop - a
        if base is not None and base[0] == a and base[1].size >= cnt + 2 * m:
            x = base[1]
            w0, w1, w2 = x[:cnt], x[m:m + cnt], x[2 * m:2 * m + cnt]
        elif 2 * m <= cnt:
            x = src.window(a, min(b - a + reach, nx - a))
            base = (a, x)
            w0, w1, w2 = x[:cnt], x[m:m + cnt], x[2 * m:2 * m + cnt]
        else:
            w0, w1, w2 = (src.window(a + j * m, cnt) for j in (0, 1, 2))
        acc = np.array(w2, dtype=np.float64)
        acc += w1 * -2.0
        acc += w0
        # dot products over the noise core's in-memory blocks, added in order: the task's
        # start is a multiple of the block, so the partial sums match its own
        tot = 0.0
        for s in range(0, cnt, block):
            seg = acc[s:s + block]
            tot += float(np.dot(seg, seg))
        out.append(tot)
    return out


def oadev_dask(path, *, rate_hz: float, taus="octave", client=None, scheduler: str = "local",
               workers: int = 2, chunk: int | None = None, range_chunks: int = 8,
               confidence: float = 0.683, alpha=None, edf_method: str = "default"):
    """Overlapping Allan deviation of a ``.npy`` rate log, computed by Dask in parallel.

    Parameters
    ----------
    path : str or Path
        A one-column ``.npy`` file of rate samples (memory-mapped by every task; the
        record never has to fit in memory).
    rate_hz : float
        Sample rate, Hz.
    taus : see :func:`inertialab.noise.allan.tau_grid`, default "octave"
    client : dask.distributed.Client, optional
        An open client; else one is opened with ``scheduler``/``workers``.
    chunk : int, optional
        Checkpoint spacing in samples (default: the noise core's ``CHUNK``, which the
        bit-identical angle needs).
    range_chunks : int, default 8
        Summands per task, in chunks.
    confidence, alpha, edf_method
        As :func:`inertialab.noise.allan.deviation`.

    Returns
    -------
    DeviationResult
        Equal to ``oadev(np.load(path), rate_hz=...)`` up to the order of the final
        additions (tested at 1e-12 relative).
    """
    from inertialab.noise import allan as _allan
    from inertialab.noise import edf as _edf

    p = Path(path)
    if p.suffix.lower() != ".npy" or not p.is_file():
        raise InputError("the chunked Allan path reads a one-column .npy file", path=p)
    try:
        y = np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError) as exc:
        raise InputError(f"not a readable .npy file ({exc})", path=p) from None
    if y.ndim == 2 and y.shape[1] == 1:
        y = y[:, 0]
    if y.ndim != 1 or not np.issubdtype(y.dtype, np.number):
        raise InputError(f".npy log must be one numeric column, got shape {y.shape}", path=p)
    n = int(y.size)
    if n < 3:
        raise InputError(f"too few samples ({n}) for any tau", path=p)
    rate = float(rate_hz)
    if not math.isfinite(rate) or rate <= 0:
        raise InputError(f"rate_hz must be positive and finite, got {rate_hz}")
    C = int(chunk or _allan.CHUNK)
    tau0 = 1.0 / rate
    ms = _allan.tau_grid(n, taus, rate_hz=rate, statistic="oadev")
    ctx = contextlib.nullcontext(client) if client is not None else open_client(scheduler,
                                                                                  workers)
    spath = str(p.resolve())
    nchunks = -(-n // C)
    with ctx as cl:
        # pass 1 (parallel): per-chunk sums, added in order as the noise core does
        groups = [(c0, min(c0 + range_chunks, nchunks)) for c0 in range(0, nchunks, range_chunks)]
        parts = cl.gather(cl.map(_chunk_sums, [spath] * len(groups), [g[0] for g in groups],
                                 [g[1] for g in groups], [C] * len(groups), pure=False))
        total = 0.0
        for part in parts:
            for v in part:
                total += v
        mean = total / n
        # pass 2 (one task): the angle at every chunk boundary
        ck, constant = cl.submit(_checkpoints, spath, mean, tau0, C, pure=False).result()
        if constant:
            raise InputError("data are constant (zero deviation at every tau); nothing to "
                             "analyse", path=p)
        src = _NpyPhase(spath, tau0, mean, ck, C)
        # pass 3 (parallel): partial sums per summand range, all taus in one task
        span = C * range_chunks
        starts = list(range(0, n + 1, span))
        mlist = [int(m) for m in ms]
        sfut = cl.scatter(src, broadcast=True)
        blk = int(getattr(_allan, "BLOCK", 1 << 15))
        if span % blk:
            span = -(-span // blk) * blk
            starts = list(range(0, n + 1, span))
        futs = [cl.submit(_oadev_partial, sfut, mlist, a, a + span, blk, pure=False)
                for a in starts]
        partials = cl.gather(futs)
    var = np.empty(len(mlist))
    nt = np.empty(len(mlist), dtype=np.int64)
    for k, m in enumerate(mlist):
        s = 0.0
        for part in partials:
            s += part[k]
        cnt = src.n - 2 * m
        tau = m * tau0
        var[k] = s / (2.0 * tau * tau * cnt)
        nt[k] = cnt
    dev = np.sqrt(var)
    if alpha is None:
        ident = _edf.identify_alpha(src, ms, statistic="oadev")
        alphas, sources, amethod = ident.alpha, ident.source, "lag1"
    else:
        alphas = np.broadcast_to(np.asarray(alpha, dtype=np.int64), ms.shape).copy()
        sources, amethod = ("user",) * ms.size, "user"
    edfs, emethod = _edf.edf("oadev", src.n, ms, alphas, n_terms=nt, method=edf_method)
    lo, hi = _edf.chi2_interval(dev, edfs, confidence)
    return _allan.DeviationResult(
        statistic="oadev", tau0_s=tau0, taus_s=ms * tau0, m=ms, dev=dev, n_terms=nt,
        alpha=alphas, edf=edfs, ci_low=lo, ci_high=hi, confidence=float(confidence),
        n_samples=n, input="rate", alpha_method=amethod, edf_method=emethod,
        alpha_source=tuple(sources))
