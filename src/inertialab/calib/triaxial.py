"""Triaxial accelerometer calibration on arrays (spec 002): the estimator and its artefact.

:func:`calibrate` fits the 9-parameter model of spec 002 §1.2 to static record means:
Levenberg-Marquardt (scipy, analytic Jacobian, §3.6) with the initialisation rule of
§3.6, CS / ACS / PSO (§3.3-3.5) on the search box of §3.2 with the LM optimum as target
(§3.9), the classic six-position method (§3.7) or the ellipsoid fit (§3.8); objectives
``norm`` (J_H), ``norm2`` (J_H2), ``scalar`` (S9) and ``scalar12`` (S12).

The fitted artefact is :class:`TriaxialCalibration` (``MODEL_TYPE =
"triaxial-calibration"``) obeying ``calibrated = correction_matrix @ (raw - offset)``
with ``calibrated`` in m/s^2 and ``raw`` in the file's raw unit; with a gyro, the gyro
block maps raw rates to rad/s in the calibrated accelerometer frame (§7.3).
One session's data and the accelerometer + gyro fit of it live in
:mod:`inertialab.calib.triaxial_session`; many units at once in
:mod:`inertialab.calib.triaxial_batch`. No files, no records here.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from inertialab.errors import (
    InputError,
    MissingReferenceError,
    NonIdentifiableWarning,
    UnderdeterminedError,
)
from inertialab.io.model_schemas import check_own_payload
from inertialab.jsonable import to_jsonable
from inertialab.limits import MAX_MAGNITUDE, finite
from inertialab.optim.base import Target
from inertialab.optim.cuckoo import adaptive_cuckoo_search, cuckoo_search
from inertialab.optim.pso import pso
from inertialab.regress.nlls import covariance, levenberg_marquardt
from inertialab.sensors import triaxial as tx
from inertialab.sensors.triaxial_classic import (
    FACES,
    PLACEMENT_RAD,
    ellipsoid_fit,
    face_fit,
    six_position,
)

METHODS = ("lm", "acs", "cs", "pso", "six-position", "ellipsoid")
OBJECTIVE_ALIASES = {"norm": "norm", "norm2": "norm2", "scalar": "scalar", "s9": "scalar",
                     "scalar12": "scalar12", "s12": "scalar12"}
PLANE_COND = 100.0
"""Direction-matrix condition number above which the poses are called degenerate."""
COND_FLAG = 1e8
"""cond(J^T J) above which a schedule is flagged as poorly conditioned (spec 002 §7.3)."""
DATASHEET = {"b_xy": 0.49, "b_z": 0.78, "k_rel": 0.03, "theta": 0.02}
"""MPU-6050 ±2 g datasheet ranges in m/s^2, relative and rad (spec 002 §6.1, §6.4)."""

# =========================================================================== model

def _finite_result(values: np.ndarray, raw: np.ndarray, what: str) -> np.ndarray:
    """Calibrated values, refused when finite raw samples gave a non-finite or
    overflowing result (a model of extreme entries: nothing with ``inf`` is written)."""
    bad = ~np.isfinite(values) | (np.abs(np.nan_to_num(values)) > MAX_MAGNITUDE)
    fin = np.isfinite(raw)  # a row with a missing raw value may stay missing
    bad &= fin.all(axis=-1, keepdims=True) if fin.ndim == 2 else fin
    if bad.any():
        row = int(np.flatnonzero(bad.any(axis=1))[0]) + 1 if values.ndim == 2 else None
        raise InputError(f"{what} is not finite for finite raw samples; the calibration's "
                         "entries are out of range", row=row)
    return values


@dataclass
class TriaxialCalibration:
    """A triaxial accelerometer calibration (and optionally a gyro calibration).

    ``calibrated = correction_matrix @ (raw - offset)`` with ``raw`` in ``raw_unit``
    and ``calibrated`` in m/s^2 (docs/triaxial.md). ``params`` are
    the 9 model parameters of spec 002 §1.2 in the unit the fit used (m/s^2, or
    counts in counts mode: ``bx`` in counts, ``kx`` in counts per m/s^2).

    The gyro block (``gyro``) is a dict with ``correction_matrix`` (raw gyro unit ->
    rad/s), ``offset`` (raw gyro unit) and ``raw_unit``. ``flags`` lists what made the
    fit implausible or not identifiable when it was written anyway
    (:mod:`inertialab.calib.triaxial_checks`); a flagged model is applied only on request.

    Examples
    --------
    A field calibration of noise-free means at 12 attitudes recovers the sensor's nine
    parameters (biases, scale factors, non-orthogonalities) and maps every mean back onto
    the true specific force:

    >>> import numpy as np
    >>> from inertialab.calib.triaxial_session import StaticData, calibrate_record_data
    >>> from inertialab.sensors import triaxial as tx
    >>> u = np.random.default_rng(0).normal(size=(12, 3))
    >>> a_true = 9.81 * u / np.linalg.norm(u, axis=1, keepdims=True)  # 12 static attitudes
    >>> x = [0.1, -0.05, 0.2, 1.02, 0.98, 1.01, 0.002, -0.001, 0.003]  # b, k, theta
    >>> raw = tx.forward(x, a_true)
    >>> data = StaticData(a=raw, ref=None, g=9.81, raw_unit="mps2", raw_scale=1.0,
    ...                   raw_offset=0.0, counts=False)
    >>> model = calibrate_record_data(data).model
    >>> {k: round(float(v), 6) for k, v in model.params.items()} == dict(zip(tx.PARAM_NAMES, x))
    True
    >>> bool(np.allclose(model.apply(raw), a_true, atol=1e-9))
    True
    >>> bool(np.allclose(TriaxialCalibration.from_dict(model.to_dict()).offset, x[:3]))
    True
    """

    MODEL_TYPE = "triaxial-calibration"
    FORMAT_VERSION = 1
    """Version of the payload layout of :meth:`to_dict` (per model type)."""

    method: str
    objective: str
    params: dict
    correction_matrix: np.ndarray
    offset: np.ndarray
    raw_unit: str
    g_local: float
    stderr: dict | None = None
    phi: np.ndarray | None = None
    residual_rms: float = float("nan")
    iterations: int = 0
    nfev: int = 0
    n_records: int = 0
    static_intervals: int | None = None
    gyro: dict | None = None
    flags: list = field(default_factory=list)
    #: the static means the fit used, (n, 3) in ``raw_unit``: its training span, on which
    #: apply re-checks |a| against gravity (:mod:`inertialab.calib.model_checks`)
    rest_raw: np.ndarray | None = None

    def apply(self, raw) -> np.ndarray:
        """Calibrated accelerations (m/s^2) for raw samples of shape (n, 3)."""
        raw = np.asarray(raw, dtype=float)
        if raw.ndim != 2 or raw.shape[1] != 3:
            raise InputError(f"raw samples must have shape (n, 3), got {raw.shape}")
        return _finite_result((raw - self.offset) @ np.asarray(self.correction_matrix).T,
                              raw, "calibrated acceleration")

    def apply_gyro(self, raw, acc=None) -> np.ndarray:
        """Calibrated rates (rad/s) for raw gyro samples (n, 3); needs the gyro block.

        A gyro block with a ``g_sensitivity`` (Ferraris calibrations) also needs the
        calibrated specific force ``acc`` (n, 3) in m/s^2 (:meth:`apply` of the same
        samples): ``rate = M_g (raw - offset - g_sensitivity @ acc)``.
        """
        if self.gyro is None:
            raise InputError("this calibration has no gyro block; calibrate with gyro data "
                             "(argument 'gyro_raw')")
        raw = np.asarray(raw, dtype=float) - np.asarray(self.gyro["offset"])
        kga = self.gyro.get("g_sensitivity")
        if kga is not None:
            if acc is None:
                raise InputError("this gyro calibration corrects the g-sensitivity: give the "
                                 "calibrated accelerations (argument 'acc')")
            raw = raw - np.asarray(acc, dtype=float) @ np.asarray(kga, dtype=float).T
        return _finite_result(raw @ np.asarray(self.gyro["correction_matrix"]).T, raw,
                              "calibrated rate")

    def to_dict(self) -> dict:
        return {
            "method": self.method, "objective": self.objective,
            "params": {k: float(v) for k, v in self.params.items()},
            "stderr": None if self.stderr is None else
            {k: (None if v is None else float(v)) for k, v in self.stderr.items()},
            "correction_matrix": np.asarray(self.correction_matrix).tolist(),
            "offset": np.asarray(self.offset).tolist(), "raw_unit": self.raw_unit,
            "g_local": float(self.g_local),
            "phi": None if self.phi is None else np.asarray(self.phi).tolist(),
            "residual_rms": float(self.residual_rms), "iterations": int(self.iterations),
            "nfev": int(self.nfev), "n_records": int(self.n_records),
            "static_intervals": self.static_intervals,
            "gyro": None if self.gyro is None else to_jsonable(self.gyro),
            "flags": [str(f) for f in self.flags],
            **({} if self.rest_raw is None else
               {"rest_raw": np.asarray(self.rest_raw, dtype=float).tolist()}),
        }

    @classmethod
    def from_dict(cls, d: dict) -> TriaxialCalibration:
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        try:
            cm = np.asarray(d["correction_matrix"], dtype=float)
            off = np.asarray(d["offset"], dtype=float)
            if cm.shape != (3, 3) or off.shape != (3,):
                raise ValueError("shapes")
            gy = d.get("gyro")
            if gy is not None:
                gy = dict(gy)
                gy["correction_matrix"] = np.asarray(gy["correction_matrix"], dtype=float)
                gy["offset"] = np.asarray(gy["offset"], dtype=float)
                if gy["correction_matrix"].shape != (3, 3) or gy["offset"].shape != (3,):
                    raise ValueError("gyro shapes")
                if gy.get("g_sensitivity") is not None:
                    gy["g_sensitivity"] = np.asarray(gy["g_sensitivity"], dtype=float)
                    if gy["g_sensitivity"].shape != (3, 3):
                        raise ValueError("g_sensitivity shape")
                for key in ("correction_matrix", "offset", "g_sensitivity"):
                    if gy.get(key) is not None:
                        finite(f"gyro.{key}", gy[key])
            finite("correction_matrix", cm)
            finite("offset", off)
            finite("g_local", float(d["g_local"]))
            return cls(
                method=str(d["method"]), objective=str(d["objective"]),
                params={str(k): float(v) for k, v in d["params"].items()},
                correction_matrix=cm, offset=off, raw_unit=str(d["raw_unit"]),
                g_local=float(d["g_local"]), stderr=d.get("stderr"),
                phi=None if d.get("phi") is None else np.asarray(d["phi"], dtype=float),
                residual_rms=float(d.get("residual_rms") if d.get("residual_rms") is not None
                                   else float("nan")),
                iterations=int(d.get("iterations", 0)), nfev=int(d.get("nfev", 0)),
                n_records=int(d.get("n_records", 0)), static_intervals=d.get("static_intervals"),
                gyro=gy, flags=[str(f) for f in (d.get("flags") or [])],
                rest_raw=None if d.get("rest_raw") is None else
                np.asarray(d["rest_raw"], dtype=float).reshape(-1, 3))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"not a valid {cls.MODEL_TYPE} payload ({exc})") from None

# =========================================================================== core fit

@dataclass(frozen=True)
class CalibrationFit:
    """Result of :func:`calibrate` (arrays in the working unit: m/s^2 or counts).

    Attributes
    ----------
    x : ndarray (9,)
    phi : ndarray (3,) or None
        Mount rotation (S12 only), rad.
    method, objective : str
    J : float
        Objective value ``sum(rho^2)/n`` at ``x`` (spec 002 §3.1).
    cov : ndarray (p, p) or None
    stderr : ndarray (p,) or None
    residual_rms : float
        RMS of the LM residual vector (m/s^2, or counts in counts mode).
    iterations, nfev : int
        LM: Jacobian evaluations and residual evaluations; metaheuristics:
        generations and objective evaluations (spec 002 §3.9).
    converged : bool
    cond : float
        cond(J^T J) at the solution.
    n_records : int
    corrected : ndarray (n, 3)
        Corrected record means.
    history : ndarray or None
        Best objective per generation (metaheuristics).
    wall_s : float
        Solver wall time (perf_counter around the solver only).
    x_init : ndarray (p,)
        Start (LM) or initial estimate used for the box (counts mode).
    extra : dict
    """

    x: np.ndarray
    phi: np.ndarray | None
    method: str
    objective: str
    J: float
    cov: np.ndarray | None
    stderr: np.ndarray | None
    residual_rms: float
    iterations: int
    nfev: int
    converged: bool
    cond: float
    n_records: int
    corrected: np.ndarray
    history: np.ndarray | None
    wall_s: float
    x_init: np.ndarray
    extra: dict = field(default_factory=dict)

    @property
    def params(self) -> dict:
        return dict(zip(tx.PARAM_NAMES, self.x.tolist()))


def _check_design(a, ref, objective):
    """Refuse too few records and degenerate (coplanar / one-cone) pose sets."""
    n = a.shape[0]
    need = 9 if objective in ("norm", "norm2") else 3
    if n < need:
        if objective in ("norm", "norm2"):
            raise UnderdeterminedError(
                f"{n} usable records for 9 unknowns: the norm objective needs at least 9 poses "
                "(well spread over the sphere); with six faces set argument 'objective' to 'scalar'")
        raise UnderdeterminedError(f"{n} usable records: at least {need} are needed")
    if ref is not None and objective in ("scalar", "scalar12"):
        d = ref / np.linalg.norm(ref, axis=1)[:, None]
        what = "reference directions"
    else:
        d = a - a.mean(axis=0)
        what = "measured vectors (minus their mean)"
    sv = np.linalg.svd(d, compute_uv=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    if cond > PLANE_COND:
        raise UnderdeterminedError(
            f"degenerate design: all records lie in one plane (condition number {cond:.3g} of the "
            f"{what}); add poses tilted out of that plane")


def _linear_init(a, ref):
    """Linear fit a_i = C r_i + B, then LQ: x and the frame rotation Q (spec 002 §3.6)."""
    D = np.column_stack([ref, np.ones(len(ref))])
    sol, *_ = np.linalg.lstsq(D, a, rcond=None)
    C, B = sol[:3].T, sol[3]
    lq = tx.lq_to_params(C)
    return np.r_[B, lq.x_tail], lq.rotation


def _log_rotation(Q):
    c = np.clip((np.trace(Q) - 1.0) / 2.0, -1.0, 1.0)
    th = np.arccos(c)
    w = np.array([Q[2, 1] - Q[1, 2], Q[0, 2] - Q[2, 0], Q[1, 0] - Q[0, 1]])
    return 0.5 * w if th < 1e-9 else th / (2 * np.sin(th)) * w


def initial_estimate(a, *, objective="norm", g=tx.G_PAPER, ref=None, counts=False):
    """Start point of spec 002 §3.6: x0 for m/s^2 data with ||mean record|| < 0.5 g, else the
    linear fit + LQ (reference mode) or the ellipsoid fit (norm mode; strict in counts mode).

    Returns ``(x (9|12,), how)``.
    """
    a = np.asarray(a, dtype=float)
    if not counts and np.linalg.norm(a.mean(axis=0)) < 0.5 * g:
        x = tx.X0.copy()
        how = "nominal"
        if objective == "scalar12":
            x = np.r_[x, np.zeros(3)]
        return x, how
    if objective in ("scalar", "scalar12") and ref is not None:
        x, Q = _linear_init(a, ref)
        if objective == "scalar12":
            phi = _log_rotation(Q)
            if np.max(np.abs(phi)) > 0.5:
                phi = np.zeros(3)
            x = np.r_[x, phi]
        return x, "linear fit + LQ"
    fit = ellipsoid_fit(a, g=g, strict=counts)
    if not fit.success:
        return tx.X0.copy(), "nominal (ellipsoid fit failed)"
    return fit.x, "ellipsoid fit"


def fit_lm(a, ref, objective, g, x_start, loss="linear", f_scale=1.0, bounds=None):
    """Levenberg-Marquardt fit of the triaxial model to the static means ``a`` (one row
    per pose, the log's unit) against gravity ``g`` (m/s^2) or the reference directions
    ``ref``, from ``x_start``; ``loss``/``f_scale``/``bounds`` as
    :func:`inertialab.regress.nlls.levenberg_marquardt`."""
    fun = lambda p: tx.residuals(p, a, objective=objective, g=g, ref=ref)  # noqa: E731
    jac = lambda p: tx.jacobian(p, a, objective=objective, g=g, ref=ref)  # noqa: E731
    return levenberg_marquardt(fun, x_start, jac=jac, loss=loss, f_scale=f_scale, bounds=bounds)


def _six_faces(ref):
    """Indices of the six face records (+x, -x, +y, -y, +z, -z) among reference directions."""
    d = ref / np.linalg.norm(ref, axis=1)[:, None]
    idx = []
    for f in FACES:
        e = np.zeros(3)
        e["xyz".index(f[1])] = 1.0 if f[0] == "+" else -1.0
        dots = d @ e
        i = int(np.argmax(dots))
        if dots[i] < np.cos(np.deg2rad(2.0)):
            raise UnderdeterminedError(
                f"six-position method needs a record with {f} up (within 2 deg); none found")
        idx.append(i)
    return np.array(idx)


def _checked_inputs(a, ref, method: str, objective: str):
    """Records (n, 3), references (n, 3) or None and the objective's canonical name, or a
    one-line error: a bad shape, an unknown method or objective, a scalar objective (or
    the six-position method) without a reference for every record."""
    a = np.asarray(a, dtype=float)
    if a.ndim != 2 or a.shape[1] != 3:
        raise InputError(f"records must have shape (n, 3), got {a.shape}")
    if method not in METHODS:
        raise InputError(f"unknown method '{method}' (use one of {', '.join(METHODS)})")
    objective = OBJECTIVE_ALIASES.get(objective, objective)
    if objective not in tx.OBJECTIVES:
        raise InputError(f"unknown objective '{objective}' (use norm, norm2, scalar or scalar12)")
    if ref is not None:
        ref = np.asarray(ref, dtype=float)
        if ref.shape != a.shape:
            raise InputError(f"references must have shape {a.shape}, got {ref.shape}")
        if not np.all(np.isfinite(ref)):
            ref = None if np.all(~np.isfinite(ref)) else ref
    needs_ref = objective in ("scalar", "scalar12") or method == "six-position"
    if needs_ref and (ref is None or not np.all(np.isfinite(ref))):
        what = "method 'six-position'" if method == "six-position" else f"objective '{objective}'"
        raise MissingReferenceError(
            f"{what} needs a reference direction for every record (ref_x/ref_y/ref_z, "
            "pitch_deg/heading_deg or face); in field mode set argument 'objective' to 'norm'")
    return a, ref, objective


def _lm_fit(a, ref, objective, g, x_start, *, loss, f_scale, bounded, counts):
    """The Levenberg-Marquardt fit from ``x_start`` (spec 002 §3.6): a robust loss
    without ``f_scale`` takes 3 x the robust scale of a plain fit's residuals and starts
    from it; ``bounded`` solves inside the search box of §3.2. Returns the solver's
    result, the start it used and the wall time (s)."""
    if loss != "linear" and f_scale is None:
        plain = fit_lm(a, ref, objective, g, x_start)
        f_scale = max(3.0 * 1.4826 * float(np.median(np.abs(plain.residuals))), 1e-12)
        x_start = plain.x
    lm_box = None
    if bounded:
        bx = tx.search_box(objective, center=x_start[:9] if counts else None)
        lm_box = (bx[:, 0], bx[:, 1])
    t0 = time.perf_counter()
    res = fit_lm(a, ref, objective, g, x_start, loss=loss,
              f_scale=1.0 if f_scale is None else f_scale, bounds=lm_box)
    return res, x_start, time.perf_counter() - t0


def calibrate(a, *, ref=None, method: str = "lm", objective: str = "norm", g: float = tx.G_PAPER,
              rng=0, counts: bool = False, pop_size: int = 25, max_generations: int = 1000,
              loss: str = "linear", f_scale: float | None = None,
              bounded: bool = False, refine_faces: bool = True,
              placement_rad: float = PLACEMENT_RAD) -> CalibrationFit:
    """Calibrate a triaxial accelerometer from static record means (spec 002 §3).

    Parameters
    ----------
    a : array (n, 3)
        Record means in the working unit (m/s^2, or counts in counts mode).
    ref : array (n, 3), optional
        Reference vectors in m/s^2 (``|ref| = g``) for the scalar objectives.
    method : {"lm", "acs", "cs", "pso", "six-position", "ellipsoid"}, default "lm"
    objective : {"norm", "norm2", "scalar", "scalar12"}, default "norm"
        J_H, J_H2, S9, S12 (spec 002 §3.1). ``norm`` is the only possible objective in a
        true field calibration; the scalar ones need references.
    g : float, default 9.8
        Gravity magnitude, m/s^2 (paper's value; pass the local one).
    rng : int, Generator or None, default 0
        Seed of the metaheuristics (the initial population is its first draw).
    counts : bool, default False
        Data are raw counts without a known sensitivity (spec 002 §2.3): the box of the
        metaheuristics is centred on the initial estimate and the ellipsoid fit is strict.
    pop_size, max_generations : int, default 25, 1000
        Metaheuristic settings (spec 002 §3.3).
    loss : {"linear", "soft_l1", "huber", "cauchy"}, default "linear"
        Robust loss of the LM (spec 002 §7.3), default plain least squares.
    f_scale : float, optional
        Residual scale of a robust loss; default 3 x the robust scale (1.4826 x median
        absolute residual) of a plain LM fit, i.e. about 3·sigma_rec (spec 002 §7.3).
    bounded : bool, default False
        LM only: solve with scipy's ``trf`` inside the search box of spec 002 §3.2 (the
        bounded variant of §3.6; the box is centred on the initial estimate in counts mode).
    refine_faces : bool, default True
        Six-position only: refine the 12-parameter closed form so that every face has
        |a| = g (:func:`~inertialab.sensors.triaxial_classic.face_fit`, for
        hand-placed faces); False is the classic closed form of spec 002 §3.7.
    placement_rad : float, default 2 deg
        Six-position with ``refine_faces``: standard deviation of a face's tilt.

    Raises
    ------
    MissingReferenceError
        A scalar objective (or the six-position method) without references.
    UnderdeterminedError
        Too few records or a degenerate design (the message names the condition number).
    """
    a, ref, objective = _checked_inputs(a, ref, method, objective)
    if method == "six-position":
        return _fit_six(a, ref, g, refine=refine_faces, placement_rad=placement_rad)
    _check_design(a, ref, objective)
    n = a.shape[0]
    if method == "ellipsoid":
        t0 = time.perf_counter()
        fit = ellipsoid_fit(a, g=g, strict=True)
        wall = time.perf_counter() - t0
        return _finish(a, ref, fit.x, None, "ellipsoid", "norm", g, None, 0, 1, True, wall,
                       fit.x, None)
    x_start, how = initial_estimate(a, objective=objective, g=g, ref=ref, counts=counts)
    res, x_start, wall = _lm_fit(a, ref, objective, g, x_start, loss=loss, f_scale=f_scale,
                                 bounded=bounded, counts=counts)
    if method == "lm":
        x = res.x
        phi = x[9:12] if objective == "scalar12" else None
        fit = _finish(a, ref, x[:9], phi, "lm", objective, g, res, res.njev, res.nfev,
                      bool(res.success), wall, x_start, None)
        return _with_extra(fit, init=how)
    # metaheuristics: box of §3.2, target = LM optimum (§3.9)
    J_star = float(np.dot(res.residuals, res.residuals) / n)
    box = tx.search_box(objective, center=x_start[:9] if counts else None)
    f = lambda X: tx.objective_many(X, a, objective=objective, g=g, ref=ref)  # noqa: E731
    solver = {"acs": adaptive_cuckoo_search, "cs": cuckoo_search, "pso": pso}[method]
    t0 = time.perf_counter()
    opt = solver(f, box, pop_size=pop_size, max_generations=max_generations, rng=rng,
                 vectorized=True, target=Target(J_star))
    wall = time.perf_counter() - t0
    x = opt.x
    phi = x[9:12] if objective == "scalar12" else None
    fit = _finish(a, ref, x[:9], phi, method, objective, g, None, opt.nit, opt.nfev,
                  bool(opt.success), wall, x_start, opt.history)
    return _with_extra(fit, J_lm=J_star, message=opt.message, converged_at=opt.converged_at,
                       x_lm=res.x.tolist())


def _with_extra(fit: CalibrationFit, **kw) -> CalibrationFit:
    d = dict(fit.extra)
    d.update(kw)
    return CalibrationFit(**{**fit.__dict__, "extra": d})


def _finish(a, ref, x, phi, method, objective, g, res, iterations, nfev, converged, wall,
            x_init, history) -> CalibrationFit:
    xp = x if phi is None else np.r_[x, phi]
    r = tx.residuals(xp, a, objective=objective, g=g, ref=ref)
    J = float(np.dot(r, r) / a.shape[0])
    if res is not None:
        cov, se, cond = res.cov, res.stderr, res.cond
    else:
        cv = covariance(tx.jacobian(xp, a, objective=objective, g=g, ref=ref), r)
        cov, se, cond = cv.cov, cv.stderr, cv.cond
    if not np.isfinite(cond) or cond > COND_FLAG:
        hint = ""
        try:
            sug = suggest_orientations(x, a, g=g, objective=objective, n=3)
            hint = "; e.g. with gravity-up along " + ", ".join(
                "(" + ", ".join(f"{v:+.2f}" for v in d) + ")" for d in sug) + " in the sensor frame"
        except (InputError, np.linalg.LinAlgError):
            pass
        warnings.warn(
            f"poorly conditioned pose schedule (cond(J^T J) = {cond:.3g} > 1e8): some parameters "
            f"are barely identifiable; add orientations spread over the sphere{hint}",
            NonIdentifiableWarning, stacklevel=3)
    return CalibrationFit(
        x=np.asarray(x, dtype=float), phi=None if phi is None else np.asarray(phi, dtype=float),
        method=method, objective=objective, J=J, cov=cov, stderr=se,
        residual_rms=float(np.sqrt(np.mean(r * r))), iterations=int(iterations), nfev=int(nfev),
        converged=bool(converged), cond=float(cond), n_records=int(a.shape[0]),
        corrected=tx.correct(x, a), history=history, wall_s=float(wall),
        x_init=np.asarray(x_init, dtype=float))


def fibonacci_sphere(n: int) -> np.ndarray:
    """n nearly uniform unit vectors (golden-angle spiral), the candidate grid of
    :func:`suggest_orientations`."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    r = np.sqrt(1.0 - z * z)
    phi = np.pi * (1.0 + 5**0.5) * i
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def suggest_orientations(x, a, *, g: float = tx.G_PAPER, objective: str = "norm", n: int = 3,
                         candidates: int = 400) -> np.ndarray:
    """Greedy D-optimal extra poses (spec 002 §7.3): gravity-up directions in the sensor frame
    that most increase log det(J^T J) of the calibration at ``x``.

    Each candidate direction d is turned into a predicted record ``forward(x, g d)``; its
    Jacobian rows (norm objective: one; scalar: three, with d as its own reference) are
    added to the current normal matrix. Returns an array (n, 3) of unit vectors.
    """
    x = np.asarray(x, dtype=float)[:9]
    obj = "norm" if objective in ("norm", "norm2") else "scalar"
    a = np.asarray(a, dtype=float)
    ref = tx.correct(x, a) if obj == "scalar" else None
    J = tx.jacobian(x, a, objective=obj, g=g, ref=ref)
    d = np.sqrt(np.maximum(np.sum(J * J, axis=0), 1e-300))
    N = (J / d).T @ (J / d) + 1e-12 * np.eye(9)
    cand = fibonacci_sphere(candidates)
    rec = tx.forward(x, g * cand)
    Jc = tx.jacobian(x, rec, objective=obj, g=g, ref=g * cand if obj == "scalar" else None) / d
    rows = Jc.reshape(candidates, -1, 9)
    picked = []
    for _ in range(n):
        gains = np.array([np.linalg.slogdet(N + R.T @ R)[1] for R in rows])
        k = int(np.argmax(gains))
        picked.append(cand[k])
        N = N + rows[k].T @ rows[k]
    return np.array(picked)


def _fit_six(a, ref, g, *, refine: bool = True, placement_rad: float = PLACEMENT_RAD
             ) -> CalibrationFit:
    idx = _six_faces(ref)
    t0 = time.perf_counter()
    r12 = six_position(a[idx], g=g, form=12)
    r6 = six_position(a[idx], g=g, form=6)
    x = r12.x
    rot = r12.rotation
    extra = {}
    if refine:
        ff = face_fit(a[idx], g=g, placement_rad=placement_rad)
        x, rot = ff.x, ff.rotation
        extra = {"x_closed_form": r12.x.tolist(), "face_tilt_deg": np.rad2deg(ff.tilt_rad).tolist(),
                 "face_norm_residual": ff.norm_residual.tolist()}
    wall = time.perf_counter() - t0
    fit = _finish(a[idx], ref[idx], x, None, "six-position", "scalar", g, None, 0, 1, True,
                  wall, x, None)
    fit = CalibrationFit(**{**fit.__dict__, "corrected": tx.correct(x, a),
                            "n_records": int(a.shape[0])})
    return _with_extra(fit, x_6param=r6.x.tolist(), rotation_12param=rot.tolist(),
                       face_rows=idx.tolist(), refined=bool(refine), **extra)
