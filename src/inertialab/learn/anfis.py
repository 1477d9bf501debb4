"""ANFIS: adaptive-network fuzzy inference with Jang's hybrid learning.

The network is a first-order TSK system (:class:`~inertialab.learn.fis.TSKFIS`) with
Gaussian premises. One batch epoch (spec 000 §3.4):

1. forward pass: premises fixed, consequents by least squares (optimal for them);
2. backward pass: gradient of ``E = 1/2 sum (y - t)^2`` with respect to every MF
   centre and width (consequents fixed), summed over the rules sharing an MF;
3. normalised step ``alpha <- alpha - k g/||g||``, widths clamped at ``sigma_min``;
4. Jang's step-size heuristics (:class:`StepSizeRule`): ``k *= 1.1`` after four
   consecutive decreases of the training RMSE, ``k *= 0.9`` after the pattern
   up, down, up, down.

The model of the epoch with the lowest validation RMSE is returned ("epoch e" = the
premises after e updates with their least-squares consequents; epoch 0 is the initial
FIS, so training never makes validation worse; ties go to the earliest epoch).

Hand-written: no maintained Python package implements ANFIS with the hybrid rule and
MATLAB's step-size heuristics, and the learner must be cheap enough to run inside
the IAFSA objective thousands of times (spec 000 §8.2.5).

References
----------
J.-S. R. Jang, "ANFIS: adaptive-network-based fuzzy inference system", IEEE Trans.
SMC 23 (1993) 665-685; MATLAB ``anfis`` (initial step 0.01, decrease 0.9, increase
1.1). Spec 000 §3.4.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from inertialab.errors import InputError, NotFittedError
from inertialab.estimator import Estimator
from inertialab.io.model_schemas import check_own_payload
from inertialab.learn.fis import TSKFIS, _as_2d, genfis, grid_fis, solve_lstsq


class StepSizeRule:
    """Jang's step-size heuristics (spec 000 §3.4 step 4).

    ``update(err)`` records the training error of an epoch and returns the step size
    to use for that epoch's premise update. After four consecutive decreases the step
    grows by ``inc``; after the sign pattern increase, decrease, increase, decrease it
    shrinks by ``dec``. After any change the history restarts from the latest error.
    """

    def __init__(self, k0: float = 0.01, *, inc: float = 1.1, dec: float = 0.9):
        self.k = float(k0)
        self.inc = float(inc)
        self.dec = float(dec)
        self._errs: list[float] = []

    def update(self, err: float) -> float:
        self._errs.append(float(err))
        e = self._errs
        if len(e) >= 5:
            d = np.sign(np.diff(e[-5:]))
            if np.all(d < 0):
                self.k *= self.inc
                self._errs = [e[-1]]
            elif d[0] > 0 and d[1] < 0 and d[2] > 0 and d[3] < 0:
                self.k *= self.dec
                self._errs = [e[-1]]
        return self.k


def premise_gradient(fis: TSKFIS, X, t, *, wb=None) -> tuple[np.ndarray, np.ndarray]:
    """Gradient of ``E = 1/2 sum_s (y_s - t_s)^2`` w.r.t. MF centres and widths.

    Consequents are held fixed. Returns ``(dE/dc, dE/dsigma)``, each of shape (M,)
    (one value per membership function, summed over the rules that use it). ``wb``
    (normalised firing strengths at ``X``) may be passed when already computed.
    """
    X = _as_2d(X)
    if wb is None:
        wb = fis.normalized_firing(X)
    F = fis.rule_outputs(X)
    yhat = np.sum(wb * F, axis=1)
    coef = (yhat - np.asarray(t, dtype=float).ravel())[:, None] * (F - yhat[:, None]) * wb
    m = fis.mf_center.size
    gc = np.zeros(m)
    gs = np.zeros(m)
    for j in range(fis.n_inputs):
        idx = fis.rule_mf[:, j]
        c = fis.mf_center[idx]
        s = fis.mf_sigma[idx]
        dx = X[:, j, None] - c
        np.add.at(gc, idx, np.sum(coef * dx, axis=0) / s**2)
        np.add.at(gs, idx, np.sum(coef * dx * dx, axis=0) / s**3)
    return gc, gs


def _rmse(fis: TSKFIS, X, y) -> float:
    e = fis.predict(X) - y
    return float(np.sqrt(np.mean(e * e)))


@dataclass(frozen=True)
class HybridTrace:
    """Per-epoch record of a hybrid-learning run (epoch 0 = the initial FIS).

    ``train_rmse`` and ``val_rmse`` (nan without validation data) have length
    ``epochs_run + 1``; ``step_size`` the step used after each epoch (length
    ``epochs_run``); ``best_epoch`` the epoch returned.
    """

    train_rmse: np.ndarray
    val_rmse: np.ndarray
    step_size: np.ndarray
    best_epoch: int


def train_hybrid(fis: TSKFIS, X, y, *, epochs: int = 150, validation=None,
                 step_size: float = 0.01, step_inc: float = 1.1, step_dec: float = 0.9,
                 sigma_min: float = 1e-3, error_goal: float = 0.0) -> tuple[TSKFIS, HybridTrace]:
    """Jang's hybrid learning of ``fis`` on ``(X, y)`` (spec 000 §3.4).

    Returns the FIS of the best epoch (lowest validation RMSE, else lowest training
    RMSE) and the :class:`HybridTrace`. ``fis`` itself is not modified.
    """
    X = _as_2d(X)
    y = np.asarray(y, dtype=float).ravel()
    if y.size != X.shape[0]:
        raise InputError(f"X has {X.shape[0]} rows but y has {y.size}")
    if epochs < 0:
        raise InputError(f"epochs must be >= 0, got {epochs}")
    if validation is not None:
        Xv = _as_2d(validation[0], "X_val")
        yv = np.asarray(validation[1], dtype=float).ravel()
        if Xv.shape[0] != yv.size or yv.size == 0:
            raise InputError("validation X and y must be non-empty with equal lengths")
    cur = fis.copy()
    rule = StepSizeRule(step_size, inc=step_inc, dec=step_dec)
    tr, va, ks = [], [], []
    best, best_score = None, np.inf
    Xe = np.hstack([X, np.ones((X.shape[0], 1))])
    n_th = X.shape[1] + 1
    for e in range(epochs + 1):
        wb = cur.normalized_firing(X)
        A = (wb[:, :, None] * Xe[:, None, :]).reshape(X.shape[0], -1)
        theta = solve_lstsq(A, y)
        cur.consequents = theta.reshape(cur.n_rules, n_th)
        r = A @ theta - y
        err = float(np.sqrt(np.mean(r * r)))
        tr.append(err)
        verr = _rmse(cur, Xv, yv) if validation is not None else np.nan
        va.append(verr)
        score = verr if validation is not None else err
        if score < best_score:
            best_score, best = score, (e, cur.copy())
        if e == epochs or err <= error_goal:
            break
        k = rule.update(err)
        ks.append(k)
        gc, gs = premise_gradient(cur, X, y, wb=wb)
        norm = np.sqrt(np.sum(gc * gc) + np.sum(gs * gs))
        if not np.isfinite(norm) or norm == 0.0:
            break
        cur.mf_center = cur.mf_center - k * gc / norm
        cur.mf_sigma = np.maximum(cur.mf_sigma - k * gs / norm, sigma_min)
    if best is None:  # every score was nan/inf: keep the initial system
        best = (0, cur)
    trace = HybridTrace(np.asarray(tr), np.asarray(va), np.asarray(ks), int(best[0]))
    return best[1], trace


@dataclass(frozen=True)
class ScaledRules:
    """A fitted ANFIS as plain numbers (read-only copies), for code that evaluates it
    elsewhere (:mod:`inertialab.export.thermal_c`): per rule ``i`` and input ``j`` the
    Gaussian premise ``exp(-((x_j - centers[i, j]) / sigmas[i, j])^2 / 2)`` and the
    consequent ``consequents[i] . (x_1 .. x_n, 1)``, in scaled units ``x = (X - x_lo) /
    x_span``; the output is ``y_lo + y_span * (normalised sum)`` in the training units.

    Attributes
    ----------
    centers, sigmas : ndarray (n_rules, n_inputs)
    consequents : ndarray (n_rules, n_inputs + 1)
    x_lo, x_span : ndarray (n_inputs,)
    y_lo, y_span : float
    """

    centers: np.ndarray
    sigmas: np.ndarray
    consequents: np.ndarray
    x_lo: np.ndarray
    x_span: np.ndarray
    y_lo: float
    y_span: float

    @property
    def n_rules(self) -> int:
        return int(self.centers.shape[0])

    @property
    def n_inputs(self) -> int:
        return int(self.centers.shape[1])


def _frozen(a) -> np.ndarray:
    out = np.array(a, dtype=float)
    out.flags.writeable = False
    return out


class ANFIS(Estimator):
    """ANFIS regressor: first-order TSK system trained by Jang's hybrid rule.

    Parameters
    ----------
    partition : {"cluster", "grid"}, default="cluster"
        Initial premise: subtractive clustering + genfis2 (spec 000 §3.2-3.3) or a grid
        of ``n_mfs`` Gaussian MFs per input (spec 000 §4 ANFIS baseline).
    n_mfs : int or sequence of int, default=3
        MFs per input of the grid partition.
    radius, squash, accept, reject
        Subtractive-clustering parameters of the cluster partition, defaults 0.5, 1.25,
        0.5, 0.15 (spec 000 §3.2, MATLAB).
    epochs : int, default=150
        Hybrid-learning epochs (spec 000 §3.4 final training; 20 inside IAFSA).
    step_size, step_inc, step_dec : float, default=0.01, 1.1, 0.9
        Jang's initial step and its heuristics (MATLAB ``anfis`` defaults).
    sigma_min : float, default=1e-3
        Lower clamp of the MF widths in scaled units.
    error_goal : float, default=0.0
        Stop when the training RMSE (scaled units) reaches it.
    scale : bool, default=True
        Map every input and the output linearly to [0, 1] with ``input_bounds`` /
        ``output_bounds`` (default: training min/max) before learning (spec 000 §3.1
        step 5); predictions are returned in the original units.
    input_bounds : array-like (2, n_in) or None
    output_bounds : (lo, hi) or None

    Attributes
    ----------
    fis_ : TSKFIS
        The trained system in scaled units.
    best_epoch_ : int
    trace_ : HybridTrace
    n_rules_ : int

    Examples
    --------
    A smooth surface ``y = x1^2 + 0.5 x2`` learnt from 200 noise-free points, checked on 50
    new ones:

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> X = rng.uniform(-1.0, 1.0, (200, 2))
    >>> y = X[:, 0] ** 2 + 0.5 * X[:, 1]
    >>> X_new = rng.uniform(-0.9, 0.9, (50, 2))
    >>> y_new = X_new[:, 0] ** 2 + 0.5 * X_new[:, 1]
    >>> fis = ANFIS(epochs=20).fit(X, y)
    >>> rms = float(np.sqrt(np.mean((fis.predict(X_new) - y_new) ** 2)))
    >>> rms < 0.01, fis.n_rules_ > 1
    (True, True)
    """

    MODEL_TYPE = "anfis"

    def __init__(self, *, partition: str = "cluster", n_mfs=3, radius=0.5, squash: float = 1.25,
                 accept: float = 0.5, reject: float = 0.15, epochs: int = 150,
                 step_size: float = 0.01, step_inc: float = 1.1, step_dec: float = 0.9,
                 sigma_min: float = 1e-3, error_goal: float = 0.0, scale: bool = True,
                 input_bounds=None, output_bounds=None):
        self.partition = partition
        self.n_mfs = n_mfs
        self.radius = radius
        self.squash = squash
        self.accept = accept
        self.reject = reject
        self.epochs = epochs
        self.step_size = step_size
        self.step_inc = step_inc
        self.step_dec = step_dec
        self.sigma_min = sigma_min
        self.error_goal = error_goal
        self.scale = scale
        self.input_bounds = input_bounds
        self.output_bounds = output_bounds

    # scaling ----------------------------------------------------------------------------
    def _sx(self, X) -> np.ndarray:
        return (X - self.x_lo_) / self.x_span_

    def _sy(self, y) -> np.ndarray:
        return (y - self.y_lo_) / self.y_span_

    def _set_scaling(self, X, y) -> None:
        n_in = X.shape[1]
        if self.scale:
            if self.input_bounds is None:
                lo, hi = X.min(axis=0), X.max(axis=0)
            else:
                b = np.asarray(self.input_bounds, dtype=float)
                if b.shape != (2, n_in):
                    raise InputError(f"input_bounds must have shape (2, {n_in})")
                lo, hi = b[0], b[1]
            if self.output_bounds is None:
                ylo, yhi = float(y.min()), float(y.max())
            else:
                ylo, yhi = (float(v) for v in self.output_bounds)
        else:
            lo, hi = np.zeros(n_in), np.ones(n_in)
            ylo, yhi = 0.0, 1.0
        span = hi - lo
        self.x_lo_ = np.asarray(lo, dtype=float)
        self.x_span_ = np.where(span > 0, span, 1.0)
        self.y_lo_ = ylo
        self.y_span_ = (yhi - ylo) if yhi > ylo else 1.0

    def initial_fis(self, X, y) -> TSKFIS:
        """The untrained FIS (scaled units) this estimator starts from."""
        Xs, ys = self._sx(X), self._sy(y)
        if self.partition == "cluster":
            n_in = X.shape[1]
            bounds = np.zeros((2, n_in + 1))
            bounds[1] = 1.0
            if not self.scale:
                bounds = None
            return genfis(Xs, ys, radius=self.radius, squash=self.squash, accept=self.accept,
                          reject=self.reject, bounds=bounds)
        if self.partition == "grid":
            b = np.vstack([np.zeros(X.shape[1]), np.ones(X.shape[1])]) if self.scale else None
            return grid_fis(Xs, ys, n_mfs=self.n_mfs, bounds=b)
        raise InputError(f"partition must be 'cluster' or 'grid', got {self.partition!r}")

    def fit(self, X, y, *, validation=None, init_fis: TSKFIS | None = None) -> ANFIS:
        """Train on ``X`` (n, n_in), ``y`` (n,); ``validation=(X_val, y_val)`` selects the
        best epoch; ``init_fis`` (scaled units) replaces the initial partition."""
        X = _as_2d(X)
        y = np.asarray(y, dtype=float).ravel()
        if y.size != X.shape[0]:
            raise InputError(f"X has {X.shape[0]} rows but y has {y.size}")
        if not np.all(np.isfinite(y)):
            raise InputError("y contains NaN or infinite values")
        self._set_scaling(X, y)
        fis0 = init_fis.copy() if init_fis is not None else self.initial_fis(X, y)
        val = None
        if validation is not None:
            Xv = _as_2d(validation[0], "X_val")
            val = (self._sx(Xv), self._sy(np.asarray(validation[1], dtype=float).ravel()))
        self.fis_, self.trace_ = train_hybrid(
            fis0, self._sx(X), self._sy(y), epochs=int(self.epochs), validation=val,
            step_size=self.step_size, step_inc=self.step_inc, step_dec=self.step_dec,
            sigma_min=self.sigma_min, error_goal=self.error_goal)
        self.best_epoch_ = self.trace_.best_epoch
        self.n_rules_ = self.fis_.n_rules
        self.n_features_in_ = X.shape[1]
        return self

    def predict(self, X) -> np.ndarray:
        """Output (n,) in the units of the training ``y``."""
        if not hasattr(self, "fis_"):
            raise NotFittedError("ANFIS.predict called before fit")
        X = _as_2d(X)
        if X.shape[1] != self.n_features_in_:
            raise InputError(f"expected {self.n_features_in_} input columns, got {X.shape[1]}")
        return self.y_lo_ + self.y_span_ * self.fis_.predict(self._sx(X))

    def rules(self) -> ScaledRules:
        """The fitted system as :class:`ScaledRules` (read-only copies)."""
        if not hasattr(self, "fis_"):
            raise NotFittedError("ANFIS.rules called before fit")
        fis = self.fis_
        return ScaledRules(_frozen(fis.mf_center[fis.rule_mf]), _frozen(fis.mf_sigma[fis.rule_mf]),
                           _frozen(fis.consequents), _frozen(self.x_lo_), _frozen(self.x_span_),
                           float(self.y_lo_), float(self.y_span_))

    # model-file support --------------------------------------------------------------
    def to_dict(self) -> dict:
        if not hasattr(self, "fis_"):
            raise NotFittedError("ANFIS.to_dict called before fit")
        params = {k: getattr(self, k) for k in (
            "partition", "n_mfs", "radius", "squash", "accept", "reject", "epochs", "step_size",
            "step_inc", "step_dec", "sigma_min", "error_goal", "scale")}
        for k, v in params.items():
            if isinstance(v, np.ndarray):
                params[k] = v.tolist()
        return {
            "params": params,
            "x_lo": self.x_lo_.tolist(), "x_span": self.x_span_.tolist(),
            "y_lo": float(self.y_lo_), "y_span": float(self.y_span_),
            "best_epoch": int(self.best_epoch_),
            "fis": self.fis_.to_dict(),
        }

    @classmethod
    def from_dict(cls, d: dict) -> ANFIS:
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        try:
            obj = cls(**d["params"])
            obj.x_lo_ = np.asarray(d["x_lo"], dtype=float)
            obj.x_span_ = np.asarray(d["x_span"], dtype=float)
            obj.y_lo_ = float(d["y_lo"])
            obj.y_span_ = float(d["y_span"])
            obj.best_epoch_ = int(d["best_epoch"])
            obj.fis_ = TSKFIS.from_dict(d["fis"])
        except (KeyError, TypeError) as exc:
            raise InputError(f"anfis model: malformed payload ({exc})") from exc
        obj.n_rules_ = obj.fis_.n_rules
        obj.n_features_in_ = obj.x_lo_.size
        return obj
