"""imu_tk-style text logs: one file per sensor, ``time x y z`` per line (blank or comma
separated, no header), accelerometer and gyro in separate files joined on time.

imu_tk (Tedaldi et al., ICRA 2014) reads ``xsens_acc.mat`` and ``xsens_gyro.mat``: plain
text despite the suffix, time stamps in seconds. :func:`join_on_time` takes the file
read by the front door and the files of the ``join`` option, names each file's columns
by its role (``a`` for a file whose name holds ``acc``, ``g`` for ``gyr``; otherwise the
first file is the accelerometer and the next the gyro): ``t_s ax ay az gx gy gz``, and
joins them on the nearest time stamp within half a sample of the first file (rows of the
first file without a partner are dropped and counted). The columns carry no unit: give
them with the unit option (``g,dps`` or ``mps2,rps``) or a map.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from inertialab.errors import InputError

__all__ = ["join_on_time", "role_of"]

_ROLES = ("a", "g", "m")


def role_of(path, default: str) -> str:
    name = Path(path).name.lower()
    if "gyr" in name:
        return "g"
    if "acc" in name:
        return "a"
    if "mag" in name:
        return "m"
    return default


def _xyz(df: pd.DataFrame, role: str, p, time_scale: float) -> pd.DataFrame:
    cols = list(df.columns)
    if cols == ["col1", "col2", "col3", "col4"]:
        t = pd.to_numeric(df["col1"], errors="coerce").to_numpy(dtype=float)
        out = pd.DataFrame({"t_s": t * time_scale,
                            f"{role}x": df["col2"], f"{role}y": df["col3"], f"{role}z": df["col4"]})
    else:
        low = {str(c).strip().lower(): c for c in cols}
        tcol = low.get("t_s") or cols[0]
        out = df.rename(columns={tcol: "t_s"})
        out["t_s"] = pd.to_numeric(out["t_s"], errors="coerce") * (1.0 if tcol == low.get("t_s")
                                                                     else time_scale)
    bad = ~np.isfinite(out["t_s"].to_numpy(dtype=float))
    if bad.any():
        raise InputError("time stamp is not a number", path=p, column="t_s",
                         row=int(np.flatnonzero(bad)[0]) + 1)
    return out


def join_on_time(first_path, first: pd.DataFrame, others, *, parse=None, options=None):
    """Join ``first`` (already read from ``first_path``) with the files ``others`` on time.

    Returns ``(frame, meta)``; ``meta`` lists the files, their roles and the unmatched
    counts.
    """
    from inertialab import units as U
    from inertialab.io.formats.dispatch import load_frame

    scale = U.convert(1.0, options.time_unit, "s") if options is not None and \
        options.time_unit else 1.0
    paths = [Path(first_path), *[Path(o) for o in others]]
    used = set()
    roles = []
    for k, p in enumerate(paths):
        r = role_of(p, _ROLES[min(k, 2)])
        if r in used:
            r = next((x for x in _ROLES if x not in used), None)
            if r is None:
                raise InputError("more than three files to join", path=p)
        used.add(r)
        roles.append(r)
    base = _xyz(first, roles[0], paths[0], scale).sort_values("t_s", kind="stable")
    t = base["t_s"].to_numpy(dtype=float)
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    if not step > 0:
        raise InputError("time stamps do not increase", path=paths[0], column="t_s")
    meta = {"files": [str(p) for p in paths], "roles": roles, "tolerance_s": step / 2,
            "unmatched": {}}
    out = base
    for p, r in zip(paths[1:], roles[1:]):
        if not p.is_file():
            raise InputError("no such file to join", path=p)
        other = _xyz(load_frame(p, parse=parse).frame, r, p, scale).sort_values("t_s",
                                                                                 kind="stable")
        merged = pd.merge_asof(out, other.rename(columns={"t_s": f"_t_{r}"}), left_on="t_s",
                               right_on=f"_t_{r}", direction="nearest", tolerance=step / 2)
        miss = merged[f"{r}x"].isna().to_numpy()
        meta["unmatched"][str(p)] = int(miss.sum())
        out = merged.loc[~miss].drop(columns=[f"_t_{r}"]).reset_index(drop=True)
    if len(out) == 0:
        raise InputError("no common time stamps between the joined files", path=paths[0])
    t0 = float(out["t_s"].iloc[0])
    meta["time_origin_s"] = t0
    out["t_s"] = out["t_s"] - t0
    meta["matched"] = len(out)
    return out, meta
