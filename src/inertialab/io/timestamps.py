"""Time stamps as they are (mean rate, jitter, gaps, dropped and repeated samples) and
the one time base of a record.

Real logs are not uniform: a USB IMU's stamps jitter by tens of microseconds, a bag
loses messages, a driver republishes one. :func:`audit` measures what is there, and
:func:`inertialab.io.read_record` puts its :class:`TimingAudit` in
``meta["timestamps"]`` (so every command's JSON carries the counts). Nothing is
changed unless asked: :func:`resample_uniform` puts a log on a uniform grid (linear
interpolation) only when the caller asks for it, and records that it did.

:func:`decide_timebase` decides a record's :class:`Timebase` (sample rate, tau0, grid
slots, jitter, lost samples, where the rate came from) once, when the record is read;
every analysis takes its rate from ``record.timebase`` and none derives one from the
stamps itself (docs/records.md "One time base"). The precedence:

1. ``rate_hz`` given by the caller (``--rate``): the samples are taken as uniform at
   that rate and the stamps are not used to place them;
2. the sidecar's (or header's) ``fs_hz``: the nominal rate; the stamps still place the
   samples on the grid (lost samples become NaN slots). A nominal rate that contradicts
   the stamps by more than :data:`RATE_CONTRADICTION` (relative) is an error naming both;
3. the time stamps: uniform stamps (every step within :data:`UNIFORM_TOL` of the
   median) give ``(n - 1) / span``; jittering or gappy stamps give the mean rate of the
   sensor's grid (:func:`sample_slots`), one ``DataQualityWarning`` with the figures,
   and lost samples as NaN slots (never interpolated).

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

import warnings
from dataclasses import dataclass, field

import numpy as np

from inertialab.errors import DataQualityWarning, InputError
from inertialab.io.gaps import GAP_FACTOR, detect_gaps
from inertialab.limits import check_budget

__all__ = ["RATE_CONTRADICTION", "UNIFORM_TOL", "SampleSlots", "Timebase", "TimingAudit",
           "audit", "decide_timebase", "on_slots", "resample_uniform", "sample_slots",
           "stamps_rate_hz"]

#: Stamps whose every step is within this fraction of the median step are uniform.
UNIFORM_TOL = 1e-6
#: A nominal rate (sidecar ``fs_hz``) further than this, relative, from the rate of the
#: stamps contradicts them (a clock 10 % off its nominal rate is no clock).
RATE_CONTRADICTION = 0.1

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


@dataclass(frozen=True)
class Timebase:
    """The one time base of a record (decided by :func:`decide_timebase` on reading).

    Attributes
    ----------
    rate_hz : float
        Sample rate, Hz (``1 / tau0_s``).
    source : {"argument", "sidecar", "timestamps", "resampled"}
        Where the rate came from.
    n_samples : int
        Samples in the record.
    index : ndarray of int or None
        Grid slot of each sample when some are lost (a step of ``k`` nominal steps
        advances ``k`` slots); None when every sample has its own consecutive slot.
    jitter_rel, jitter_max_rel : float
        RMS and largest deviation of a step per slot from ``tau0_s``, relative to it
        (NaN without time stamps, 0 for uniform stamps).
    n_gaps : int
        Steps longer than 1.5 nominal steps.
    stamps_rate_hz : float
        The rate the time stamps alone give (NaN without stamps).
    back_rows : tuple of int
        1-based rows whose stamp repeats or goes back (only a log split into segments
        keeps them); such samples cannot be placed on one grid.
    """

    rate_hz: float
    source: str
    n_samples: int
    index: np.ndarray | None = None
    jitter_rel: float = float("nan")
    jitter_max_rel: float = float("nan")
    n_gaps: int = 0
    stamps_rate_hz: float = float("nan")
    back_rows: tuple = ()

    @property
    def tau0_s(self) -> float:
        """Sampling interval, s."""
        return 1.0 / self.rate_hz

    @property
    def n_slots(self) -> int:
        """Slots of the grid from the first to the last sample."""
        return self.n_samples if self.index is None else int(self.index[-1]) + 1

    @property
    def n_missing(self) -> int:
        """Samples lost in gaps (empty grid slots)."""
        return self.n_slots - self.n_samples

    def place(self, values) -> np.ndarray:
        """``values`` (one per sample) on the grid, NaN in the slots of lost samples
        (returned unchanged when none is lost)."""
        if self.index is None:
            return values
        return on_slots(values, self.index)

    def to_dict(self) -> dict:
        return {"rate_hz": self.rate_hz, "tau0_s": self.tau0_s, "source": self.source,
                "n_samples": self.n_samples, "n_slots": self.n_slots,
                "n_missing": self.n_missing, "n_gaps": self.n_gaps,
                "jitter_rel": self.jitter_rel, "jitter_max_rel": self.jitter_max_rel,
                "stamps_rate_hz": self.stamps_rate_hz}


def _from_stamps(t: np.ndarray):
    """(rate, index or None, jitter_rel, jitter_max_rel, n_gaps, back rows) of stamps."""
    dt = np.diff(t)
    back = np.flatnonzero(dt <= 0)
    if back.size:
        pos = dt[dt > 0]
        step = float(np.median(pos)) if pos.size else float("nan")
        return 1.0 / step, None, float("nan"), float("nan"), 0, \
            tuple(int(i) + 2 for i in back[:5])
    step = float(np.median(dt))
    if np.all(np.abs(dt - step) <= UNIFORM_TOL * step):
        return (t.size - 1) / (float(t[-1]) - float(t[0])), None, 0.0, 0.0, 0, ()
    sl = sample_slots(t)
    n_gaps = int(np.count_nonzero(np.diff(sl.index) > 1))
    return (1.0 / sl.tau0_s, sl.index if sl.n_missing else None, sl.jitter_rel,
            sl.jitter_max_rel, n_gaps, ())


def stamps_rate_hz(t) -> float:
    """The sample rate, Hz, that the time stamps ``t`` (s, at least two) alone give: the
    rate :func:`decide_timebase` takes from stamps (step 3 of the module's text: uniform
    stamps ``(n - 1) / span``; jittering or gappy ones the mean rate of the sensor's grid,
    :func:`sample_slots`; stamps that go back ``1 / median`` positive step, NaN when no
    step is positive). No warning. For an array-level call that has stamps and no record;
    a record's rate is ``record.timebase.rate_hz``.

    Examples
    --------
    >>> import numpy as np
    >>> stamps_rate_hz(np.arange(101) / 100.0)
    100.0
    >>> t = np.r_[np.arange(50), np.arange(52, 100)] / 100.0  # two samples lost
    >>> round(stamps_rate_hz(t), 9)
    100.0
    """
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise InputError(f"a rate needs at least two time stamps, got {t.size}", column="t_s")
    return float(_from_stamps(t)[0])


def decide_timebase(t, *, n: int, rate_hz: float | None = None,
                    nominal_hz: float | None = None, path=None) -> Timebase | None:
    """The time base of a record of ``n`` samples (the precedence in the module's text).

    ``t``: time stamps, s (None when the record has none); ``rate_hz``: the caller's
    rate (``--rate``); ``nominal_hz``: the sidecar's ``fs_hz``. Returns None when there
    is neither a rate nor time stamps. Warns once (``DataQualityWarning``) with the
    figures when stamps that place the samples jitter or lose samples; raises an
    :class:`InputError` naming both rates when the nominal rate contradicts the stamps.
    """
    where = f"{path}: " if path else ""
    stamps = None
    if t is not None and np.asarray(t).size >= 2:
        t = np.asarray(t, dtype=float)
        stamps = _from_stamps(t)
    if rate_hz is not None:
        return Timebase(float(rate_hz), "argument", n,
                        stamps_rate_hz=stamps[0] if stamps else float("nan"))
    if stamps is None:
        if nominal_hz is None:
            return None
        return Timebase(float(nominal_hz), "sidecar", n)
    rate, index, jit, jmax, n_gaps, back = stamps
    source = "timestamps"
    if nominal_hz is not None:
        if not abs(rate / float(nominal_hz) - 1.0) <= RATE_CONTRADICTION:
            raise InputError(f"the sidecar's fs_hz = {float(nominal_hz):.6g} Hz contradicts the "
                             f"time stamps ({rate:.6g} Hz, median step "
                             f"{1.0 / rate:.6g} s); correct fs_hz, or give argument "
                             "'rate_hz' to set the rate", path=path, column="t_s")
        rate, source = float(nominal_hz), "sidecar"
    tb = Timebase(rate, source, n, index=index, jitter_rel=jit, jitter_max_rel=jmax,
                  n_gaps=n_gaps, stamps_rate_hz=stamps[0], back_rows=back)
    if not back and (jmax > UNIFORM_TOL or index is not None):
        jit_text = (f"time stamps jitter by {100 * jit:.2g} % rms, up to "
                    f"{100 * jmax:.2g} %, of the {1.0 / stamps[0]:.6g} s step"
                    if jmax > UNIFORM_TOL else
                    f"time stamps on a {1.0 / stamps[0]:.6g} s step apart from dropouts")
        rows = _off_rows(t)
        msg = (f"{where}column 't_s': {jit_text} (e.g. rows {', '.join(map(str, rows))}): "
               f"the samples are taken on a uniform grid at {tb.rate_hz:.6g} Hz ("
               + ("the mean rate; argument 'rate_hz' sets it)" if source == "timestamps"
                  else "the sidecar's fs_hz)"))
        if tb.n_missing:
            msg += (f"; {tb.n_missing} sample(s) lost in steps longer than 1.5 nominal steps "
                    "are missing on that grid (gap-resistant statistics, never interpolated)")
        warnings.warn(msg, DataQualityWarning, stacklevel=4)
    return tb


def _off_rows(t: np.ndarray) -> list[int]:
    """The first 1-based rows whose step is off the median step."""
    dt = np.diff(t)
    step = float(np.median(dt))
    return [int(i) + 2 for i in np.flatnonzero(np.abs(dt - step) > UNIFORM_TOL * step)[:5]]
