"""The checks a command runs on a record before computing, one function per kind, so
that ``inertialab validate FILE --kind K`` and the commands of kind K cannot disagree.

A kind is a record kind (``gyro_log``, ``triaxial_raw`` ...) or the kind of an analysis
(``allan``, ``imu``, ``vibration``, ``ferraris``); :data:`KINDS` maps each to the record
kind it reads and what it needs. :func:`preflight` raises the one-line
:class:`~inertialab.errors.InputError` naming the real cause (no time column: "needs a
t_s column or argument 'rate_hz'", not a missing column of another kind), the same
error the command gives, because the command calls it too:

* every continuous log (``gyro_log``, ``allan``, ``imu``, ``vibration``,
  ``triaxial_raw``, ``ferraris``, ``clock_log``): a time base (time stamps, the sidecar's
  ``fs_hz`` or the rate option; :mod:`inertialab.io.timestamps`);
* ``allan``, ``imu``, ``ferraris``: stamps that do not repeat or go back;
* ``imu``: one or more IMU axis columns (``gx gy gz ax ay az``), one segment, and the
  magnitudes of a sensor at rest in the declared units
  (:func:`inertialab.io.unit_check.check_static_units`);
* ``vibration``: a rate or angle-increment column, ``vib_on``, and a contiguous log
  (no lost samples);
* ``ferraris``: the gyro triad ``gx gy gz`` beside the accelerometer;
* ``triaxial`` (a raw log for ``triaxial fit``): the accelerometer triad and an initial
  rest (:func:`inertialab.io.rest.initial_rest`, the test the static-interval detector
  runs with its default threshold sweep; with an absolute threshold the fit needs none).

Columns, units and values (:mod:`inertialab.io.schemas`, :mod:`inertialab.io.unit_check`)
are checked by :func:`inertialab.io.read_record` for every kind. The analysis kinds are
the workflows' knowledge, so this module is a workflow (it was ``inertialab.io.preflight``,
which still imports, with a DeprecationWarning, for one release).
"""

from __future__ import annotations

from dataclasses import dataclass

from inertialab.errors import InputError
from inertialab.io.schemas import SCHEMAS

__all__ = ["KINDS", "Kind", "check_length", "check_varying", "preflight", "read_for"]


@dataclass(frozen=True)
class Kind:
    """What a kind reads and needs."""

    record_kind: str
    description: str
    time_base: bool = False
    ordered: bool = False
    contiguous: bool = False
    needs: tuple = ()  # groups of column bases, at least one of each group present
    single_segment: bool = False
    missing: str = ""  # the message when a group of ``needs`` is absent (default: generic)
    initial_rest: bool = False  # the log must start with the sensor at rest
    static: bool = False  # a log at rest: magnitudes within a static sensor's (units)
    min_samples: int = 0  # fewest samples the analysis can read anything from
    varying: bool = False  # some measurement column must vary (constant data: nothing)


_IMU = ("gx", "gy", "gz", "ax", "ay", "az")

KINDS: dict[str, Kind] = {
    **{k: Kind(k, s.description, time_base=s.time_order == "strict" and s.time_column == "t_s")
       for k, s in SCHEMAS.items()},
    "allan": Kind("gyro_log", "a rate, angle or acceleration log for the Allan family",
                  time_base=True, ordered=True, varying=True),
    "imu": Kind("gyro_log", "an IMU log for the noise parameters of each axis",
                time_base=True, ordered=True, needs=(_IMU,), single_segment=True,
                static=True, min_samples=100, varying=True,
                missing="no IMU axis columns (gx_*, gy_*, gz_*, ax_*, ay_*, az_*); map them "
                        "with a column map (argument 'column_map')"),
    "vibration": Kind("gyro_log", "a vibration run (P1 static, P2 shaker on, P3 static)",
                      time_base=True, contiguous=True, needs=(("rate", "dtheta"), ("vib_on",))),
    "ferraris": Kind("triaxial_raw", "a Ferraris session (six faces and three turns)",
                     time_base=True, ordered=True, needs=(("gx",), ("gy",), ("gz",))),
    "triaxial": Kind("triaxial_raw", "a raw log of static poses for triaxial fit",
                     time_base=True, ordered=True, needs=(("ax",), ("ay",), ("az",)),
                     initial_rest=True),
}


def _has(record, base: str) -> bool:
    return record.find(base) is not None or base in record.data.columns \
        or base in record.arrays


def preflight(record, kind: str) -> None:
    """Raise the :class:`InputError` of the first check of ``kind`` the record fails."""
    if kind not in KINDS:
        raise InputError(f"unknown kind '{kind}' (known: {', '.join(KINDS)})")
    k = KINDS[kind]
    path = record.path
    if k.record_kind != record.kind:
        raise InputError(f"a {kind} analysis reads a {k.record_kind} record, got a "
                         f"{record.kind} record", path=path)
    tb = record.timebase
    if k.time_base and tb is None:
        raise InputError("needs a t_s column or argument 'rate_hz'", path=path)
    if k.ordered and tb is not None and tb.back_rows and tb.source != "argument":
        raise InputError("time stamps repeat or go back; the samples cannot be placed in time "
                         "(set argument 'gaps' to 'split' and analyse a segment, or give "
                         "argument 'rate_hz' to ignore t_s)", path=path, column="t_s",
                         row=list(tb.back_rows))
    if k.contiguous and tb is not None and (tb.n_missing or tb.back_rows) \
            and tb.source != "argument":
        raise InputError(f"{tb.n_missing} sample(s) lost in gaps or stamps that go back: "
                         f"{k.description} needs a contiguous log", path=path, column="t_s")
    for group in k.needs:
        if not any(_has(record, b) for b in group):
            if k.missing:
                raise InputError(k.missing, path=path)
            shown = ", ".join(f"{b}_<unit>" if b != "vib_on" else b for b in group)
            raise InputError(f"{k.description} needs the column{'s' if len(group) > 1 else ''} "
                             f"{shown if len(group) == 1 else 'one of ' + shown}", path=path,
                             column=group[0] if len(group) == 1 else None)
    if k.initial_rest and "t_s" in record.data.columns:
        from inertialab.io.rest import initial_rest

        acc = record.data[[record.find(b) for b in ("ax", "ay", "az")]].to_numpy(dtype=float)
        initial_rest(record.column("t_s"), acc, path=path)
    if k.single_segment and "segment" in record.data.columns \
            and record.data["segment"].nunique() > 1:
        raise InputError("the log has several segments (argument 'gaps' split); analyse one "
                         "segment", path=path)
    check_length(record, kind)
    if k.varying:
        check_varying(record, kind)
    if k.static:
        from inertialab.io.unit_check import check_static_units

        check_static_units(record)


#: dimensions of the columns an Allan analysis reads; temperatures, voltages and times
#: beside them are context, not a signal
_MEASURED = ("angular_rate", "acceleration", "angle", "counts")


def _analysed(record, kind: str | None) -> list[str]:
    """The unit columns ``kind``'s analysis reads: the six axes for ``imu``, else those of
    a rate, acceleration, angle or count unit (all unit columns when none is)."""
    from inertialab import units

    cols = [c for c in (record.units or {}) if c in record.data.columns and c != "t_s"]
    if kind == "imu":
        return [c for c in cols if units.split_suffix(c)[0] in _IMU]

    def measured(c) -> bool:
        try:
            return units.dimension(record.units[c]) in _MEASURED
        except (InputError, KeyError, ValueError):
            return True  # a unit this table does not know: the analysis decides
    return [c for c in cols if measured(c)] or cols


def check_varying(record, kind: str | None = None) -> None:
    """Refuse a log whose every analysed column (:func:`_analysed`) is constant (a stuck
    or absent sensor: nothing to analyse, however much a temperature column beside it
    varies), as the analyses do; one constant column among varying ones is the
    analysis's to flag."""
    import numpy as np

    cols = _analysed(record, kind)
    if not cols:
        return
    for c in cols:
        v = np.asarray(record.data[c], dtype=float)
        v = v[np.isfinite(v)]
        if v.size and np.ptp(v) > 0:
            return
    raise InputError("data are constant in every analysed column (" + ", ".join(cols)
                     + "); nothing to analyse", path=record.path)


def check_length(record, kind: str) -> None:
    """Refuse a record shorter than what ``kind``'s analysis can read anything from
    (``imu``: 100 samples, a few octaves of tau for the noise terms)."""
    need = KINDS[kind].min_samples
    n = len(record.data)
    if n < need:
        raise InputError(f"too few samples for {KINDS[kind].description}: {n}, need at least "
                         f"{need}", path=record.path)


def read_for(path, kind: str, **read_args):
    """:func:`inertialab.io.read_record` of the record kind ``kind`` reads, then
    :func:`preflight` (what ``validate --kind`` runs)."""
    from inertialab.io.readers import read_record

    if kind not in KINDS:
        raise InputError(f"unknown kind '{kind}' (known: {', '.join(KINDS)})")
    rec = read_record(path, KINDS[kind].record_kind, **read_args)
    preflight(rec, kind)
    return rec
