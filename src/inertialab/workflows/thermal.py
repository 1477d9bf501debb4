"""Study 000: integrated temperature-drift compensation of a quartz flexure accelerometer.

Pipeline (spec 000 §3): a thermal tumble record -> per (ramp, set point, position)
averages -> reference fit of eq. 1 at 55 °C -> samples ``x = (T, N)``, ``y = Nc`` ->
split (``random``, ``interp_T``, ``leave_one_T_out``) -> the seven models (ANN, FIS,
ANFIS on a grid, SCM-ANFIS, IAFSA-SCM-ANFIS, POLY-SEP, POLY-2D) -> metrics (spec 000 §5)
-> a :class:`ThermalModel` that compensates the unit, or another unit of its lot
(§3.7 transfer), and exports to C (:mod:`inertialab.workflows.thermal_export`).

Everything here is NumPy on top of the method modules; the workflow never reads
files or draws. ``STUDY`` runs the paper-preset demo for ``inertialab demo``.

References
----------
Spec 000 (seed paper 000, Fu, Wen, Miao, Wang), sections cited per function.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import asdict, dataclass, field, replace

import numpy as np
import pandas as pd

from inertialab._blas import single_threaded_blas
from inertialab.errors import (
    ExtrapolationWarning,
    InputError,
    MissingReferenceError,
)
from inertialab.learn.anfis import ANFIS
from inertialab.learn.mlp_lm import MLPRegressorLM
from inertialab.learn.poly import PolynomialRegressor
from inertialab.learn.subclust import DEFAULTS as SCM_DEFAULTS
from inertialab.learn.subclust import SubtractiveClustering
from inertialab.optim.fish_swarm import iafsa
from inertialab.seeding import as_generator
from inertialab.sensors.pendulous import (
    SingleAxisCoefficients,
    estimate_input,
    fit_single_axis,
    higher_order_terms,
    integrated_output,
    reference_target,
)
from inertialab.workflows.base import Headline, NullProgress, Study, StudyResult, settings_dict

#: Model names, in the order of the paper's comparison, then the industry baselines.
METHODS = ("ann", "fis", "anfis", "scm-anfis", "iafsa-scm-anfis", "poly-sep", "poly-2d")
#: Models built on a TSK fuzzy system (exportable to C).
FUZZY = ("fis", "anfis", "scm-anfis", "iafsa-scm-anfis")
SPLITS = ("random", "interp_T", "leave_one_T_out", "up_down")
#: IAFSA search box of spec 000 §3.5: r_a, eta, eps_up, eps_down.
SEARCH_BOUNDS = ((0.05, 1.0), (1.0, 2.5), (0.2, 0.9), (0.01, 0.5))
#: Objective value of an unusable rule count (mg), spec 000 §3.5 step 1.
PENALTY_MG = 1e3
#: Status codes of compensated output (CONTRACTS.md "thermal"; same in the C export).
STATUS_OK, STATUS_T_CLAMPED, STATUS_N_CLAMPED = 0, 1, 2
#: Paper figures (spec 000 §6): test RMSE in mg.
PAPER_RMSE_MG = {"ann": 0.138, "fis": 0.101, "anfis": 0.034, "iafsa-scm-anfis": 0.004}



# ---------------------------------------------------------------------------------------
# configuration
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ThermalConfig:
    """Settings of a thermal fit (defaults: spec 000 §3-§4).

    Attributes
    ----------
    methods : models to fit (subset of :data:`METHODS`)
    split : "random" | "interp_T" | "leave_one_T_out" (§3.1 step 4) | "up_down" (train on
        the up pass, test on the down pass: hysteresis, §8.4)
    test_positions : positions per set point in the test set of the random split (7 of 24)
    val_fraction : stratified validation share of the training set (0.2)
    target : "linear55" (eq. 6) | "measured55" (the 55 °C Ua at the same position)
    input : "ua" (eq. 5) | "raw" (N = U; the target keeps the fitted 55 °C terms)
    learn_drift : learn ``Nc - N`` instead of ``Nc`` (§3.1 step 5)
    include_kp : fit Kp in the reference fit (§3.1 step 1)
    reference_temp_c : 55 °C; temp_tolerance_c : ±2 °C around each set point (§2.3)
    epochs : final ANFIS epochs (150); search_epochs : ANFIS epochs inside IAFSA (20)
    fish, generations : IAFSA N_fish (10) and G_max (30); r_max : rule cap (40)
    radii : "scalar" (4-D search) | "per_dim" (6-D: r_T, r_N, r_y)
    ann_hidden, ann_max_epochs : MLP 2-10-1, up to 500 LM iterations (§4)
    poly_sep_degree : cubic K0(T), K1(T) (§4); poly2d_degrees : (m, n) = (3, 1) (§4)
    range_margin_c, range_margin_frac : the calibrated range used for clamping is the
        training range of T widened by 0.5 °C (chamber wander) and of N widened by 5 % of
        its span on each side [ours]. Clamping N exactly at the training maximum would
        saturate a +1 g reading whose position happened to fall in the test set (measured:
        400 µg at 70 °C, +1 g), while the first-order consequents extrapolate benignly.
    seed : master seed (split, search, ANN init; spawned in that order)
    """

    methods: tuple[str, ...] = METHODS
    split: str = "random"
    test_positions: int = 7
    val_fraction: float = 0.2
    target: str = "linear55"
    input: str = "ua"
    learn_drift: bool = False
    include_kp: bool = True
    reference_temp_c: float = 55.0
    temp_tolerance_c: float = 2.0
    epochs: int = 150
    search_epochs: int = 20
    fish: int = 10
    generations: int = 30
    r_max: int = 40
    radii: str = "scalar"
    ann_hidden: int = 10
    ann_max_epochs: int = 500
    poly_sep_degree: int = 3
    poly2d_degrees: tuple[int, int] = (3, 1)
    range_margin_c: float = 0.5
    range_margin_frac: float = 0.05
    seed: int = 0

    def validate(self) -> ThermalConfig:
        bad = [m for m in self.methods if m not in METHODS]
        if bad:
            raise InputError(f"unknown method(s) {bad}; choose from {', '.join(METHODS)} or all")
        if self.split not in SPLITS:
            raise InputError(f"unknown split {self.split!r}; choose one of {', '.join(SPLITS)}")
        if self.target not in ("linear55", "measured55"):
            raise InputError(f"target must be linear55 or measured55, got {self.target!r}")
        if self.input not in ("ua", "raw"):
            raise InputError(f"input must be ua or raw, got {self.input!r}")
        if self.radii not in ("scalar", "per_dim"):
            raise InputError(f"radii must be scalar or per_dim, got {self.radii!r}")
        if not 0 < self.val_fraction < 1:
            raise InputError(f"val_fraction must be in (0, 1), got {self.val_fraction}")
        return self


# ---------------------------------------------------------------------------------------
# samples
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ThermalSamples:
    """Averaged tumble samples of one unit (one per ramp pass, set point and position).

    Arrays have one entry per sample: ``temp_c`` (mean measured temperature),
    ``set_point_c``, ``pos_index``, ``ramp_dir``, ``a_in_g``, ``a_pend_g`` (nominal),
    ``output_mv`` (U), ``n_mv`` (model input N), ``y_mv`` (target Nc), ``true_a_in_g``
    (nan for real data). ``ref`` is the 55 °C fit and ``ref_stderr`` its standard errors.
    """

    temp_c: np.ndarray
    set_point_c: np.ndarray
    pos_index: np.ndarray
    ramp_dir: np.ndarray
    a_in_g: np.ndarray
    a_pend_g: np.ndarray
    output_mv: np.ndarray
    n_mv: np.ndarray
    y_mv: np.ndarray
    true_a_in_g: np.ndarray
    ref: SingleAxisCoefficients
    ref_stderr: dict
    ref_residual_mv: float
    input: str
    target: str
    unit_id: str = ""

    @property
    def n(self) -> int:
        return int(self.temp_c.size)

    @property
    def X(self) -> np.ndarray:
        return np.column_stack([self.temp_c, self.n_mv])

    @property
    def k1(self) -> float:
        return self.ref.k1


def _positions_ok(frame: pd.DataFrame, n_positions: int, path) -> None:
    for (rd, sp), g in frame.groupby(["ramp_dir", "temp_set_c"], sort=True):
        k = g.pos_index.nunique()
        if k < n_positions:
            raise InputError(
                f"set point {sp:g} °C ({rd}) has {k} distinct positions, need {n_positions}",
                path=path, column="pos_index")


def prepare_samples(frame: pd.DataFrame, config: ThermalConfig | None = None, *,
                    path="<frame>", n_positions: int = 24) -> ThermalSamples:
    """Validate a thermal-tumble frame and build the (T, N) -> Nc samples (spec 000 §2.3,
    §3.1).

    Raises
    ------
    MissingReferenceError
        No (or more than one) set point at the reference temperature.
    InputError
        Fewer than ``n_positions`` positions at a set point; a measured temperature more
        than ``temp_tolerance_c`` from its set point (the row is named).
    """
    cfg = (config or ThermalConfig()).validate()
    f = frame.copy()
    for col in ("temp_set_c", "temp_meas_c", "pos_index", "output_mv"):
        if col not in f.columns:
            raise InputError("missing required column", path=path, column=col)
    if "ramp_dir" not in f.columns:
        f["ramp_dir"] = "up"
    if "a_in_g" not in f.columns or "a_pend_g" not in f.columns:
        ang = np.deg2rad(15.0 * f["pos_index"].to_numpy() * 24.0 / n_positions)
        f["a_in_g"] = np.round(np.sin(ang), 15)
        f["a_pend_g"] = np.round(np.cos(ang), 15)
    off = np.abs(f.temp_meas_c.to_numpy() - f.temp_set_c.to_numpy())
    if np.any(off > cfg.temp_tolerance_c):
        rows = (np.flatnonzero(off > cfg.temp_tolerance_c) + 1)[:5].tolist()
        raise InputError(
            f"measured temperature more than {cfg.temp_tolerance_c:g} °C from its set point "
            f"(worst {off.max():.2f} °C)", path=path, column="temp_meas_c",
            row=rows[0] if len(rows) == 1 else rows)
    sps = np.unique(f.temp_set_c.to_numpy())
    is_ref = np.isclose(sps, cfg.reference_temp_c, atol=1e-6)
    if is_ref.sum() != 1:
        raise MissingReferenceError(
            f"no set point at the reference temperature {cfg.reference_temp_c:g} °C "
            f"(set points: {', '.join(f'{s:g}' for s in sps)})", path=path, column="temp_set_c")
    _positions_ok(f, n_positions, path)
    has_true = "true_a_in_g" in f.columns
    agg = {"temp_meas_c": "mean", "output_mv": "mean", "a_in_g": "first", "a_pend_g": "first"}
    if has_true:
        agg["true_a_in_g"] = "mean"
    g = (f.groupby(["ramp_dir", "temp_set_c", "pos_index"], sort=True).agg(agg).reset_index())
    # up pass first (the reference fit uses the first pass at 55 °C)
    g["_o"] = (g.ramp_dir != "up").astype(int)
    g = g.sort_values(["_o", "temp_set_c", "pos_index"], kind="stable").reset_index(drop=True)
    a_i = g.a_in_g.to_numpy(float)
    a_p = g.a_pend_g.to_numpy(float)
    U = g.output_mv.to_numpy(float)
    sp = g.temp_set_c.to_numpy(float)
    rd = g.ramp_dir.to_numpy(str)
    ref_rows = np.isclose(sp, cfg.reference_temp_c, atol=1e-6) & (rd == rd[0])
    fit = fit_single_axis(a_i[ref_rows], a_p[ref_rows], U[ref_rows], include_kp=cfg.include_kp)
    ref = fit.coefficients
    ua = integrated_output(U, a_i, a_p, ref)
    if cfg.target == "linear55":
        y = reference_target(a_i, ref)
    else:  # measured55: the 55 °C Ua at the same position (same pass)
        lut = {int(p): v for p, v in zip(g.pos_index.to_numpy()[ref_rows], ua[ref_rows])}
        y = np.array([lut[int(p)] for p in g.pos_index.to_numpy()])
    if cfg.input == "raw":
        n = U
        y = y + higher_order_terms(a_i, a_p, ref)
    else:
        n = ua
    unit_id = str(f["unit_id"].iloc[0]) if "unit_id" in f.columns else ""
    return ThermalSamples(
        temp_c=g.temp_meas_c.to_numpy(float), set_point_c=sp,
        pos_index=g.pos_index.to_numpy(int), ramp_dir=rd, a_in_g=a_i, a_pend_g=a_p,
        output_mv=U, n_mv=np.asarray(n, float), y_mv=np.asarray(y, float),
        true_a_in_g=g.true_a_in_g.to_numpy(float) if has_true else np.full(len(g), np.nan),
        ref=ref, ref_stderr=fit.stderr, ref_residual_mv=fit.residual_rms, input=cfg.input,
        target=cfg.target, unit_id=unit_id)


# ---------------------------------------------------------------------------------------
# splits
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Split:
    """Index sets into the samples: ``train`` = ``fit`` + ``val``; ``test``."""

    name: str
    train: np.ndarray
    test: np.ndarray
    fit: np.ndarray
    val: np.ndarray


def _strata(s: ThermalSamples) -> np.ndarray:
    keys = [f"{r}|{t:g}" for r, t in zip(s.ramp_dir, s.set_point_c)]
    _, inv = np.unique(keys, return_inverse=True)
    return inv


def _validation(train: np.ndarray, strata: np.ndarray, frac: float, rng) -> tuple[np.ndarray, np.ndarray]:
    val = []
    for k in np.unique(strata[train]):
        members = train[strata[train] == k]
        m = int(np.floor(frac * members.size + 0.5))
        if m:
            val.extend(rng.choice(members, size=m, replace=False).tolist())
    val = np.sort(np.asarray(val, dtype=int))
    fit = np.setdiff1d(train, val)
    return fit, val


def make_splits(samples: ThermalSamples, config: ThermalConfig, rng=None) -> list[Split]:
    """The split(s) of spec 000 §3.1 step 4 (one for random/interp_T/up_down, one per set
    point for leave_one_T_out; the reference set point is always in training)."""
    cfg = config.validate()
    g = as_generator(rng)
    strata = _strata(samples)
    idx = np.arange(samples.n)
    is_ref = np.isclose(samples.set_point_c, cfg.reference_temp_c, atol=1e-6)
    splits = []
    if cfg.split == "random":
        test = []
        for k in np.unique(strata):
            members = idx[strata == k]
            if cfg.test_positions >= members.size:
                raise InputError(f"test_positions {cfg.test_positions} leaves no training data")
            test.extend(g.choice(members, size=cfg.test_positions, replace=False).tolist())
        test = np.sort(np.asarray(test, dtype=int))
        train = np.setdiff1d(idx, test)
        fit, val = _validation(train, strata, cfg.val_fraction, g)
        splits.append(Split("random", train, test, fit, val))
    elif cfg.split == "interp_T":
        sps = np.unique(samples.set_point_c)
        lo = sps.min()
        step = np.min(np.diff(sps)) if sps.size > 1 else 1.0
        k = np.rint((samples.set_point_c - lo) / step).astype(int)
        train_mask = (k % 2 == 0) | is_ref
        train, test = idx[train_mask], idx[~train_mask]
        if test.size == 0:
            raise InputError("interp_T split: no intermediate set points to test on")
        fit, val = _validation(train, strata, cfg.val_fraction, g)
        splits.append(Split("interp_T", train, test, fit, val))
    elif cfg.split == "up_down":
        up = samples.ramp_dir == "up"
        train, test = idx[up], idx[~up]
        if test.size == 0 or train.size == 0:
            raise InputError("up_down split needs a record with an up and a down pass "
                             "(simulate with --ramp up_down)")
        fit, val = _validation(train, strata, cfg.val_fraction, g)
        splits.append(Split("up_down", train, test, fit, val))
    else:
        for sp in np.unique(samples.set_point_c[~is_ref]):
            test = idx[samples.set_point_c == sp]
            train = idx[samples.set_point_c != sp]
            fit, val = _validation(train, strata, cfg.val_fraction, g)
            splits.append(Split(f"leave_out_{sp:g}", train, test, fit, val))
    return splits


# ---------------------------------------------------------------------------------------
# regressors that are not estimators elsewhere
# ---------------------------------------------------------------------------------------
class TensorPolynomial:
    """POLY-2D: least-squares surface ``Nc = sum_{m<=M, n<=Nd} c_mn T^m N^n`` (spec 000 §4),
    inputs mapped to [-1, 1] with the training range (conditioning only)."""

    def __init__(self, *, degrees=(3, 1)):
        self.degrees = degrees

    def _design(self, X):
        Z = 2.0 * (np.asarray(X, float) - self.lo_) / self.span_ - 1.0
        m, n = self.degrees
        return np.column_stack([Z[:, 0] ** i * Z[:, 1] ** j for i in range(m + 1)
                                for j in range(n + 1)])

    def fit(self, X, y) -> TensorPolynomial:
        X = np.asarray(X, float)
        self.lo_ = X.min(axis=0)
        sp = X.max(axis=0) - self.lo_
        self.span_ = np.where(sp > 0, sp, 1.0)
        self.coef_ = np.linalg.lstsq(self._design(X), np.asarray(y, float), rcond=None)[0]
        return self

    def predict(self, X) -> np.ndarray:
        if not hasattr(self, "coef_"):
            raise RuntimeError("TensorPolynomial.predict called before fit")
        return self._design(X) @ self.coef_

    def to_dict(self) -> dict:
        return {"degrees": list(self.degrees), "lo": self.lo_.tolist(),
                "span": self.span_.tolist(), "coef": self.coef_.tolist()}

    @classmethod
    def from_dict(cls, d) -> TensorPolynomial:
        obj = cls(degrees=tuple(int(v) for v in d["degrees"]))
        obj.lo_ = np.asarray(d["lo"], float)
        obj.span_ = np.asarray(d["span"], float)
        obj.coef_ = np.asarray(d["coef"], float)
        return obj


class SeparatePolynomials:
    """POLY-SEP (industry practice, spec 000 §4): per training set point the bias K0 from
    the 0°/180° positions (else the intercept of a line fit) and the scale factor K1 by
    least squares over the positions, then cubic polynomials K0(T), K1(T) (the shared
    :class:`~inertialab.learn.poly.PolynomialRegressor`); ``a_hat = (N - K0(T))/K1(T)``
    and ``Nc_hat = K0c + K1c a_hat``. Needs the nominal ``a_i`` of the training rows."""

    def __init__(self, *, degree: int = 3):
        self.degree = degree

    def fit(self, T, N, a_i, set_point, ref: SingleAxisCoefficients) -> SeparatePolynomials:
        tt, k0s, k1s = [], [], []
        for sp in np.unique(set_point):
            m = set_point == sp
            a, n = a_i[m], N[m]
            zero = np.isclose(a, 0.0)
            if zero.sum() >= 2:
                k0 = float(np.mean(n[zero]))
                nz = ~zero
                if nz.sum() < 1:
                    continue
                k1 = float(np.sum(a[nz] * (n[nz] - k0)) / np.sum(a[nz] ** 2))
            else:
                if m.sum() < 2 or np.ptp(a) == 0:
                    continue
                k1, k0 = np.polyfit(a, n, 1)
            tt.append(float(np.mean(T[m])))
            k0s.append(k0)
            k1s.append(k1)
        if len(tt) <= self.degree:
            raise InputError(f"POLY-SEP needs more than {self.degree} training set points")
        tt = np.asarray(tt)
        self.k0_ = PolynomialRegressor(degree=self.degree, warn_extrapolation=False).fit(tt, k0s)
        self.k1_ = PolynomialRegressor(degree=self.degree, warn_extrapolation=False).fit(tt, k1s)
        self.ref_ = ref
        return self

    def predict(self, X) -> np.ndarray:
        X = np.asarray(X, float)
        a_hat = (X[:, 1] - self.k0_.predict(X[:, 0])) / self.k1_.predict(X[:, 0])
        return self.ref_.k0 + self.ref_.k1 * a_hat

    def to_dict(self) -> dict:
        return {"degree": self.degree, "k0": self.k0_.to_dict(), "k1": self.k1_.to_dict(),
                "ref": self.ref_.to_dict()}

    @classmethod
    def from_dict(cls, d) -> SeparatePolynomials:
        obj = cls(degree=int(d["degree"]))
        obj.k0_ = PolynomialRegressor.from_dict(d["k0"])
        obj.k1_ = PolynomialRegressor.from_dict(d["k1"])
        obj.k0_.warn_extrapolation = obj.k1_.warn_extrapolation = False
        obj.ref_ = SingleAxisCoefficients.from_dict(d["ref"])
        return obj


_REGRESSORS = {"anfis": ANFIS, "mlp-lm": MLPRegressorLM, "tensor-poly": TensorPolynomial,
               "poly-sep": SeparatePolynomials}


def _regressor_tag(reg) -> str:
    for k, v in _REGRESSORS.items():
        if isinstance(reg, v):
            return k
    raise TypeError(f"unsupported regressor {type(reg).__name__}")


# ---------------------------------------------------------------------------------------
# the compensation model
# ---------------------------------------------------------------------------------------
@dataclass
class ThermalModel:
    """A fitted integrated compensation model ``Nc = t(T, N)`` (spec 000 §1 eq. 7, §3.6).

    Attributes
    ----------
    method : model name (one of :data:`METHODS`)
    ref : 55 °C coefficients of the training unit (mV/g^k)
    regressor : the fitted map (ANFIS, MLPRegressorLM, TensorPolynomial, SeparatePolynomials)
    input, target, learn_drift : sample construction (see :class:`ThermalConfig`)
    t_range_c, n_range_mv : calibrated input range (training min/max) used for clamping
    reference_temp_c : 55 °C
    scm : SCM parameters of the fuzzy models (radius, squash, accept, reject)
    search : IAFSA search log (F*, nfev, nit, history) or None
    metrics : test metrics at fit time (JSON-ready)
    unit_id : the training unit
    """

    MODEL_TYPE = "thermal-compensation"

    method: str
    ref: SingleAxisCoefficients
    regressor: object
    input: str = "ua"
    target: str = "linear55"
    learn_drift: bool = False
    t_range_c: tuple[float, float] = (-40.0, 70.0)
    n_range_mv: tuple[float, float] = (-1e3, 1e3)
    reference_temp_c: float = 55.0
    scm: dict | None = None
    search: dict | None = None
    metrics: dict = field(default_factory=dict)
    unit_id: str = ""

    @property
    def n_rules(self) -> int | None:
        reg = self.regressor
        return int(reg.n_rules_) if isinstance(reg, ANFIS) else None

    def predict_nc(self, T, N) -> np.ndarray:
        """``t(T, N)`` in mV, no clamping (training-mode evaluation)."""
        X = np.column_stack([np.asarray(T, float).ravel(), np.asarray(N, float).ravel()])
        out = np.asarray(self.regressor.predict(X), float)
        return X[:, 1] + out if self.learn_drift else out

    def to_dict(self) -> dict:
        return {
            "method": self.method, "ref": self.ref.to_dict(), "input": self.input,
            "target": self.target, "learn_drift": bool(self.learn_drift),
            "t_range_c": [float(v) for v in self.t_range_c],
            "n_range_mv": [float(v) for v in self.n_range_mv],
            "reference_temp_c": float(self.reference_temp_c),
            "regressor_type": _regressor_tag(self.regressor),
            "regressor": self.regressor.to_dict(), "scm": self.scm, "search": self.search,
            "metrics": self.metrics, "unit_id": self.unit_id,
        }

    @classmethod
    def from_dict(cls, d: dict) -> ThermalModel:
        try:
            rcls = _REGRESSORS[d["regressor_type"]]
            return cls(
                method=d["method"], ref=SingleAxisCoefficients.from_dict(d["ref"]),
                regressor=rcls.from_dict(d["regressor"]), input=d["input"], target=d["target"],
                learn_drift=bool(d["learn_drift"]), t_range_c=tuple(d["t_range_c"]),
                n_range_mv=tuple(d["n_range_mv"]), reference_temp_c=float(d["reference_temp_c"]),
                scm=d.get("scm"), search=d.get("search"), metrics=d.get("metrics", {}),
                unit_id=d.get("unit_id", ""))
        except KeyError as exc:
            raise InputError(f"thermal model: missing key {exc}") from exc


# ---------------------------------------------------------------------------------------
# fitting
# ---------------------------------------------------------------------------------------
def _bounds(X: np.ndarray, y: np.ndarray):
    return np.vstack([X.min(axis=0), X.max(axis=0)]), (float(y.min()), float(y.max()))


def _decode(v: np.ndarray, radii: str) -> dict:
    """SCM parameters from a decision vector (with the eps_down < eps_up repair)."""
    if radii == "per_dim":
        r = [float(x) for x in v[:3]]
        squash, acc, rej = (float(x) for x in v[3:])
    else:
        r = float(v[0])
        squash, acc, rej = (float(x) for x in v[1:])
    if rej >= acc:
        rej = 0.5 * acc
    return {"radius": r, "squash": squash, "accept": acc, "reject": rej}


def _search_space(radii: str):
    if radii == "per_dim":
        return [SEARCH_BOUNDS[0]] * 3 + list(SEARCH_BOUNDS[1:]), [0.5, 0.5, 0.5, 1.25, 0.5, 0.15]
    return list(SEARCH_BOUNDS), [0.5, 1.25, 0.5, 0.15]


@dataclass(frozen=True)
class SearchResult:
    """IAFSA search over the SCM parameters (spec 000 §3.5): ``params`` found, ``fun`` =
    F* (validation RMSE, mg), ``f_default`` = F at the default parameters, ``n_rules``,
    ``nfev``, ``nit``, ``history`` (best F per generation), ``wall_s``."""

    params: dict
    fun: float
    f_default: float
    n_rules: int
    nfev: int
    nit: int
    history: list
    wall_s: float
    message: str

    def to_dict(self) -> dict:
        return asdict(self)


def search_scm(Xf, yf, Xv, yv, *, k1: float, bounds_x, bounds_y, config: ThermalConfig,
               rng=None, progress=None) -> SearchResult:
    """IAFSA over (r_a, eta, eps_up, eps_down) minimising the validation RMSE (mg) of a
    20-epoch SCM-ANFIS (spec 000 §3.5); fish 0 starts at the defaults."""
    cfg = config
    box, start = _search_space(cfg.radii)
    y_span = bounds_y[1] - bounds_y[0] if bounds_y[1] > bounds_y[0] else 1.0

    zb = np.zeros((2, 3))
    zb[1] = 1.0

    def n_clusters(m: ANFIS, p: dict) -> int:
        Z = np.column_stack([m._sx(np.asarray(Xf, float)), m._sy(np.asarray(yf, float))])
        return SubtractiveClustering(bounds=zb, **p).fit(Z).n_clusters_

    def F(v):
        p = _decode(np.asarray(v), cfg.radii)
        m = ANFIS(epochs=cfg.search_epochs, input_bounds=bounds_x, output_bounds=bounds_y, **p)
        m._set_scaling(np.asarray(Xf, float), np.asarray(yf, float))
        # count the rules before any least squares: R > R_max would cost O(R^3)
        R = n_clusters(m, p)
        if R < 2 or R > cfg.r_max:
            return PENALTY_MG
        m.fit(Xf, yf, validation=(Xv, yv))
        best = m.trace_.val_rmse[m.best_epoch_]
        return float(best * y_span / k1 * 1e3)

    t0 = time.perf_counter()
    f_default = F(np.asarray(start, float))
    gens = max(int(cfg.generations), 1)

    def cb(t, x, f):
        if progress is not None:
            progress.update(t, gens, f"IAFSA generation {t}: F* = {f * 1e3:.2f} µg")

    res = iafsa(F, box, pop_size=cfg.fish, max_generations=gens, rng=rng, x_init=start,
                memoize=1_000_000, callback=cb)
    p = _decode(res.x, cfg.radii)
    m = ANFIS(input_bounds=bounds_x, output_bounds=bounds_y, **p)
    m._set_scaling(np.asarray(Xf, float), np.asarray(yf, float))
    R = n_clusters(m, p)
    return SearchResult(params=p, fun=float(res.fun), f_default=float(f_default), n_rules=int(R),
                        nfev=int(res.nfev), nit=int(res.nit), history=res.history.tolist(),
                        wall_s=time.perf_counter() - t0, message=res.message)


def _target(s: ThermalSamples, learn_drift: bool) -> np.ndarray:
    return s.y_mv - s.n_mv if learn_drift else s.y_mv


def fit_model(samples: ThermalSamples, split: Split, method: str, config: ThermalConfig, *,
              rng=None, progress=None, scm_params: dict | None = None) -> ThermalModel:
    """Fit one model on a split (spec 000 §3.6, §4). ``scm_params`` skips the IAFSA search
    of ``iafsa-scm-anfis`` (bootstrap replicas reuse the parameters found)."""
    cfg = config
    X = samples.X
    y = _target(samples, cfg.learn_drift)
    tr, fi, va = split.train, split.fit, split.val
    bx, by = _bounds(X[tr], y[tr])
    scm = None
    search = None
    if method == "fis":
        scm = dict(SCM_DEFAULTS)
        reg = ANFIS(epochs=0, input_bounds=bx, output_bounds=by, **scm).fit(X[tr], y[tr])
    elif method == "anfis":
        reg = ANFIS(partition="grid", n_mfs=3, epochs=cfg.epochs, input_bounds=bx,
                    output_bounds=by).fit(X[fi], y[fi], validation=(X[va], y[va]))
    elif method == "scm-anfis":
        scm = dict(SCM_DEFAULTS)
        reg = ANFIS(epochs=cfg.epochs, input_bounds=bx, output_bounds=by, **scm).fit(
            X[fi], y[fi], validation=(X[va], y[va]))
    elif method == "iafsa-scm-anfis":
        if scm_params is None:
            sr = search_scm(X[fi], y[fi], X[va], y[va], k1=samples.k1, bounds_x=bx, bounds_y=by,
                            config=cfg, rng=rng, progress=progress)
            scm, search = sr.params, sr.to_dict()
        else:
            scm = dict(scm_params)
        reg = ANFIS(epochs=cfg.epochs, input_bounds=bx, output_bounds=by, **scm).fit(
            X[fi], y[fi], validation=(X[va], y[va]))
    elif method == "ann":
        reg = MLPRegressorLM(hidden=cfg.ann_hidden, max_epochs=cfg.ann_max_epochs, rng=rng).fit(
            X[fi], y[fi], validation=(X[va], y[va]))
    elif method == "poly-2d":
        reg = TensorPolynomial(degrees=tuple(cfg.poly2d_degrees)).fit(X[tr], y[tr])
    elif method == "poly-sep":
        if cfg.learn_drift or cfg.input == "raw":
            raise InputError("POLY-SEP needs input='ua' and learn_drift=False")
        reg = SeparatePolynomials(degree=cfg.poly_sep_degree).fit(
            samples.temp_c[tr], samples.n_mv[tr], samples.a_in_g[tr], samples.set_point_c[tr],
            samples.ref)
    else:
        raise InputError(f"unknown method {method!r}")
    return ThermalModel(
        method=method, ref=samples.ref, regressor=reg, input=cfg.input, target=cfg.target,
        learn_drift=cfg.learn_drift,
        t_range_c=(float(bx[0, 0] - cfg.range_margin_c), float(bx[1, 0] + cfg.range_margin_c)),
        n_range_mv=(float(bx[0, 1] - cfg.range_margin_frac * (bx[1, 1] - bx[0, 1])),
                    float(bx[1, 1] + cfg.range_margin_frac * (bx[1, 1] - bx[0, 1]))),
        reference_temp_c=cfg.reference_temp_c,
        scm=scm, search=search, unit_id=samples.unit_id)


# ---------------------------------------------------------------------------------------
# metrics
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ModelMetrics:
    """Spec 000 §5 metrics of one model on one sample set, acceleration units.

    ``rmse_ug``, ``me_ug``, ``ae_ug``, ``mbe_ug`` in µg; ``maxe_ppm``, ``mare_ppm`` over
    samples with |a_i| >= 0.25 g; ``rmse_truth_ug`` against the noise-free input
    (simulation only, else nan); ``rules`` (fuzzy models) and ``wall_s``.
    """

    rmse_ug: float
    me_ug: float
    ae_ug: float
    mbe_ug: float
    maxe_ppm: float
    mare_ppm: float
    rmse_truth_ug: float
    n: int
    rules: int | None = None
    wall_s: float = 0.0

    def to_dict(self) -> dict:
        return asdict(self)


def score(model: ThermalModel, samples: ThermalSamples, idx: np.ndarray, *, wall_s=0.0) -> ModelMetrics:
    """Metrics of ``model`` on the samples ``idx`` (spec 000 §5)."""
    from inertialab.metrics import error_summary, relative_errors

    pred = model.predict_nc(samples.temp_c[idx], samples.n_mv[idx])
    k1 = samples.k1
    e_true = samples.y_mv[idx] / k1 * 1e6
    e_pred = pred / k1 * 1e6
    s = error_summary(e_true, e_pred)
    rel = relative_errors(e_true, e_pred, samples.a_in_g[idx] * 1e6, min_reference=0.25e6)
    ta = samples.true_a_in_g[idx]
    if np.all(np.isfinite(ta)):
        truth = samples.ref.k0 + k1 * ta
        if samples.input == "raw":
            truth = truth + higher_order_terms(ta, samples.a_pend_g[idx], samples.ref)
        et = (pred - truth) / k1 * 1e6
        rt = float(np.sqrt(np.mean(et * et)))
    else:
        rt = float("nan")
    return ModelMetrics(rmse_ug=s.rmse, me_ug=s.me, ae_ug=s.ae, mbe_ug=s.mbe,
                        maxe_ppm=rel.maxe * 1e6, mare_ppm=rel.mare * 1e6, rmse_truth_ug=rt,
                        n=int(idx.size), rules=model.n_rules, wall_s=float(wall_s))


def raw_drift_rms_ug(samples: ThermalSamples, idx: np.ndarray) -> float:
    """RMS of the uncompensated error ``(N - Nc)/K1c`` on ``idx`` (µg)."""
    e = (samples.n_mv[idx] - samples.y_mv[idx]) / samples.k1 * 1e6
    return float(np.sqrt(np.mean(e * e)))


# ---------------------------------------------------------------------------------------
# fit of all requested models
# ---------------------------------------------------------------------------------------
@dataclass
class ThermalFit:
    """Result of :func:`fit_thermal`.

    ``models``: method -> ThermalModel fitted on the (first) split; ``metrics``: method ->
    ModelMetrics on the test set (pooled over folds for leave_one_T_out); ``predictions``:
    method -> test predictions (mV) aligned with ``test_index``; ``splits``; ``samples``;
    ``raw_rms_ug`` = uncompensated RMS on the test set; ``search``: the IAFSA log.
    """

    samples: ThermalSamples
    splits: list[Split]
    models: dict
    metrics: dict
    predictions: dict
    test_index: np.ndarray
    raw_rms_ug: float
    config: ThermalConfig
    search: dict | None = None

    def table(self) -> dict:
        """JSON-ready per-model metrics (the CLI's ``models`` key)."""
        return {m: v.to_dict() for m, v in self.metrics.items()}


def fit_thermal(samples: ThermalSamples, config: ThermalConfig | None = None, *,
                progress=None) -> ThermalFit:
    """Fit the requested models on the configured split and score them (spec 000 §3-§5).

    Random streams: ``SeedSequence(config.seed)`` spawns the split stream, then one
    stream per (fold, method) in the order of ``config.methods``.
    """
    cfg = (config or ThermalConfig()).validate()
    progress = progress or NullProgress()
    ss = np.random.SeedSequence(cfg.seed)
    split_ss, model_ss = ss.spawn(2)
    splits = make_splits(samples, cfg, rng=np.random.Generator(np.random.PCG64(split_ss)))
    n_folds = len(splits)
    streams = model_ss.spawn(n_folds * len(cfg.methods))
    preds = {m: [] for m in cfg.methods}
    models, walls, search = {}, {m: 0.0 for m in cfg.methods}, None
    total = n_folds * len(cfg.methods)
    done = 0
    for f, sp in enumerate(splits):
        for j, m in enumerate(cfg.methods):
            progress.update(done, total, f"{m} ({sp.name})")
            t0 = time.perf_counter()
            rng = np.random.Generator(np.random.PCG64(streams[f * len(cfg.methods) + j]))
            with single_threaded_blas():
                model = fit_model(samples, sp, m, cfg, rng=rng)
            walls[m] += time.perf_counter() - t0
            preds[m].append(model.predict_nc(samples.temp_c[sp.test], samples.n_mv[sp.test]))
            if f == 0:
                models[m] = model
                if model.search is not None:
                    search = model.search
            done += 1
    progress.update(total, total, "done")
    test = np.concatenate([sp.test for sp in splits])
    metrics = {}
    for m in cfg.methods:
        pm = np.concatenate(preds[m])
        proxy = _FixedPrediction(pm, test)
        met = score(proxy, samples, test, wall_s=walls[m])
        met = replace(met, rules=models[m].n_rules)
        metrics[m] = met
        models[m].metrics = met.to_dict()
        preds[m] = pm
    return ThermalFit(samples=samples, splits=splits, models=models, metrics=metrics,
                      predictions=preds, test_index=test, raw_rms_ug=raw_drift_rms_ug(samples, test),
                      config=cfg, search=search)


class _FixedPrediction:
    """Adapter so :func:`score` can score pooled fold predictions."""

    n_rules = None
    learn_drift = False

    def __init__(self, pred, idx):
        self._pred = pred

    def predict_nc(self, T, N):
        return self._pred


# ---------------------------------------------------------------------------------------
# compensation and transfer
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Compensation:
    """Compensated output of a record: ``nc_mv`` (t(T, N) at 55 °C), ``a_g`` (acceleration
    estimate), ``status`` (0 ok, 1 temperature clamped, 2 output clamped, 3 both),
    ``n_mv`` (model input after the A-frame mapping)."""

    nc_mv: np.ndarray
    a_g: np.ndarray
    status: np.ndarray
    n_mv: np.ndarray


def model_input(model: ThermalModel, output_mv, a_pend_g=None,
                unit_ref: SingleAxisCoefficients | None = None) -> np.ndarray:
    """N from a raw output in deployment (spec 000 §3.1, §3.7): ``a_i`` estimated from U
    by one fixed-point pass, Ua by eq. 5 with the unit's own 55 °C coefficients, then
    mapped into the model unit's frame ``N_A = K0c_A + K1c_A (Ua_B - K0c_B)/K1c_B``."""
    U = np.asarray(output_mv, float)
    ref_b = unit_ref or model.ref
    if model.input == "raw":
        if unit_ref is None:
            return U
        return model.ref.k0 + model.ref.k1 * (U - ref_b.k0) / ref_b.k1
    a_p = np.zeros_like(U) if a_pend_g is None else np.asarray(a_pend_g, float)
    a_i = estimate_input(U, a_p, ref_b, passes=1)
    ua = integrated_output(U, a_i, a_p, ref_b)
    return model.ref.k0 + model.ref.k1 * (ua - ref_b.k0) / ref_b.k1


def compensate(model: ThermalModel, temp_c, output_mv, a_pend_g=None, *,
               unit_ref: SingleAxisCoefficients | None = None, path="<data>") -> Compensation:
    """Compensate a unit's readings (spec 000 §3.7): clamp (T, N) to the calibrated range
    with a status flag, ``Nc_hat = t(T, N)``, ``a_hat = (Nc_hat - K0c)/K1c``.

    Raises InputError when every reading lies outside the calibrated temperature range
    (no silent extrapolation); partial excursions are clamped, flagged and warned about.
    """
    T = np.asarray(temp_c, float).ravel()
    N = model_input(model, output_mv, a_pend_g, unit_ref).ravel()
    if T.size != N.size:
        raise InputError("temperature and output have different lengths", path=path)
    if T.size == 0:
        raise InputError("no readings to compensate", path=path)
    tlo, thi = model.t_range_c
    nlo, nhi = model.n_range_mv
    t_out = (T < tlo) | (T > thi)
    n_out = (N < nlo) | (N > nhi)
    if np.all(t_out):
        raise InputError(
            f"every temperature lies outside the model's calibrated range {tlo:.2f}..{thi:.2f} °C",
            path=path, column="temp_meas_c")
    status = t_out * STATUS_T_CLAMPED + n_out * STATUS_N_CLAMPED
    if np.any(status):
        warnings.warn(f"{int(np.count_nonzero(status))} of {T.size} readings outside the "
                      "calibrated range were clamped (status column)", ExtrapolationWarning,
                      stacklevel=2)
    nc = model.predict_nc(np.clip(T, tlo, thi), np.clip(N, nlo, nhi))
    # raw-input models keep the 55 °C higher-order terms in Nc; with a_i unknown the
    # linear inverse is used for both (those terms are µg-level)
    a = (nc - model.ref.k0) / model.ref.k1
    return Compensation(nc_mv=nc, a_g=a, status=status.astype(int), n_mv=N)


@dataclass(frozen=True)
class DriftResult:
    """Raw and compensated drift relative to 55 °C per sample (spec 000 §5 "Drift"), in µg:
    ``raw_ug``, ``comp_ug``; the maxima ``raw_max_ug``, ``comp_max_ug``; ``set_point_c``,
    ``a_in_g`` of each sample; ``status`` of the compensation."""

    raw_ug: np.ndarray
    comp_ug: np.ndarray
    raw_max_ug: float
    comp_max_ug: float
    set_point_c: np.ndarray
    a_in_g: np.ndarray
    status: np.ndarray

    def summary(self) -> dict:
        return {"raw_max_drift_ug": self.raw_max_ug, "comp_max_drift_ug": self.comp_max_ug}


def drift(model: ThermalModel, samples: ThermalSamples, *, own_unit: bool = False) -> DriftResult:
    """Raw vs compensated drift of a unit's samples (the transfer test of spec 000 §3.7 when
    ``samples`` come from another unit; ``own_unit`` compensates with the model unit's
    coefficients). Uses the nominal a_p of the tumble for Ua."""
    ref_b = None if own_unit else samples.ref
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)
        comp = compensate(model, samples.temp_c, samples.output_mv, samples.a_pend_g,
                          unit_ref=ref_b)
    k1b = samples.k1
    ua = integrated_output(samples.output_mv, samples.a_in_g, samples.a_pend_g, samples.ref)
    is55 = np.isclose(samples.set_point_c, model.reference_temp_c, atol=1e-6)
    key = [f"{r}|{p}" for r, p in zip(samples.ramp_dir, samples.pos_index)]
    ref_pos = {}
    for i in np.flatnonzero(is55):
        ref_pos.setdefault(f"{samples.ramp_dir[i]}|{samples.pos_index[i]}", i)
    first_dir = samples.ramp_dir[0]
    base = np.array([ref_pos.get(k, ref_pos.get(f"{first_dir}|{p}"))
                     for k, p in zip(key, samples.pos_index)])
    if np.any(base == None):  # noqa: E711
        raise MissingReferenceError("drift: positions without a 55 °C reading")
    base = base.astype(int)
    raw = (ua - ua[base]) / k1b * 1e6
    comp_ug = (comp.a_g - comp.a_g[base]) * 1e6
    return DriftResult(raw_ug=raw, comp_ug=comp_ug, raw_max_ug=float(np.max(np.abs(raw))),
                       comp_max_ug=float(np.max(np.abs(comp_ug))), set_point_c=samples.set_point_c,
                       a_in_g=samples.a_in_g, status=comp.status)


def recalibrate(model: ThermalModel, samples_b: ThermalSamples, *,
                set_points=(-40.0, 15.0, 70.0), rcond: float = 1e-2) -> ThermalModel:
    """Few-point recalibration for transfer (spec 000 §8.4): keep unit A's premises and
    refit only the consequents by least squares on unit B's samples at ``set_points``
    (mapped into A's frame as in §3.7). Returns a model to apply to B with
    ``unit_ref = samples_b.ref`` (as :func:`drift` does).

    Plain least squares of all consequents on three set points extrapolates wildly
    between them (measured: 23 µg -> 1.5 mg on the paper preset), so the change of A's
    consequents is the minimum-norm solution truncated at ``rcond`` (relative singular
    value, default 1e-2): directions the three set points do not see keep A's values.
    Measured on the realistic preset (lot 0, unit 1): 386 -> 208 µg max drift, short of
    the spec's 10x because the a_p-dependent misalignment drift (~95 µg at -40 °C) is not a
    function of (T, N)."""
    reg = model.regressor
    if not isinstance(reg, ANFIS):
        raise InputError("few-point recalibration needs a fuzzy model (fis, anfis, scm-anfis, "
                         "iafsa-scm-anfis)")
    m = np.zeros(samples_b.n, dtype=bool)
    for sp in set_points:
        m |= np.isclose(samples_b.set_point_c, sp, atol=1e-6)
    if not np.any(m):
        raise InputError(f"none of the recalibration set points {list(set_points)} is in the record")
    ra, rb = model.ref, samples_b.ref
    n_a = ra.k0 + ra.k1 * (samples_b.n_mv[m] - rb.k0) / rb.k1
    y_a = ra.k0 + ra.k1 * (samples_b.y_mv[m] - rb.k0) / rb.k1
    target = y_a - n_a if model.learn_drift else y_a
    new = ANFIS.from_dict(reg.to_dict())
    X = new._sx(np.column_stack([samples_b.temp_c[m], n_a]))
    fis = new.fis_
    A = fis.design(X)
    theta0 = fis.consequents.ravel()
    resid = new._sy(target) - A @ theta0
    # smallest change of A's consequents that fits B (truncated SVD): directions the three
    # set points cannot see stay at A's values instead of being extrapolated
    delta = np.linalg.lstsq(A, resid, rcond=rcond)[0]
    fis.consequents = (theta0 + delta).reshape(fis.consequents.shape)
    return replace(model, regressor=new, unit_id=samples_b.unit_id, search=None, metrics={})


# ---------------------------------------------------------------------------------------
# bootstrap uncertainty (spec 000 §8.4)
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class BootstrapResult:
    """Bootstrap over set-point blocks: ``std_ug`` of the compensated output per sample,
    ``band_lo_ug``/``band_hi_ug`` = 2.5/97.5 % of the compensated drift per sample,
    ``n_boot`` replicas, ``method``."""

    std_ug: np.ndarray
    band_lo_ug: np.ndarray
    band_hi_ug: np.ndarray
    n_boot: int
    method: str

    def summary(self) -> dict:
        return {"n_boot": self.n_boot, "method": self.method,
                "median_std_ug": float(np.median(self.std_ug)),
                "max_band_halfwidth_ug": float(np.max(self.band_hi_ug - self.band_lo_ug) / 2)}


def bootstrap(samples: ThermalSamples, model: ThermalModel, config: ThermalConfig, *,
              n_boot: int = 50, epochs: int | None = None, rng=None) -> BootstrapResult:
    """Resample the temperature blocks (set points, the reference always kept) with
    replacement, refit ``model.method`` with its SCM parameters fixed, and collect the
    compensated drift of every sample (spec 000 §8.4)."""
    cfg = replace(config, epochs=epochs if epochs is not None else config.epochs)
    g = as_generator(rng)
    sps = np.unique(samples.set_point_c)
    is_ref = np.isclose(sps, cfg.reference_temp_c, atol=1e-6)
    others = sps[~is_ref]
    ref_sp = sps[is_ref]
    preds = []
    for _ in range(n_boot):
        pick = np.concatenate([ref_sp, g.choice(others, size=others.size, replace=True)])
        idx = np.concatenate([np.flatnonzero(samples.set_point_c == s) for s in pick])
        strata = _strata(samples)
        fit, val = _validation(idx, strata, cfg.val_fraction, g)
        # a resampled block appears more than once: keep duplicates in fit, val from distinct
        sp = Split("bootstrap", idx, np.arange(samples.n), fit if fit.size else idx, val)
        with single_threaded_blas():
            m = fit_model(samples, sp, model.method, cfg, rng=g, scm_params=model.scm)
        d = drift(m, samples, own_unit=True)
        preds.append(d.comp_ug)
    P = np.asarray(preds)
    return BootstrapResult(std_ug=P.std(axis=0, ddof=1), band_lo_ug=np.percentile(P, 2.5, axis=0),
                           band_hi_ug=np.percentile(P, 97.5, axis=0), n_boot=int(n_boot),
                           method=model.method)


# ---------------------------------------------------------------------------------------
# demo study
# ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class QuickSettings:
    """Demo settings (quick: <= 8 s on 2 cores): paper preset, lot seed 0, unit 0 trains,
    unit 1 is the transfer unit; a shortened IAFSA (6 fish, 6 generations, 10-epoch
    objective) and 60 final epochs; no bootstrap."""

    preset: str = "paper"
    lot_seed: int = 0
    run_seed: int = 0
    split: str = "random"
    methods: tuple[str, ...] = METHODS
    fish: int = 6
    generations: int = 5
    search_epochs: int = 10
    epochs: int = 60
    ann_max_epochs: int = 100
    n_boot: int = 0
    boot_epochs: int = 20


@dataclass(frozen=True)
class FullSettings(QuickSettings):
    """Full demo (<= 25 s): 8 fish x 10 generations, 20-epoch objective, 150 final epochs,
    ANN up to 500 LM iterations, 10 bootstrap replicas of 20 epochs."""

    fish: int = 8
    generations: int = 10
    search_epochs: int = 20
    epochs: int = 150
    ann_max_epochs: int = 500
    n_boot: int = 10


def run_demo(settings=None, progress=None) -> StudyResult:
    """The thermal study on the virtual lab (for ``inertialab demo``)."""
    from inertialab.sim.thermal_tumble import simulate

    st = settings or QuickSettings()
    progress = progress or NullProgress()
    t0 = time.perf_counter()
    run_a = simulate(st.preset, st.lot_seed, 0, seed=st.run_seed)
    run_b = simulate(st.preset, st.lot_seed, 1, seed=st.run_seed + 1000)
    cfg = ThermalConfig(methods=tuple(st.methods), split=st.split, fish=st.fish,
                        generations=st.generations, search_epochs=st.search_epochs,
                        epochs=st.epochs, ann_max_epochs=st.ann_max_epochs, seed=st.run_seed)
    sa = prepare_samples(run_a.frame, cfg)
    sb = prepare_samples(run_b.frame, cfg)
    fit = fit_thermal(sa, cfg, progress=progress)
    best = "iafsa-scm-anfis" if "iafsa-scm-anfis" in fit.models else next(iter(fit.models))
    model = fit.models[best]
    own = drift(model, sa, own_unit=True)
    transfer = drift(model, sb)
    boot = None
    if st.n_boot > 0 and best in FUZZY:
        boot = bootstrap(sa, model, cfg, n_boot=st.n_boot, epochs=st.boot_epochs, rng=st.run_seed)
    tables = {
        "models": fit.table(),
        "raw_rms_ug": fit.raw_rms_ug,
        "noise_floor_ug": run_a.noise_floor_ug,
        "search": fit.search,
        "transfer": transfer.summary(),
        "own_unit": own.summary(),
        "bootstrap": boot.summary() if boot else None,
    }
    head = [Headline(f"test RMSE {m.upper()}", round(fit.metrics[m].rmse_ug, 2),
                     None if m not in PAPER_RMSE_MG else PAPER_RMSE_MG[m] * 1e3, "µg")
            for m in fit.metrics]
    head.append(Headline("transfer max drift (unit 1)", round(transfer.comp_max_ug, 1), 9.3, "µg"))
    text = [
        f"Virtual lab, {st.preset} preset, lot seed {st.lot_seed}: unit 0 trains the models "
        f"({st.split} split, 23 set points x 24 positions), unit 1 is compensated with unit 0's "
        f"{best.upper()} model. Noise floor of the record: {run_a.noise_floor_ug:.1f} µg.",
        "The paper reports test RMSE 0.138 / 0.101 / 0.034 / 0.004 mg for ANN / FIS / ANFIS / "
        "IAFSA-SCM-ANFIS and a transfer drift of 9.3 µg; the ordering, not the exact numbers, "
        "is the reproduction target (split ratio, fish parameters and ANN structure are lost).",
    ]
    data = {"fit": fit, "samples": sa, "samples_b": sb, "own": own, "transfer": transfer,
            "bootstrap": boot, "best": best}
    return StudyResult(name="thermal", title="Quartz accelerometer temperature drift (spec 000)",
                       settings=settings_dict(st) | {"config": settings_dict(cfg)}, headline=head,
                       tables=tables, data=data, text=text, wall_s=time.perf_counter() - t0)


STUDY = Study(name="thermal", title="Quartz accelerometer temperature drift (spec 000)",
              quick=QuickSettings(), full=FullSettings(), run=run_demo)

__all__ = [
    "METHODS", "STUDY", "BootstrapResult", "Compensation", "DriftResult",
    "ModelMetrics", "SearchResult", "SeparatePolynomials", "Split", "TensorPolynomial",
    "ThermalConfig", "ThermalFit", "ThermalModel", "ThermalSamples", "bootstrap", "compensate",
    "drift", "fit_model", "fit_thermal", "make_splits", "recalibrate", "prepare_samples", "score",
    "search_scm",
]
