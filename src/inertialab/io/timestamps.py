"""Time stamps as they are: mean rate, jitter, gaps, dropped and repeated samples
(issue 16 item 3).

Real logs are not uniform: a USB IMU's stamps jitter by tens of microseconds, a bag
loses messages, a driver republishes one. :func:`audit` measures what is there, and
:func:`inertialab.io.read_record` puts its :class:`TimingAudit` in
``meta["timestamps"]`` (so every command's JSON carries the counts). Nothing is
changed unless asked: :func:`resample_uniform` puts a log on a uniform grid (linear
interpolation) only when the caller asks for it, and records that it did.

Definitions (the nominal step is the median positive step, as :mod:`inertialab.io.gaps`):

* ``mean_rate_hz`` = (n - 1) / (t_last - t_first), over the whole log;
* ``jitter_s`` = standard deviation of the steps that are neither gaps nor repeats;
  ``jitter_max_s`` the largest absolute deviation of such a step from nominal;
* a **gap** is a step longer than ``gap_factor`` (1.5) nominal steps; ``n_dropped`` is
  the number of samples missing in gaps, ``round(step / nominal) - 1`` summed;
* a **repeat** is a step of exactly zero (``n_repeated``), an **out-of-order** sample
  one whose step is negative (``n_out_of_order``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from inertialab.io.gaps import GAP_FACTOR, detect_gaps
from inertialab.limits import check_budget

__all__ = ["SampleSlots", "TimingAudit", "audit", "on_slots", "resample_uniform",
           "sample_slots"]

_LISTED = 20


@dataclass(frozen=True)
class TimingAudit:
    """What :func:`audit` measured (units in the names: s, Hz)."""

    n: int
    duration_s: float
    mean_rate_hz: float
    nominal_dt_s: float
    jitter_s: float
    jitter_max_s: float
    n_gaps: int
    n_dropped: int
    n_repeated: int
    n_out_of_order: int
    gaps: list = field(default_factory=list)

    @property
    def uniform(self) -> bool:
        return self.n_gaps == 0 and self.n_repeated == 0 and self.n_out_of_order == 0

    def to_dict(self) -> dict:
        return {"n": self.n, "duration_s": self.duration_s, "mean_rate_hz": self.mean_rate_hz,
                "nominal_dt_s": self.nominal_dt_s, "jitter_s": self.jitter_s,
                "jitter_max_s": self.jitter_max_s, "n_gaps": self.n_gaps,
                "n_dropped": self.n_dropped, "n_repeated": self.n_repeated,
                "n_out_of_order": self.n_out_of_order, "gaps": list(self.gaps)}


def audit(t, *, gap_factor: float = GAP_FACTOR) -> TimingAudit:
    """Measure the time stamps ``t`` (s, in the order recorded).

    Returns a :class:`TimingAudit`; ``gaps`` lists the first 20 gaps as
    ``{"row", "t_s", "duration_s", "missing"}`` (``row`` 1-based, the sample after the
    gap; ``duration_s`` the time lost beyond one nominal step).
    """
    t = np.asarray(t, dtype=float)
    n = int(t.size)
    if n < 2:
        return TimingAudit(n, 0.0, float("nan"), float("nan"), float("nan"), float("nan"),
                           0, 0, 0, 0)
    rep = detect_gaps(t, gap_factor=gap_factor)
    dt = np.diff(t)
    nominal = rep.nominal_dt_s
    span = float(t.max() - t.min())
    mean_rate = (n - 1) / span if span > 0 else float("nan")
    normal = (dt > 0) & (dt <= gap_factor * nominal)
    dev = dt[normal] - nominal
    jitter = float(np.std(dt[normal])) if normal.any() else float("nan")
    jmax = float(np.max(np.abs(dev))) if dev.size else float("nan")
    gaps = [i for i in rep.issues if i.kind == "gap"]
    return TimingAudit(
        n=n, duration_s=span, mean_rate_hz=float(mean_rate), nominal_dt_s=float(nominal),
        jitter_s=jitter, jitter_max_s=jmax, n_gaps=len(gaps),
        n_dropped=int(sum(i.missing for i in gaps)),
        n_repeated=int(np.count_nonzero(dt == 0)), n_out_of_order=int(np.count_nonzero(dt < 0)),
        gaps=[{"row": i.row, "t_s": i.t_before_s, "duration_s": i.duration_s,
               "missing": i.missing} for i in gaps[:_LISTED]])


@dataclass(frozen=True)
class SampleSlots:
    """Where each sample of a jittery, gappy log sits on its sensor's sample grid.

    ``index[i]`` is the grid slot of sample ``i`` (0 for the first; a step of ``k``
    nominal steps, rounded, advances ``k`` slots, so a dropout leaves ``k - 1`` empty
    slots); ``tau0_s`` the mean step per slot, span / last slot; ``jitter_rel`` and
    ``jitter_max_rel`` the rms and largest deviation of a step per slot from ``tau0_s``,
    relative to it."""

    index: np.ndarray
    tau0_s: float
    jitter_rel: float
    jitter_max_rel: float

    @property
    def n_slots(self) -> int:
        return int(self.index[-1]) + 1

    @property
    def n_missing(self) -> int:
        return self.n_slots - int(self.index.size)


def sample_slots(t) -> SampleSlots:
    """Grid slots of the samples stamped ``t`` (s, strictly increasing).

    A sensor samples on its own clock; a logger stamps the samples on arrival, so the
    stamps jitter around that grid and a lost packet shows as a step of several nominal
    steps. Each step advances ``round(step / nominal)`` slots (nominal: the median step),
    which follows a logger clock that runs slightly off the sensor's (a fixed nominal grid
    from the first stamp would drift by whole samples over a long log), and counts a
    step above 1.5 nominal steps as a dropout, as :mod:`inertialab.io.gaps`. Steps that
    are not positive are the caller's to refuse."""
    t = np.asarray(t, dtype=float)
    dt = np.diff(t)
    nominal = float(np.median(dt))
    slots = np.maximum(np.rint(dt / nominal), 1.0)
    index = np.concatenate([[0], np.cumsum(slots)]).astype(np.int64)
    tau0 = float(t[-1] - t[0]) / float(index[-1])
    rel = dt / slots / tau0 - 1.0
    return SampleSlots(index=index, tau0_s=tau0, jitter_rel=float(np.sqrt(np.mean(rel * rel))),
                       jitter_max_rel=float(np.max(np.abs(rel))))


def on_slots(values, index) -> np.ndarray:
    """``values`` (one per sample) placed at their grid slots ``index``
    (:attr:`SampleSlots.index`), NaN in the slots of lost samples (never interpolated)."""
    full = np.full(int(index[-1]) + 1, np.nan)
    full[index] = np.asarray(values, dtype=np.float64)
    return full


def resample_uniform(t, columns: dict, rate_hz: float, *, path=None) -> tuple[np.ndarray, dict]:
    """Linear interpolation of ``columns`` (name -> values at ``t``) onto
    ``t0 + k / rate_hz`` within ``[t0, t_last]``. ``t`` must increase strictly. A grid
    above the memory budget is refused before it is allocated (``path`` names the file)."""
    t = np.asarray(t, dtype=float)
    span = float(np.floor((t[-1] - t[0]) * rate_hz + 1e-9)) + 1  # samples, before allocating
    check_budget(span * 8 * (len(columns) + 2), f"resampling {t[-1] - t[0]:g} s at "
                 f"{rate_hz:g} Hz ({span:.0f} samples)", path)
    n = int(span)
    grid = t[0] + np.arange(n) / rate_hz
    return grid, {k: np.interp(grid, t, np.asarray(v, dtype=float)) for k, v in columns.items()}
