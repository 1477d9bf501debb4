"""Priors of the dual-meter g^2 calibration (spec 003 §3.3, §6.5; docs/dual.md).

A prior is a centre beta0 and scale w on the nine coefficients :data:`COEF_NAMES`:

* none (``None``): the paper-faithful beta0 = 0, W = I;
* :func:`certificate_prior`: K2 centred at 0 with SD = certificate limit / 2 (§6.5);
* :func:`prior_from_history`: mean and SD of past calibrations of the unit, the SD
  floored at tau/2 (turn-on repeatability, :data:`~inertialab.sensors.dual_meter.TURN_ON_TAU`);
* :func:`prior_from_dict`: the ``inertialab.prior/1`` JSON object, validated.

Real-data code (a history of a real unit's calibrations), on arrays and dicts only;
reading the files is :func:`inertialab.workflows.dual.load_prior`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.sensors.dual_meter import (
    COEF_NAMES,
    COEF_UNITS,
    PAPER_ALIASES,
    TURN_ON_TAU,
    canonical_coef_name,
)

__all__ = ["CERT_LIMITS", "DualPrior", "certificate_prior", "history_prior", "prior_from_dict",
           "prior_from_history", "resolve_prior"]

CERT_LIMITS = {"KA2": 9.4e-5, "KB2": 2.5e-5}  # seed certificate limits, g/g^2 [P]


@dataclass(frozen=True)
class DualPrior:
    """Prior centre and scale (beta0, w) on :data:`COEF_NAMES`; ``kind`` labels it."""

    kind: str
    mean: np.ndarray
    sd: np.ndarray

    def to_json(self) -> dict:
        return {"schema": "inertialab.prior/1",
                "coef": {n: {"mean": float(self.mean[j]), "sd": float(self.sd[j]),
                             "unit": COEF_UNITS[n]} for j, n in enumerate(COEF_NAMES)}}


def certificate_prior() -> DualPrior:
    """Certificate prior of spec §6.5: K2 centred at 0 with SD = limit/2, Kx 0 +- 1e-5,
    K0, k1, eta weakly informative (0 +- 1e-3)."""
    mean = np.zeros(9)
    sd = np.full(9, 1e-3)
    idx = {n: i for i, n in enumerate(COEF_NAMES)}
    sd[idx["KA2"]] = CERT_LIMITS["KA2"] / 2
    sd[idx["KB2"]] = CERT_LIMITS["KB2"] / 2
    sd[idx["KAx"]] = sd[idx["KBx"]] = 1e-5
    return DualPrior("certificate", mean, sd)


_UNIT_ALIASES = {"g/g": {"g/g", "1", "", "ratio"}, "rad": {"rad"}, "g": {"g"},
                 "g/g^2": {"g/g^2", "g/g2", "1/g"}}


def _canonical_keys(coef: dict, path) -> dict:
    """Paper aliases (``KAip_paper``, spec §1.3) to canonical names; both at once is an error."""
    out: dict = {}
    for k, v in coef.items():
        c = canonical_coef_name(k) if isinstance(k, str) else k
        if c in out:
            raise InputError(f"prior gives {c} twice (as {c} and its alias "
                             f"{PAPER_ALIASES[c]})", path=path)
        out[c] = v
    return out


def prior_from_dict(d: dict, *, path="<prior>") -> DualPrior:
    """Validate a prior JSON object ``{"schema": "inertialab.prior/1", "coef": {...}}``."""
    if not isinstance(d, dict) or d.get("schema") != "inertialab.prior/1":
        raise InputError("prior file needs \"schema\": \"inertialab.prior/1\"", path=path)
    coef = d.get("coef")
    if not isinstance(coef, dict):
        raise InputError("prior file needs a \"coef\" object", path=path)
    coef = _canonical_keys(coef, path)
    unknown = [k for k in coef if k not in COEF_NAMES]
    if unknown:
        raise InputError(f"unknown coefficient name(s) {', '.join(unknown)}; names are "
                         f"case-sensitive: {' '.join(COEF_NAMES)} (paper aliases "
                         f"{' '.join(PAPER_ALIASES.values())})", path=path)
    missing = [n for n in COEF_NAMES if n not in coef]
    if missing:
        raise InputError(f"prior lacks {', '.join(missing)}", path=path)
    mean, sd = np.zeros(9), np.zeros(9)
    for j, n in enumerate(COEF_NAMES):
        e = coef[n]
        try:
            mean[j], sd[j] = float(e["mean"]), float(e["sd"])
        except (KeyError, TypeError, ValueError):
            raise InputError(f"prior entry {n} needs numeric \"mean\" and \"sd\"",
                             path=path) from None
        unit = str(e.get("unit", COEF_UNITS[n]))
        if unit not in _UNIT_ALIASES[COEF_UNITS[n]]:
            raise InputError(f"prior entry {n} has unit '{unit}', expected "
                             f"'{COEF_UNITS[n]}'", path=path)
        if not (np.isfinite(mean[j]) and np.isfinite(sd[j]) and sd[j] > 0):
            raise InputError(f"prior entry {n}: mean must be finite and sd positive", path=path)
    return DualPrior(str(d.get("kind", "file")), mean, sd)



def prior_from_history(history) -> dict:
    """Prior ``{name: {"mean", "sd", "unit"}}`` from historical estimates (spec §6.5).

    Mean over runs; SD floored at tau/2. ``history`` is an (H, 9) array in
    :data:`COEF_NAMES` order or a DataFrame with those columns.
    """
    if isinstance(history, pd.DataFrame):
        missing = [n for n in COEF_NAMES if n not in history.columns]
        if missing:
            raise InputError(f"history lacks columns {', '.join(missing)}")
        H = history[list(COEF_NAMES)].to_numpy(dtype=float)
    else:
        H = np.asarray(history, dtype=float)
    if H.ndim != 2 or H.shape[1] != 9 or H.shape[0] < 2:
        raise InputError("history needs at least 2 calibrations of the 9 coefficients")
    if not np.all(np.isfinite(H)):
        rows = (np.flatnonzero(~np.all(np.isfinite(H), axis=1))[:5] + 1).tolist()
        raise InputError(f"history has missing or non-finite values (rows {rows})")
    mean = H.mean(axis=0)
    sd = H.std(axis=0, ddof=1)
    floor = np.array([TURN_ON_TAU[n] / 2 for n in COEF_NAMES])
    sd = np.maximum(sd, floor)
    return {n: {"mean": float(mean[j]), "sd": float(sd[j]), "unit": COEF_UNITS[n]}
            for j, n in enumerate(COEF_NAMES)}


def history_prior(history) -> DualPrior:
    """:class:`DualPrior` of kind "history" from past calibrations (:func:`prior_from_history`)."""
    pj = prior_from_history(history)
    return DualPrior("history", np.array([pj[n]["mean"] for n in COEF_NAMES]),
                     np.array([pj[n]["sd"] for n in COEF_NAMES]))


def resolve_prior(spec) -> DualPrior | None:
    """``None`` or "none" (paper-faithful beta0 = 0, W = I), "certificate", or a
    :class:`DualPrior` (returned as is). Files are read by ``workflows.dual.load_prior``."""
    if spec is None or isinstance(spec, DualPrior):
        return spec
    s = str(spec).lower()
    if s == "none":
        return None
    if s == "certificate":
        return certificate_prior()
    raise InputError(f"argument 'prior' must be none, certificate or a DualPrior, got {spec!r}")
