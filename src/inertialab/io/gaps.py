"""Dropouts, repeated stamps and saturation in continuous logs.

A real log loses packets (a time step much longer than the nominal one), repeats a
stamp (a resent packet, a coarse clock) or jumps back (a counter reset); a sensor
driven past its range sits at its full-scale value. This module finds both:

* :func:`detect_gaps` reads the time column and returns a :class:`GapReport` with
  every problem (kind, the 1-based data row after the jump, the times either side
  and the duration lost) and the segments between them.
* :func:`apply_gap_policy` applies ``--gaps error`` (the CLI default: one
  :class:`~inertialab.errors.InputError` listing the first problems with their rows
  and durations) or ``--gaps split`` (a ``segment`` column, 0, 1, ...; each segment
  has strictly increasing, gap-free time).
* :func:`detect_saturation` flags samples at the full-scale value, either given per
  column (``--full-scale ax_mps2=78.4,...`` or the sidecar's ``full_scale``) or found
  as flat runs at a column's extreme (clipping), and :func:`exclude_flagged` removes
  flagged samples from index intervals ``[start, stop)`` (e.g. static intervals), so
  a saturated sample never enters a static mean.
* :func:`stuck_run` finds the longest run of one repeated value that the column's own
  rate of repeats cannot explain (a frozen sensor or a driver that resent its last
  sample for minutes).

The nominal step is the median positive step; a gap is a step longer than
``gap_factor`` (default 1.5) times it, i.e. at least one whole sample missing with up
to 50 % clock jitter tolerated.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from inertialab.errors import InputError

__all__ = [
    "GAP_FACTOR",
    "GapReport",
    "SaturationReport",
    "TimeIssue",
    "apply_gap_policy",
    "detect_gaps",
    "is_constant",
    "detect_saturation",
    "exclude_flagged",
    "stuck_run",
]

#: A step longer than this many nominal steps is a dropout.
GAP_FACTOR = 1.5
_LISTED = 5


@dataclass(frozen=True)
class TimeIssue:
    """One time-stamp problem.

    Attributes
    ----------
    kind : {"gap", "repeat", "backward"}
    row : int
        1-based data row of the sample after the jump (as a spreadsheet counts).
    t_before_s, t_after_s : float
        Stamps either side, s.
    duration_s : float
        Time lost: ``step - nominal`` for a gap, 0 for a repeat, the (negative) step
        for a backward jump.
    missing : int
        Samples missing in a gap (``round(step / nominal) - 1``); 0 otherwise.
    """

    kind: str
    row: int
    t_before_s: float
    t_after_s: float
    duration_s: float
    missing: int = 0

    def text(self) -> str:
        if self.kind == "gap":
            return (f"gap of {self.duration_s:.6g} s (~{self.missing} samples) before row "
                    f"{self.row}")
        if self.kind == "repeat":
            return f"repeated stamp {self.t_after_s:.9g} s at row {self.row}"
        return f"time goes back by {-self.duration_s:.6g} s at row {self.row}"

    def to_dict(self) -> dict:
        return {"kind": self.kind, "row": self.row, "t_before_s": self.t_before_s,
                "t_after_s": self.t_after_s, "duration_s": self.duration_s,
                "missing": self.missing}


@dataclass(frozen=True)
class GapReport:
    """Time-stamp problems of a log and the segments between them.

    Attributes
    ----------
    n_rows : int
    nominal_dt_s : float
        Median positive step, s.
    issues : tuple of TimeIssue
    segments : tuple of (start, stop)
        0-based row ranges ``[start, stop)`` free of problems.
    gap_factor : float
    """

    n_rows: int
    nominal_dt_s: float
    issues: tuple[TimeIssue, ...] = ()
    segments: tuple[tuple[int, int], ...] = ()
    gap_factor: float = GAP_FACTOR

    @property
    def ok(self) -> bool:
        return not self.issues

    @property
    def lost_s(self) -> float:
        return float(sum(i.duration_s for i in self.issues if i.kind == "gap"))

    def summary(self, limit: int = _LISTED) -> str:
        counts = {}
        for i in self.issues:
            counts[i.kind] = counts.get(i.kind, 0) + 1
        head = ", ".join(f"{v} {k}{'s' if v > 1 else ''}" for k, v in counts.items())
        listed = "; ".join(i.text() for i in self.issues[:limit])
        more = f"; ... ({len(self.issues) - limit} more)" if len(self.issues) > limit else ""
        return f"{head} (nominal step {self.nominal_dt_s:.6g} s): {listed}{more}"

    def to_dict(self) -> dict:
        return {"n_rows": self.n_rows, "nominal_dt_s": self.nominal_dt_s,
                "gap_factor": self.gap_factor, "lost_s": self.lost_s,
                "issues": [i.to_dict() for i in self.issues],
                "segments": [[int(a), int(b)] for a, b in self.segments]}


def detect_gaps(t, *, gap_factor: float = GAP_FACTOR,
                nominal_dt_s: float | None = None) -> GapReport:
    """Find dropouts, repeated stamps and backward jumps in a time column.

    Parameters
    ----------
    t : array_like (n,)
        Time stamps, s.
    gap_factor : float, default 1.5
        A step longer than ``gap_factor * nominal`` is a gap.
    nominal_dt_s : float, optional
        Nominal sample interval, s (default: median of the positive steps).
    """
    t = np.asarray(t, dtype=float)
    n = t.size
    if gap_factor <= 1.0:
        raise InputError(f"gap factor must exceed 1, got {gap_factor}")
    if n < 2:
        return GapReport(n_rows=n, nominal_dt_s=float("nan"), segments=((0, n),),
                         gap_factor=gap_factor)
    dt = np.diff(t)
    pos = dt[dt > 0]
    nominal = float(nominal_dt_s) if nominal_dt_s is not None else (
        float(np.median(pos)) if pos.size else float("nan"))
    bad = (dt <= 0) | (dt > gap_factor * nominal)
    issues = []
    for k in np.flatnonzero(bad):
        step = float(dt[k])
        row = int(k) + 2  # sample k+1 (0-based) is data row k+2
        if step == 0:
            issues.append(TimeIssue("repeat", row, float(t[k]), float(t[k + 1]), 0.0))
        elif step < 0:
            issues.append(TimeIssue("backward", row, float(t[k]), float(t[k + 1]), step))
        else:
            miss = max(int(round(step / nominal)) - 1, 1)
            issues.append(TimeIssue("gap", row, float(t[k]), float(t[k + 1]),
                                    step - nominal, miss))
    cuts = np.flatnonzero(bad) + 1
    bounds = np.r_[0, cuts, n]
    segs = tuple((int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:]))
    return GapReport(n_rows=n, nominal_dt_s=nominal, issues=tuple(issues), segments=segs,
                     gap_factor=gap_factor)


def apply_gap_policy(df: pd.DataFrame, policy: str, *, time_column: str = "t_s", path=None,
                     gap_factor: float = GAP_FACTOR) -> tuple[pd.DataFrame, GapReport]:
    """Apply ``--gaps error|split`` to a log.

    ``"error"`` raises one :class:`InputError` listing the problems (rows, durations);
    ``"split"`` returns the frame with an int ``segment`` column (0-based; each segment
    has strictly increasing time without dropouts). Either way the report is returned
    (with ``"error"`` and no problem, the frame is returned unchanged).
    """
    if policy not in ("error", "split"):
        raise InputError(f"argument 'gaps' must be 'error' or 'split', got '{policy}'")
    if time_column not in df.columns:
        raise InputError("argument 'gaps' needs a time column", path=path, column=time_column)
    rep = detect_gaps(df[time_column].to_numpy(dtype=float), gap_factor=gap_factor)
    if rep.issues and policy == "error":
        raise InputError(f"{rep.summary()}; set argument 'gaps' to 'split' to analyse the segments",
                         path=path, column=time_column)
    if policy == "error":
        return df, rep
    out = df.copy()
    seg = np.zeros(len(df), dtype=np.int64)
    for i, (a, b) in enumerate(rep.segments):
        seg[a:b] = i
    out["segment"] = seg
    return out, rep


# ----------------------------------------------------------------------------- saturation

@dataclass(frozen=True)
class SaturationReport:
    """Samples at full scale.

    Attributes
    ----------
    mask : ndarray of bool (n,)
        True where any checked column is at full scale.
    counts : dict
        Column -> flagged samples.
    limits : dict
        Column -> the full-scale value used (``"auto"`` detection records the extreme).
    rows : tuple of int
        First flagged 1-based rows (at most 5).
    method : str
        ``"given"`` or ``"auto"``.
    """

    mask: np.ndarray
    counts: dict = field(default_factory=dict)
    limits: dict = field(default_factory=dict)
    rows: tuple[int, ...] = ()
    method: str = "given"

    @property
    def n_flagged(self) -> int:
        return int(self.mask.sum())

    def to_dict(self) -> dict:
        return {"n_flagged": self.n_flagged, "counts": dict(self.counts),
                "limits": dict(self.limits), "rows": list(self.rows), "method": self.method}


def _runs_at(x: np.ndarray, value: float, min_run: int) -> np.ndarray:
    hit = x == value
    if min_run <= 1:
        return hit
    edges = np.diff(np.r_[0, hit.astype(np.int8), 0])
    starts = np.flatnonzero(edges == 1)
    stops = np.flatnonzero(edges == -1)
    out = np.zeros_like(hit)
    for a, b in zip(starts, stops):
        if b - a >= min_run:
            out[a:b] = True
    return out


#: chance of a run as long by repeats alone, over the whole column, below which a run of
#: one value is a stuck sensor (:func:`stuck_run`)
STUCK_FALSE_ALARM = 1e-6
#: a shorter run (share of the column's samples) is left alone: it moves a variance
#: read over the whole column by less than this share
STUCK_MIN_SHARE = 0.01


def is_constant(x, *, empty: bool = False) -> bool:
    """Whether a sensor column's finite samples are all one value (a stuck or absent
    sensor: no noise to read); ``empty``: the answer for a column with no finite sample.

    >>> is_constant([2.0, 2.0, float("nan"), 2.0]), is_constant([2.0, 2.5])
    (True, False)
    >>> is_constant([float("nan")]), is_constant([float("nan")], empty=True)
    (False, True)
    """
    x = np.asarray(x, dtype=float)
    finite = x[np.isfinite(x)]
    return bool(empty) if not finite.size else not bool(np.ptp(finite) > 0)


def stuck_run(x, false_alarm: float = STUCK_FALSE_ALARM):
    """The longest run of one repeated value in ``x`` that its repeats cannot explain:
    ``(start, length, p_repeat)`` (0-based start, samples; ``p_repeat`` the fraction of
    consecutive pairs that repeat, the longest run left out), or None.

    A quantised sensor at rest repeats its last value now and then; if each pair repeats
    with probability ``p``, a run of ``L`` equal samples starts at a given sample with
    probability ``p**(L-1)``, so over ``n`` samples a run at least as long comes by chance
    with probability at most ``n p**(L-1)``. A run where that is below ``false_alarm``
    (default :data:`STUCK_FALSE_ALARM`) and that holds at least :data:`STUCK_MIN_SHARE`
    of the samples is a stuck sensor. NaNs break runs.

    Examples
    --------
    >>> import numpy as np
    >>> y = np.random.default_rng(0).normal(0.0, 1.0, 10_000).round(1)
    >>> stuck_run(y) is None
    True
    >>> y[4000:4500] = 0.05  # off the 0.1 grid: a run of exactly 500
    >>> stuck_run(y)[:2]
    (4000, 500)
    """
    x = np.asarray(x, dtype=float)
    if x.size < 3:
        return None
    same = (x[1:] == x[:-1]) & np.isfinite(x[1:])
    edges = np.diff(np.r_[0, same.astype(np.int8), 0])
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    if not starts.size:
        return None
    k = int(np.argmax(stops - starts))
    pairs = int(stops[k] - starts[k])  # repeated pairs in the longest run: length - 1
    if pairs + 1 < STUCK_MIN_SHARE * x.size:
        return None
    rest = same.size - pairs
    # the repeat rate without the run (Laplace's rule: never 0 from a few repeats)
    p = (int(same.sum()) - pairs + 1) / (rest + 2)
    if x.size * p ** pairs >= false_alarm:
        return None
    return int(starts[k]), pairs + 1, float(p)


def rails(suffix: str, meta: dict, scale_g: float, raw=None) -> tuple[float, float] | None:
    """A sensor's output rails ``(lo, hi)`` in the column's raw unit, or None when unknown.

    Counts (``suffix == "lsb"``): ``saturation_lsb`` (half range around ``lsb_offset``)
    when the sidecar gives it; otherwise 16-bit rails, signed (-32768, 32767) when every
    value of ``raw`` fits a signed word, else unsigned (0, 65535) when every value fits
    that, else none. SI units: ``range_g`` (0.999 of it; ``scale_g`` is one g in the
    column's unit).

    Examples
    --------
    >>> rails("lsb", {}, 1.0, [-120, 40, 17])
    (-32768.0, 32767.0)
    >>> rails("mps2", {"range_g": 2}, 9.80665)
    (-19.5936867, 19.5936867)
    """
    if suffix == "lsb":
        off = float(meta.get("lsb_offset", 0.0) or 0.0)
        if "saturation_lsb" in meta:
            s = float(meta["saturation_lsb"])
            return off - s, off + s - 1
        if raw is None:
            return None
        lo, hi = float(np.min(raw)), float(np.max(raw))
        if lo >= -32768 and hi <= 32767:
            return -32768.0, 32767.0
        if lo >= 0 and hi <= 65535:
            return 0.0, 65535.0
        return None
    if "range_g" in meta:
        lim = float(meta["range_g"]) * scale_g * 0.999
        return -lim, lim
    return None


def at_rails(values, limits) -> np.ndarray:
    """The one saturation test: True where a sample sits at or beyond a rail of
    ``limits = (lo, hi)``; for an ``(n, k)`` array, True for a row with any such value.

    Examples
    --------
    >>> at_rails([[0.0, 1.0], [2.0, -2.0], [0.5, 0.5]], (-2.0, 2.0)).tolist()
    [False, True, False]
    """
    x = np.asarray(values, dtype=float)
    hit = (x <= limits[0]) | (x >= limits[1])
    return hit if hit.ndim == 1 else np.any(hit, axis=1)


def detect_saturation(df: pd.DataFrame, columns, full_scale=None, *, min_run: int = 3,
                      rel_tol: float = 1e-9) -> SaturationReport:
    """Flag samples at the sensor's full-scale value.

    Parameters
    ----------
    df : DataFrame
    columns : sequence of str
        Measurement columns to check (missing ones are skipped).
    full_scale : dict, float or None
        Column -> full-scale magnitude in the column's unit (``|x| >= fs (1 - rel_tol)``
        is flagged), a single magnitude for every column, or None for ``"auto"``:
        a sample is flagged when it equals the column's maximum or minimum and sits in
        a run of at least ``min_run`` equal samples (a clipped, flat top).
    min_run : int, default 3
        Shortest flat run counted as clipping in auto mode.
    """
    cols = [c for c in columns if c in df.columns]
    n = len(df)
    mask = np.zeros(n, dtype=bool)
    counts, limits = {}, {}
    method = "auto" if full_scale is None else "given"
    for c in cols:
        x = df[c].to_numpy(dtype=float)
        if x.size == 0:
            continue
        if full_scale is None:
            hi, lo = float(np.nanmax(x)), float(np.nanmin(x))
            if hi == lo:
                continue
            f = _runs_at(x, hi, min_run) | _runs_at(x, lo, min_run)
            limits[c] = [lo, hi]
        else:
            fs = full_scale.get(c) if isinstance(full_scale, dict) else full_scale
            if fs is None:
                continue
            fs = abs(float(fs))
            if not np.isfinite(fs) or fs == 0:
                raise InputError(f"full-scale value must be finite and non-zero, got {fs}",
                                 column=c)
            f = at_rails(x, (-fs * (1.0 - rel_tol), fs * (1.0 - rel_tol)))
            limits[c] = fs
        if f.any():
            counts[c] = int(f.sum())
            mask |= f
    rows = tuple(int(r) + 1 for r in np.flatnonzero(mask)[:_LISTED])
    return SaturationReport(mask=mask, counts=counts, limits=limits, rows=rows, method=method)


def exclude_flagged(start, stop, mask, *, min_length: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """Cut index intervals ``[start, stop)`` around flagged samples.

    Each interval is split at the flagged samples it contains; pieces shorter than
    ``min_length`` are dropped. Returns the new ``(start, stop)`` arrays.
    """
    mask = np.asarray(mask, dtype=bool)
    ns, ne = [], []
    for a, b in zip(np.asarray(start, dtype=int), np.asarray(stop, dtype=int)):
        ok = ~mask[a:b]
        edges = np.diff(np.r_[0, ok.astype(np.int8), 0])
        for s, e in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
            if e - s >= min_length:
                ns.append(a + s)
                ne.append(a + e)
    return np.asarray(ns, dtype=int), np.asarray(ne, dtype=int)
