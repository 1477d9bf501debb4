"""Several calibration methods on one session, side by side (spec 002 §5).

From the user's own data, what the paper shows for its simulation, turntable and six-face
tests:

- :func:`parameter_table`: the fitted parameters of every method with their standard
  errors and 95 % t-intervals (the paper's Tables 3-6 estimates per method, Tables 8-9
  lab vs ACS, Tables 11-12 six-face results; their numbers were images, §5);
- :func:`pose_error_table`: every pose's error under every method: spec 002 eq. 21
  vector error ``|r_l - a_cal,l|`` when the records have references (face labels,
  turntable angles; S12 scored in the sensor frame as in :func:`quality`), and the
  field-mode ``|a_cal| - g`` always (the paper's Fig. 8, six-face error comparison);
- :func:`error_summary`: RMSE, SD, mean and max of those errors per method (Table 10's
  RMSE/SD, through :mod:`inertialab.metrics`);
- :func:`markdown`: a DataFrame as a GitHub Markdown table.

All numbers come from :func:`~inertialab.calib.triaxial_session.quality` and the fits
themselves; nothing is recomputed differently here.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from inertialab.calib.triaxial_session import CalibrationRun, quality
from inertialab.metrics import rmse
from inertialab.sensors import triaxial as tx

__all__ = ["error_summary", "markdown", "parameter_table", "pose_error_table"]


def _units(run: CalibrationRun) -> dict:
    work = "lsb" if run.data.counts else "m/s^2"
    k = "lsb per m/s^2" if run.data.counts else "1"
    return {"bx": work, "by": work, "bz": work, "kx": k, "ky": k, "kz": k,
            "theta_yz": "rad", "theta_zy": "rad", "theta_zx": "rad",
            "phi_x": "rad", "phi_y": "rad", "phi_z": "rad"}


def parameter_table(runs: dict[str, CalibrationRun], *, level: float = 0.95) -> pd.DataFrame:
    """Long table: one row per method and parameter.

    Columns ``method, objective, parameter, value, stderr, ci95_low, ci95_high, unit``
    (``stderr`` and the interval are NaN where the fit gives none). ``value`` is the
    fitted ``x`` (and ``phi`` for S12) exactly; the interval is ``value -+ t * stderr`` of
    :func:`quality` at ``level``.
    """
    rows = []
    for name, run in runs.items():
        fit = run.fit
        names = list(tx.PARAM_NAMES) + (list(tx.PHI_NAMES) if fit.phi is not None else [])
        values = np.r_[fit.x, fit.phi] if fit.phi is not None else np.asarray(fit.x)
        se = [np.nan] * len(names) if fit.stderr is None else \
            [np.nan if s is None else float(s) for s in fit.stderr]
        ci = quality(run, level=level)["ci95"]
        unit = _units(run)
        for n, v, s in zip(names, values, se):
            lo, hi = ci.get(n, (np.nan, np.nan))
            rows.append({"method": name, "objective": fit.objective, "parameter": n,
                         "value": float(v), "stderr": s, "ci95_low": lo, "ci95_high": hi,
                         "unit": unit[n]})
    return pd.DataFrame(rows, columns=["method", "objective", "parameter", "value", "stderr",
                                       "ci95_low", "ci95_high", "unit"])


def _labels(run: CalibrationRun) -> list[str]:
    """Pose labels: the face (``+x`` ...) when the reference is a nominal face, else pos_id."""
    data = run.data
    pos = np.arange(1, len(data.a) + 1) if data.pos_id is None else np.asarray(data.pos_id)
    out = [str(p) for p in pos]
    if data.ref is not None and np.all(np.isfinite(data.ref)) and len(data.ref) == 6:
        u = data.ref / np.linalg.norm(data.ref, axis=1)[:, None]
        k = np.argmax(np.abs(u), axis=1)
        if np.allclose(np.abs(u[np.arange(6), k]), 1.0, atol=1e-9):
            out = [f"{'+' if u[i, k[i]] > 0 else '-'}{'xyz'[k[i]]}" for i in range(6)]
    return out


def pose_error_table(runs: dict[str, CalibrationRun]) -> pd.DataFrame:
    """Long table: one row per method and pose.

    Columns ``method, pose, norm_error_mps2`` (``|a_cal| - g``) and, when the records
    have references, ``vector_error_mps2`` (eq. 21), as :func:`quality` reports them.
    """
    rows = []
    for name, run in runs.items():
        labels = _labels(run)
        for lab, p in zip(labels, quality(run)["per_pose"]):
            row = {"method": name, "pose": lab, "norm_error_mps2": p["norm_error_mps2"]}
            if "vector_error_mps2" in p:
                row["vector_error_mps2"] = p["vector_error_mps2"]
            rows.append(row)
    return pd.DataFrame(rows)


def error_summary(poses: pd.DataFrame) -> pd.DataFrame:
    """Per method: RMSE, SD (ddof 1), mean and max |.| of each error column of
    :func:`pose_error_table` (the eq.-21 statistics of Table 10), m/s^2."""
    rows = []
    for name, grp in poses.groupby("method", sort=False):
        row = {"method": name, "poses": int(len(grp))}
        for col, tag in (("vector_error_mps2", "eq21"), ("norm_error_mps2", "norm")):
            if col not in grp or grp[col].isna().all():
                continue
            e = grp[col].to_numpy(dtype=float)
            row[f"{tag}_rmse_mps2"] = rmse(np.zeros_like(e), e)
            row[f"{tag}_sd_mps2"] = float(np.std(e, ddof=1)) if e.size > 1 else np.nan
            row[f"{tag}_mean_mps2"] = float(np.mean(e))
            row[f"{tag}_max_abs_mps2"] = float(np.max(np.abs(e)))
        rows.append(row)
    return pd.DataFrame(rows)


def markdown(df: pd.DataFrame, *, digits: int = 6) -> str:
    """A DataFrame as a GitHub Markdown table (numbers with ``digits`` significant digits,
    NaN as an empty cell)."""
    def cell(v) -> str:
        if isinstance(v, (float, np.floating)):
            return "" if not np.isfinite(v) else f"{v:.{digits}g}"
        return str(v)

    head = "| " + " | ".join(str(c) for c in df.columns) + " |"
    sep = "|" + "|".join("---" for _ in df.columns) + "|"
    body = ["| " + " | ".join(cell(v) for v in row) + " |" for row in df.itertuples(index=False)]
    return "\n".join([head, sep, *body]) + "\n"
