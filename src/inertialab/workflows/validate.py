"""``validate FILE --kind KIND`` as one call: read a file as a record of a kind (or for
an analysis: ``allan``, ``imu``, ``vibration``, ``ferraris``), run the checks its
commands run before computing (:func:`inertialab.workflows.preflight.read_for`) and report its
columns, units, size, time base (Hz, s) and time stamps, or the first problem as one
line naming the file, column and row.
"""

from __future__ import annotations

from dataclasses import dataclass

from inertialab.result import ResultBase

__all__ = ["ValidationResult", "run"]

_SOURCE = {"argument": "rate option", "sidecar": "sidecar fs_hz"}


def _unit_of(column: str) -> str:
    """The unit a fixed column's name carries (``t_s`` -> s, ``temp_c`` -> c), else ''."""
    from inertialab.units import SUFFIXES, split_suffix

    suf = split_suffix(column)[1]
    return suf if suf in SUFFIXES else ""


@dataclass
class ValidationResult(ResultBase):
    """The record read and checked (:class:`~inertialab.io.Record`) as ``kind``."""

    rec: object
    file: str
    kind: str
    settings: dict
    units = {}

    def columns(self) -> list:
        return list(self.rec.arrays) + list(self.rec.data.columns)

    def to_json(self) -> dict:
        rec = self.rec
        return {"kind": rec.kind, "checked_as": self.kind, "rows": rec.n,
                "columns": self.columns(), "column_units": rec.units, "meta": rec.meta,
                "timestamps": rec.meta.get("timestamps"),
                "timebase": rec.timebase.to_dict() if rec.timebase else None,
                "sha256": rec.sha256}

    def artifacts(self) -> dict:
        return {}

    def summary_rows(self) -> list:
        rec, tb, ts = self.rec, self.rec.timebase, self.rec.meta.get("timestamps")
        out = [f"{self.file}: valid {self.kind} record ({rec.kind}), {rec.n} rows",
               (None, ["column", "unit"], [[c, rec.units.get(c, "") or _unit_of(c)]
                                            for c in self.columns()])]
        if tb is not None:
            out.append(f"time base: {tb.rate_hz:.6g} Hz (tau0 {tb.tau0_s:.6g} s, from the "
                       f"{_SOURCE.get(tb.source, tb.source)}), {tb.n_missing} samples lost "
                       "on its grid")
        if ts and ts.get("n", 0) > 1:
            out.append(f"time stamps: {ts['mean_rate_hz']:.6g} Hz mean over the kept samples, "
                       f"jitter {ts['jitter_s']:.3g} s, {ts['n_gaps']} gaps "
                       f"({ts['n_dropped']} samples dropped), {ts['n_repeated']} repeated, "
                       f"{ts['n_out_of_order']} out of order")
        return out


def run(file, kind: str, read) -> ValidationResult:
    """Read ``file`` as ``kind`` with the reading options ``read``
    (:class:`~inertialab.io.mapping.ReadOptions`) and check it."""
    from inertialab.workflows.preflight import read_for

    rec = read_for(file, kind, options=read)
    return ValidationResult(rec=rec, file=str(file), kind=kind, settings={
        "kind": kind, "unit": read.unit, "rate_hz": read.rate_hz, **read.settings()})
