"""The ``vibration`` workflow's input step (spec 001 §2.2): a ``gyro_log`` record (or a
bare frame) checked and segmented into a
:class:`~inertialab.calib.vibration.VibrationRun` (rate in deg/h, P1 / P2 / P3 from
``vib_on``, the drive frequency in Hz). Every check fails with one line naming the file,
column and rows; :mod:`inertialab.workflows.vibration` re-exports :func:`prepare`,
:func:`load_run` and :func:`run_from_frame`.
"""

from __future__ import annotations

import warnings

import numpy as np

from inertialab import units
from inertialab.calib.vibration import VibrationRun
from inertialab.errors import DataQualityWarning, InputError

__all__ = ["load_run", "prepare", "run_from_frame"]


def _bad_rows(mask: np.ndarray) -> list[int]:
    return (np.flatnonzero(mask)[:5] + 1).tolist()


def _contiguous_timebase(df, cols: dict, meta: dict, path: str, timebase):
    """The record's time base (decided once in io), or for a bare frame the one of
    ``t_s`` and the sidecar ``fs_hz``; refused with lost samples or stamps going back."""
    if timebase is None:
        from inertialab.io.timestamps import decide_timebase

        t = np.asarray(df[cols["t_s"]], dtype=float) if "t_s" in cols else None
        timebase = decide_timebase(t, n=len(df), nominal_hz=meta.get("fs_hz"), path=path)
    if timebase is None:
        raise InputError("needs a t_s column or the sidecar key fs_hz", path=path)
    if timebase.n_missing or timebase.back_rows:
        raise InputError(f"{timebase.n_missing} sample(s) lost in gaps or stamps that go back: "
                         "the vibration analysis needs a contiguous log", path=path,
                         column="t_s")
    return timebase


def _signal_column(cols: dict, path: str) -> tuple[str, bool]:
    """The rate column (``rate_*``; True) or else the angle increments (``dtheta_*``)."""
    for prefix in ("rate_", "dtheta_"):
        name = next((c for c in cols if c.startswith(prefix) and units.split_suffix(c)[1]),
                    None)
        if name is not None:
            return name, prefix == "rate_"
    raise InputError("needs a rate column (e.g. rate_dph) or angle increments "
                     "(dtheta_arcsec)", path=path)


def _rate_dph(df, cols: dict, column: tuple[str, bool], units_map: dict | None, path: str,
              tau0_s: float) -> np.ndarray:
    """The rate in deg/h from a ``rate_*`` column or ``dtheta_*`` increments / tau0."""
    name, is_rate = column
    suf = (units_map or {}).get(cols[name]) or units.split_suffix(name)[1]
    raw = np.asarray(df[cols[name]], dtype=float)
    x = (units.convert(raw, suf, "dph") if is_rate else
         units.convert(raw, suf, "arcsec") / tau0_s)
    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        raise InputError("NaN or infinite rate values", path=path, column=cols[name],
                         row=_bad_rows(~np.isfinite(x)))
    return x


def _vibration_block(df, cols: dict, path: str) -> tuple[np.ndarray, int, int]:
    """``vib_on`` as booleans and the first/last vibrating sample: one contiguous block
    after a static phase."""
    if "vib_on" not in cols:
        raise InputError("record has no vibration phases: column vib_on is missing "
                         "(1 while the shaker drives, else 0)", path=path, column="vib_on")
    on_raw = np.asarray(df[cols["vib_on"]], dtype=float)
    if not np.all(np.isin(on_raw, (0.0, 1.0))):
        raise InputError("vib_on must be 0 or 1", path=path, column="vib_on",
                         row=_bad_rows(~np.isin(on_raw, (0.0, 1.0))))
    on = on_raw == 1.0
    if not on.any():
        raise InputError("record has no vibration phase (vib_on is never 1)", path=path,
                         column="vib_on")
    idx = np.flatnonzero(on)
    k_on, k_off = int(idx[0]), int(idx[-1])
    if idx.size != k_off - k_on + 1:
        gaps = np.flatnonzero(~on[k_on:k_off + 1]) + k_on
        raise InputError("vibration must be one contiguous block (P1 static, P2 vibration, "
                         "P3 static); vib_on drops to 0 inside it", path=path, column="vib_on",
                         row=(gaps[:5] + 1).tolist())
    if k_on == 0:
        raise InputError("no static phase before vibration (P1 is empty): the reference bias "
                         "needs one", path=path, column="vib_on")
    return on, k_on, k_off


def _drive_frequency(df, cols: dict, on: np.ndarray, path: str) -> np.ndarray:
    """``vib_freq_hz``: > 0 exactly where ``vib_on = 1``, 0 elsewhere."""
    if "vib_freq_hz" not in cols:
        raise InputError("column vib_freq_hz (drive frequency, Hz) is missing", path=path,
                         column="vib_freq_hz")
    f = np.asarray(df[cols["vib_freq_hz"]], dtype=float)
    badf = on & ~(np.isfinite(f) & (f > 0))
    if badf.any():
        raise InputError("drive frequency missing or <= 0 while vibrating", path=path,
                         column="vib_freq_hz", row=_bad_rows(badf))
    bad_off = ~on & ~(f == 0)
    if bad_off.any():
        raise InputError("drive frequency must be 0 while vib_on = 0", path=path,
                         column="vib_freq_hz", row=_bad_rows(bad_off))
    return f


def _check_phase_column(df, cols: dict, on: np.ndarray, k_on: int, path: str) -> None:
    """An optional ``phase`` column must run 1 -> 2 -> 3 in step with ``vib_on``."""
    if "phase" not in cols:
        return
    ph = np.asarray(df[cols["phase"]], dtype=float)
    expect = np.where(np.arange(on.size) < k_on, 1, np.where(on, 2, 3))
    badp = ph != expect
    if badp.any():
        raise InputError("phase must run 1 -> 2 -> 3 and equal 2 exactly where vib_on = 1",
                         path=path, column="phase", row=_bad_rows(badp))


def run_from_frame(df, meta: dict | None = None, *, path="<frame>", sha256: str = "",
                   units_map: dict | None = None, timebase=None) -> VibrationRun:
    """Validate a record frame for the vibration pipeline (spec 001 §2.2 loader checks).

    Checks: a rate column (``rate_*``, converted to deg/h) or angle increments
    (``dtheta_*``, rate = dtheta/tau0); the time base (``timebase``, the record's; for a
    bare frame decided from ``t_s`` and the sidecar ``fs_hz`` by
    :func:`inertialab.io.timestamps.decide_timebase`) without lost samples; no NaN;
    ``vib_on`` present with one contiguous block of 1s after a static phase;
    ``vib_freq_hz > 0`` exactly where ``vib_on = 1``; ``phase`` (if given) 1 -> 2 -> 3
    and consistent with ``vib_on``.

    Raises
    ------
    InputError
        Naming the file, column and rows.
    """
    meta = dict(meta or {})
    path = str(path)
    cols = {c.lower(): c for c in df.columns}
    column = _signal_column(cols, path)
    timebase = _contiguous_timebase(df, cols, meta, path, timebase)
    x = _rate_dph(df, cols, column, units_map, path, timebase.tau0_s)
    on, k_on, k_off = _vibration_block(df, cols, path)
    f = _drive_frequency(df, cols, on, path)
    _check_phase_column(df, cols, on, k_on, path)
    if k_off + 1 >= x.size:
        warnings.warn(f"{path}: record ends while vibrating (no P3); P3 rows are omitted",
                      DataQualityWarning, stacklevel=2)
    return VibrationRun(rate_dph=x, vib_on=on, freq_hz=np.where(on, f, 0.0),
                        fs_hz=float(timebase.rate_hz), k_on=k_on, k_off=k_off, path=path,
                        sha256=sha256, experiment=meta.get("experiment"), meta=meta)


def prepare(record) -> VibrationRun:
    """A ``gyro_log`` :class:`~inertialab.io.Record` validated and segmented for the
    pipeline (:func:`run_from_frame`)."""
    from inertialab.workflows.preflight import preflight

    preflight(record, "vibration")  # the checks `validate --kind vibration` runs
    return run_from_frame(record.data, record.meta, path=record.path, sha256=record.sha256,
                          timebase=record.timebase, units_map=record.units)


def load_run(path, *, options=None) -> VibrationRun:
    """Read a ``gyro_log`` record (``options``: :class:`~inertialab.io.mapping.ReadOptions`)
    and :func:`prepare` it."""
    from inertialab.io import read_record

    return prepare(read_record(path, "gyro_log", options=options))
