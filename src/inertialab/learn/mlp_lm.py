"""One-hidden-layer tanh network trained by Levenberg-Marquardt (MATLAB ``trainlm``).

The network is MATLAB's default fitting/NAR net: inputs mapped to [-1, 1]
(``mapminmax``), a ``tansig`` (= tanh) hidden layer of ``hidden`` neurons, a linear
(``purelin``) output. It serves the ANN baseline of spec 000 and the NAR forecaster of
spec 004 (one learner shared by the studies).

Training follows spec 004 §3.6 exactly: Nguyen-Widrow initialisation (§3.5), the
Marquardt step ``delta = -(J'J + mu I)^-1 J'r`` with MATLAB's mu schedule, and
validation early stopping that returns the parameters of the lowest validation MSE.

Why hand-written: ``scipy.optimize.least_squares(method="lm")`` (MINPACK) has no
per-iteration hook, so neither trainlm's validation early stopping (``max_fail``) nor
its mu schedule and stop reasons can be reproduced with it. The Marquardt step solves
``(J'J + mu I) delta = -J'r`` (the normal equations of the augmented least-squares
problem ``[J; sqrt(mu) I] delta = -[r; 0]`` of the spec), as MATLAB's trainlm does:
``J'J`` and ``J'r`` are formed once per epoch and each trial mu costs one P x P solve.
(A thin SVD per epoch was measured 25x slower for the 90 x 41 problems of spec 004 on
the project's 2-core machine, which dominated NAR training time.)

References
----------
Spec 004 §3.2-3.6 (structure, normalisation, initialisation, training); spec 000 §4
(ANN baseline). Nguyen & Widrow (1990), IJCNN, vol. 3, pp. 21-26. MATLAB ``trainlm``
documentation (defaults mu = 1e-3, mu_dec = 0.1, mu_inc = 10, mu_max = 1e10,
epochs = 1000, min_grad = 1e-7, max_fail = 6).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from inertialab.errors import DataQualityWarning, InputError, NotFittedError
from inertialab.estimator import Estimator
from inertialab.io.model_schemas import check_own_payload
from inertialab.seeding import as_generator

__all__ = [
    "LMReport",
    "MLPRegressorLM",
    "forward",
    "jacobian",
    "n_params",
    "nguyen_widrow",
    "pack",
    "unpack",
]


# --------------------------------------------------------------------------------------
# parameter vector: theta = (vec_row(W1), b1, W2, b2), P = S (d + 2) + 1   (spec 004 §3.2)
# --------------------------------------------------------------------------------------

def n_params(n_inputs: int, hidden: int) -> int:
    """Number of parameters ``P = S (d + 2) + 1`` of a d-S-1 network."""
    return hidden * (n_inputs + 2) + 1


def pack(W1: np.ndarray, b1: np.ndarray, W2: np.ndarray, b2: float) -> np.ndarray:
    """Flatten the layers into ``theta = (vec_row(W1), b1, W2, b2)``."""
    return np.concatenate([np.ravel(W1), np.ravel(b1), np.ravel(W2), [float(b2)]])


def unpack(theta: np.ndarray, n_inputs: int, hidden: int):
    """Inverse of :func:`pack`: ``(W1 (S, d), b1 (S,), W2 (S,), b2)``."""
    S, d = hidden, n_inputs
    theta = np.asarray(theta, dtype=float)
    if theta.size != n_params(d, S):
        raise ValueError(f"theta has {theta.size} entries, a {d}-{S}-1 net needs {n_params(d, S)}")
    W1 = theta[: S * d].reshape(S, d)
    b1 = theta[S * d: S * d + S]
    W2 = theta[S * d + S: S * d + 2 * S]
    b2 = float(theta[-1])
    return W1, b1, W2, b2


def forward(theta: np.ndarray, X: np.ndarray, hidden: int) -> np.ndarray:
    """Network output ``W2 tanh(W1 x + b1) + b2`` for each row of ``X`` (n, d), normalised units."""
    X = np.asarray(X, dtype=float)
    W1, b1, W2, b2 = unpack(theta, X.shape[-1], hidden)
    return np.tanh(X @ W1.T + b1) @ W2 + b2


def _forward_hidden(theta, X, hidden):
    W1, b1, W2, b2 = unpack(theta, X.shape[1], hidden)
    A = np.tanh(X @ W1.T + b1)
    return A, W2, A @ W2 + b2


def jacobian(theta: np.ndarray, X: np.ndarray, hidden: int) -> np.ndarray:
    """Analytic Jacobian ``d yhat / d theta`` (n, P) of :func:`forward` (spec 004 §3.6).

    With ``a_ij = tanh(n_ij)``: d/db2 = 1, d/dW2_j = a_ij, d/db1_j = W2_j (1 - a_ij^2),
    d/dW1_jk = W2_j (1 - a_ij^2) x_ik. Column order follows :func:`pack`.
    """
    X = np.asarray(X, dtype=float)
    A, W2, _ = _forward_hidden(theta, X, hidden)
    D = (1.0 - A * A) * W2  # (n, S): d yhat / d b1
    n, d = X.shape
    dW1 = (D[:, :, None] * X[:, None, :]).reshape(n, hidden * d)
    return np.hstack([dW1, D, A, np.ones((n, 1))])


def nguyen_widrow(n_inputs: int, hidden: int, rng=None) -> np.ndarray:
    """Nguyen-Widrow initial ``theta`` for inputs in [-1, 1] (spec 004 §3.5, MATLAB ``initnw``).

    ``beta = 0.7 S^(1/d)``; rows of W1 drawn U(-1, 1), scaled to norm ``2 beta``;
    ``b1_j = 2 beta lambda_j sign(W1_j1)`` with ``lambda = linspace(-1, 1, S)`` (0 for
    S = 1); W2, b2 ~ U(-1, 1). Draw order: W1, then W2, then b2.
    """
    gen = as_generator(rng)
    S, d = int(hidden), int(n_inputs)
    beta = 0.7 * S ** (1.0 / d)
    W1 = gen.uniform(-1.0, 1.0, size=(S, d))
    norms = np.linalg.norm(W1, axis=1)
    norms[norms == 0] = 1.0
    W1 = 2.0 * beta * W1 / norms[:, None]
    lam = np.linspace(-1.0, 1.0, S) if S > 1 else np.zeros(1)
    sgn = np.where(W1[:, 0] >= 0, 1.0, -1.0)
    b1 = 2.0 * beta * lam * sgn
    W2 = gen.uniform(-1.0, 1.0, size=S)
    b2 = gen.uniform(-1.0, 1.0)
    return pack(W1, b1, W2, b2)


# --------------------------------------------------------------------------------------
# mapminmax
# --------------------------------------------------------------------------------------

def _minmax(x: np.ndarray):
    """Column minima and spans; a (near-)constant column gets span 0 (spec 004 §3.3)."""
    lo = np.min(x, axis=0)
    hi = np.max(x, axis=0)
    span = hi - lo
    const = span < 1e-12 * np.maximum(1.0, np.abs(hi))
    span = np.where(const, 0.0, span)
    return lo, span


def _to_unit(x, lo, span):
    safe = np.where(span > 0, span, 1.0)
    z = 2.0 * (x - lo) / safe - 1.0
    return np.where(span > 0, z, 0.0)


@dataclass(frozen=True)
class LMReport:
    """Training record of one LM run (spec 004 §3.6).

    Attributes
    ----------
    stop_reason : one of ``"max_epochs"``, ``"goal"``, ``"min_grad"``, ``"mu_max"``, ``"max_fail"``
    epochs : epochs completed (accepted or not)
    best_epoch : epoch whose parameters were returned (0 = initial)
    train_mse, val_mse : MSE per epoch, index 0 = initial parameters, normalised units
        (``val_mse`` is empty without a validation set)
    mu : mu at the end of each epoch
    n_train, n_val : sample counts
    """

    stop_reason: str
    epochs: int
    best_epoch: int
    train_mse: tuple
    val_mse: tuple
    mu: tuple
    n_train: int
    n_val: int

    def to_dict(self) -> dict:
        return {
            "stop_reason": self.stop_reason, "epochs": self.epochs,
            "best_epoch": self.best_epoch, "train_mse": list(self.train_mse),
            "val_mse": list(self.val_mse), "mu": list(self.mu),
            "n_train": self.n_train, "n_val": self.n_val,
        }


def train_lm(theta0, X, y, hidden, *, X_val=None, y_val=None, max_epochs=1000, mu=1e-3,
             mu_dec=0.1, mu_inc=10.0, mu_max=1e10, min_grad=1e-7, max_fail=6, goal=0.0):
    """Levenberg-Marquardt training loop of spec 004 §3.6 (normalised data).

    Returns ``(theta, LMReport)``: theta at the lowest validation MSE (the final theta
    when there is no validation set).
    """
    theta = np.array(theta0, dtype=float)
    n = y.size
    has_val = X_val is not None and y_val is not None and np.size(y_val) > 0

    def mse_val(th):
        e = forward(th, X_val, hidden) - y_val
        return float(np.mean(e * e))

    A, W2, yhat = _forward_hidden(theta, X, hidden)
    r = yhat - y
    F = float(np.mean(r * r))
    train_hist = [F]
    val_hist = []
    mu_hist = []
    if has_val:
        v_best = mse_val(theta)
        val_hist.append(v_best)
    theta_best = theta.copy()
    best_epoch = 0
    fails = 0
    stop = "max_epochs"
    epoch = 0
    m = mu
    for epoch in range(1, int(max_epochs) + 1):
        J = jacobian(theta, X, hidden)
        g = (2.0 / n) * (J.T @ r)
        if F <= goal:
            stop, epoch = "goal", epoch - 1
            break
        if np.linalg.norm(g) < min_grad:
            stop, epoch = "min_grad", epoch - 1
            break
        JtJ = J.T @ J
        Jtr = J.T @ r
        eye = np.eye(JtJ.shape[0])
        improved = False
        while True:
            try:
                delta = -np.linalg.solve(JtJ + m * eye, Jtr)
                th_new = theta + delta
                r_new = forward(th_new, X, hidden) - y
                F_new = float(np.mean(r_new * r_new))
            except np.linalg.LinAlgError:
                F_new = np.inf
            if F_new < F:
                theta, r, F = th_new, r_new, F_new
                m = max(m * mu_dec, 1e-20)
                improved = True
                break
            m = m * mu_inc
            if m > mu_max:
                break
        train_hist.append(F)
        mu_hist.append(m)
        if not improved:
            stop = "mu_max"
            if has_val:
                val_hist.append(mse_val(theta))
            break
        if has_val:
            v = mse_val(theta)
            val_hist.append(v)
            if v < v_best:
                v_best, theta_best, best_epoch, fails = v, theta.copy(), epoch, 0
            else:
                fails += 1
                if fails >= max_fail:
                    stop = "max_fail"
                    break
    if not has_val:
        theta_best = theta
        best_epoch = epoch
    report = LMReport(
        stop_reason=stop, epochs=int(epoch), best_epoch=int(best_epoch),
        train_mse=tuple(train_hist), val_mse=tuple(val_hist), mu=tuple(mu_hist),
        n_train=int(n), n_val=int(np.size(y_val)) if has_val else 0,
    )
    return theta_best, report


def split_indices(n: int, val_fraction: float, split: str, rng) -> tuple[np.ndarray, np.ndarray]:
    """Training and validation indices (spec 004 §3.4).

    ``n_val = floor(val_fraction n + 0.5)``; ``"random"`` permutes with ``rng``
    (MATLAB ``dividerand``), ``"block"`` takes the last ``n_val`` samples.
    """
    n_val = int(np.floor(val_fraction * n + 0.5))
    if n_val >= n:
        n_val = n - 1
    if split == "random":
        perm = as_generator(rng).permutation(n)
        return np.sort(perm[: n - n_val]), np.sort(perm[n - n_val:])
    if split == "block":
        idx = np.arange(n)
        return idx[: n - n_val], idx[n - n_val:]
    raise InputError(f"split must be 'random' or 'block', got {split!r}")


class MLPRegressorLM(Estimator):
    """d-S-1 tanh network trained by Levenberg-Marquardt with validation early stopping.

    Parameters
    ----------
    hidden : int, default=10
        Hidden neurons S (MATLAB ``narnet``/``fitnet`` default; spec 004 §3.2 [R-3]).
    max_epochs : int, default=1000
        trainlm ``epochs``.
    mu : float, default=1e-3
        Initial Marquardt damping mu0.
    mu_dec, mu_inc : float, default=0.1, 10
        Damping factors after a successful / failed trial step.
    mu_max : float, default=1e10
        Training stops (``"mu_max"``) when mu exceeds it.
    min_grad : float, default=1e-7
        Stop when ``||(2/n) J'r||_2`` falls below it (normalised units).
    max_fail : int, default=6
        Validation early stopping: consecutive epochs without a new lowest validation MSE.
    val_fraction : float, default=0.1
        Share of samples held out for validation, ``n_val = floor(f n + 0.5)``
        (spec 004 §3.4: 90 % / 10 %). ``0`` trains without validation.
    split : {"random", "block"}, default="random"
        ``"random"`` = MATLAB ``dividerand``; ``"block"`` = last samples in order.
    scale : bool, default=True
        Map each input column and the target to [-1, 1] (``mapminmax``) with the
        training data's range; the NAR forecaster passes pre-scaled data with ``False``.
    goal : float, default=0
        Stop when the training MSE (normalised units) is at or below it.
    rng : int | numpy.random.Generator | None, default=None
        Seed. Draw order: the split permutation (random split only), then the
        Nguyen-Widrow weights (:func:`nguyen_widrow`).

    Attributes
    ----------
    theta_ : (P,) trained parameters (normalised units), layout of :func:`pack`
    report_ : :class:`LMReport`
    train_index_, val_index_ : rows of ``X`` used for training / validation
        (``val_index_`` is None with an explicit validation set)
    n_features_in_ : number of inputs d

    Notes
    -----
    ``fit(X, y, validation=(X_val, y_val))`` overrides ``val_fraction`` with an
    explicit validation set (spec 000 passes its stratified subset); the scaling then
    still comes from the training set alone.

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
    >>> net = MLPRegressorLM(hidden=5, max_epochs=200, rng=0).fit(X, y)
    >>> float(np.sqrt(np.mean((net.predict(X_new) - y_new) ** 2))) < 0.01
    True
    """

    MODEL_TYPE = "mlp-lm"

    def __init__(self, *, hidden=10, max_epochs=1000, mu=1e-3, mu_dec=0.1, mu_inc=10,
                 mu_max=1e10, min_grad=1e-7, max_fail=6, val_fraction=0.1, split="random",
                 scale=True, goal=0.0, rng=None):
        self.hidden = hidden
        self.max_epochs = max_epochs
        self.mu = mu
        self.mu_dec = mu_dec
        self.mu_inc = mu_inc
        self.mu_max = mu_max
        self.min_grad = min_grad
        self.max_fail = max_fail
        self.val_fraction = val_fraction
        self.split = split
        self.scale = scale
        self.goal = goal
        self.rng = rng

    # ---------------------------------------------------------------------------------
    @staticmethod
    def _check_xy(X, y, what="X"):
        X = np.asarray(X, dtype=float)
        if X.ndim == 1:
            X = X[:, None]
        if X.ndim != 2:
            raise InputError(f"{what} must be 1-D or 2-D, got shape {X.shape}")
        y = np.asarray(y, dtype=float)
        if y.ndim != 1:
            y = y.ravel()
        if X.shape[0] != y.size:
            raise InputError(f"{what} has {X.shape[0]} rows but its target has {y.size}")
        if not (np.all(np.isfinite(X)) and np.all(np.isfinite(y))):
            raise InputError(f"{what} and its target must be finite")
        return X, y

    def _validate_params(self):
        if int(self.hidden) != self.hidden or self.hidden < 1:
            raise InputError(f"hidden must be a positive integer, got {self.hidden}")
        if not 0.0 <= float(self.val_fraction) < 1.0:
            raise InputError(f"val_fraction must lie in [0, 1), got {self.val_fraction}")
        if self.split not in ("random", "block"):
            raise InputError(f"split must be 'random' or 'block', got {self.split!r}")
        if self.mu <= 0 or self.mu_inc <= 1 or not 0 < self.mu_dec < 1:
            raise InputError("need mu > 0, mu_inc > 1 and 0 < mu_dec < 1")

    def fit(self, X, y, *, validation=None) -> MLPRegressorLM:
        """Train on ``X`` (n, d) or (n,) and ``y`` (n,). Returns ``self``.

        Parameters
        ----------
        validation : tuple (X_val, y_val), optional
            Explicit validation set; overrides ``val_fraction``.
        """
        self._validate_params()
        X, y = self._check_xy(X, y)
        gen = as_generator(self.rng)
        if validation is not None:
            X_val, y_val = self._check_xy(*validation, what="validation X")
            if X_val.shape[1] != X.shape[1]:
                raise InputError(
                    f"validation X has {X_val.shape[1]} columns, X has {X.shape[1]}")
            X_tr, y_tr = X, y
            i_tr, i_val = np.arange(y.size), None
        elif self.val_fraction > 0:
            if y.size < 2:
                raise InputError("need at least 2 samples to hold out a validation set")
            i_tr, i_val = split_indices(y.size, float(self.val_fraction), self.split, gen)
            X_tr, y_tr, X_val, y_val = X[i_tr], y[i_tr], X[i_val], y[i_val]
        else:
            X_tr, y_tr, X_val, y_val = X, y, None, None
            i_tr, i_val = np.arange(y.size), np.zeros(0, dtype=int)
        if y_tr.size < 1:
            raise InputError("no training samples")
        d = X.shape[1]
        S = int(self.hidden)
        if self.scale:
            self.x_min_, self.x_span_ = _minmax(X_tr)
            y_lo, y_span = _minmax(y_tr[:, None])
            self.y_min_, self.y_span_ = float(y_lo[0]), float(y_span[0])
        else:
            self.x_min_, self.x_span_ = np.full(d, -1.0), np.full(d, 2.0)
            self.y_min_, self.y_span_ = -1.0, 2.0
        if self.y_span_ == 0.0:
            warnings.warn("constant training target: the network predicts that constant",
                          DataQualityWarning, stacklevel=2)
        Zt = _to_unit(X_tr, self.x_min_, self.x_span_)
        yt = self._y_to_unit(y_tr)
        Zv = yv = None
        if X_val is not None:
            Zv = _to_unit(X_val, self.x_min_, self.x_span_)
            yv = self._y_to_unit(y_val)
        theta0 = nguyen_widrow(d, S, gen)
        theta, report = train_lm(
            theta0, Zt, yt, S, X_val=Zv, y_val=yv, max_epochs=int(self.max_epochs),
            mu=float(self.mu), mu_dec=float(self.mu_dec), mu_inc=float(self.mu_inc),
            mu_max=float(self.mu_max), min_grad=float(self.min_grad),
            max_fail=int(self.max_fail), goal=float(self.goal))
        self.theta_ = theta
        self.report_ = report
        self.train_index_, self.val_index_ = i_tr, i_val
        self.n_features_in_ = d
        return self

    def _y_to_unit(self, y):
        if self.y_span_ == 0.0:
            return np.zeros_like(y)
        return 2.0 * (y - self.y_min_) / self.y_span_ - 1.0

    def _y_from_unit(self, z):
        return (z + 1.0) * self.y_span_ / 2.0 + self.y_min_

    def predict(self, X) -> np.ndarray:
        """Network output for ``X`` (n, d) or (n,), in the target's units."""
        if not hasattr(self, "theta_"):
            raise NotFittedError("MLPRegressorLM.predict called before fit")
        X = np.asarray(X, dtype=float)
        if X.ndim == 1:
            X = X[:, None] if self.n_features_in_ == 1 else X[None, :]
        if X.shape[-1] != self.n_features_in_:
            raise InputError(f"expected {self.n_features_in_} input columns, got {X.shape[-1]}")
        Z = _to_unit(X, self.x_min_, self.x_span_)
        return self._y_from_unit(forward(self.theta_, Z, int(self.hidden)))

    # model-file support --------------------------------------------------------------
    def _model_params(self) -> dict:
        """The hyper-parameters stored in the model file (not ``rng``)."""
        return {k: getattr(self, k) for k in (
            "hidden", "max_epochs", "mu", "mu_dec", "mu_inc", "mu_max", "min_grad",
            "max_fail", "val_fraction", "split", "scale", "goal")}

    def to_dict(self) -> dict:
        """JSON-ready hyper-parameters, weights and scaling (see :mod:`inertialab.io.modelfile`)."""
        if not hasattr(self, "theta_"):
            raise NotFittedError("MLPRegressorLM.to_dict called before fit")
        params = self._model_params()
        params = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in params.items()}
        return {
            "params": params,
            "n_features_in": int(self.n_features_in_),
            "theta": self.theta_.tolist(),
            "x_min": self.x_min_.tolist(), "x_span": self.x_span_.tolist(),
            "y_min": self.y_min_, "y_span": self.y_span_,
            "stop_reason": self.report_.stop_reason, "epochs": self.report_.epochs,
            "best_epoch": self.report_.best_epoch,
        }

    @classmethod
    def from_dict(cls, d: dict) -> MLPRegressorLM:
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        try:
            obj = cls(**d["params"])
            obj.n_features_in_ = int(d["n_features_in"])
            obj.theta_ = np.asarray(d["theta"], dtype=float)
            obj.x_min_ = np.asarray(d["x_min"], dtype=float)
            obj.x_span_ = np.asarray(d["x_span"], dtype=float)
            obj.y_min_ = float(d["y_min"])
            obj.y_span_ = float(d["y_span"])
            obj.report_ = LMReport(d.get("stop_reason", ""), int(d.get("epochs", 0)),
                                   int(d.get("best_epoch", 0)), (), (), (), 0, 0)
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"mlp-lm model: bad payload ({exc})") from None
        if obj.theta_.size != n_params(obj.n_features_in_, int(obj.hidden)):
            raise InputError("mlp-lm model: weight count does not match the architecture")
        return obj
