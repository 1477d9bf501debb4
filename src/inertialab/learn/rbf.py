"""Radial-basis-function network with MATLAB ``newrb`` / ``newrbe`` semantics.

Spec 001 §3.8. The model with M hidden neurons is

    y(x) = w_0 + sum_{i=1..M} w_i exp(-(b ||x - c_i||)^2),   b = sqrt(ln 2) / spread,

so each basis function equals 0.5 at distance ``spread`` from its centre. Training
starts with M = 0 (prediction = mean of the targets) and adds one neuron per
iteration until the training MSE is <= ``goal`` or M reaches ``max_neurons``
(default: the number of training points). Centres are training inputs, chosen by

- ``"max_error"`` (default; the documented newrb behaviour): the unused input with the
  largest absolute residual under the current network, ties to the lowest index;
- ``"ols"`` (what MATLAB's ``designrb`` code does): orthogonal forward selection on the
  deflated candidate columns, maximising ``(P_j.y)^2 / ((y.y)(P_j.P_j))`` with the raw
  (uncentred) target ``y``;
- ``"random_fixed"`` (the seed's wording): a seeded random order of the training inputs;
- ``"all"``: every training input at once (``newrbe``, exact interpolation).

After each addition the output layer ``[Phi, 1] [w; w_0] ~ y`` is the linear
least-squares solution. It is maintained here by an incremental, re-orthogonalised
Gram-Schmidt QR of the design (one column added per neuron, O(n) per column and
neuron), because a fresh ``lstsq`` per neuron would cost O(n M^2) each time; a column
that is numerically dependent on the previous ones (relative norm after
orthogonalisation below ``rcond`` = 1e-12) gets no independent weight, as ``lstsq``
with that ``rcond`` would do. No library offers newrb's greedy growth, hence the
hand-written loop.
"""

from __future__ import annotations

import math

import numpy as np

from inertialab.errors import InputError, NotFittedError
from inertialab.estimator import Estimator
from inertialab.io.model_schemas import check_own_payload
from inertialab.seeding import as_generator

__all__ = ["RBFNetwork"]

_MODES = ("max_error", "ols", "random_fixed", "all")


def _as_2d(X) -> np.ndarray:
    X = np.asarray(X, dtype=float)
    if X.ndim == 1:
        X = X[:, None]
    if X.ndim != 2:
        raise InputError(f"X must be 1-D or 2-D, got shape {X.shape}")
    return X


def _sqdist(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Squared Euclidean distances between rows of A (n, d) and B (m, d)."""
    if A.shape[1] == 1:
        return (A[:, 0][:, None] - B[:, 0][None, :]) ** 2
    d2 = (A**2).sum(1)[:, None] + (B**2).sum(1)[None, :] - 2.0 * A @ B.T
    return np.maximum(d2, 0.0)


class _IncrementalQR:
    """Least squares with columns appended one at a time (Gram-Schmidt, twice)."""

    def __init__(self, y: np.ndarray, rcond: float, max_cols: int):
        self.y = y
        self.rcond = rcond
        self.Qm = np.zeros((y.size, max_cols))  # orthonormal columns, filled left to right
        self.k = 0
        self.R = np.zeros((0, 0))
        self.qty: list[float] = []
        self.kept: list[int] = []  # indices (in order of addition) of independent columns
        self.resid = y.copy()

    def add(self, col: np.ndarray, tag: int) -> bool:
        norm0 = float(np.linalg.norm(col))
        v = col.copy()
        k = self.k
        r = np.zeros(k)
        if k:
            Qm = self.Qm[:, :k]
            for _ in range(2):
                c = Qm.T @ v
                v -= Qm @ c
                r += c
        nv = float(np.linalg.norm(v))
        if norm0 == 0.0 or nv <= self.rcond * norm0:
            return False
        if k >= self.Qm.shape[1]:  # numerically full rank reached: nothing left to add
            return False
        q = v / nv
        R = np.zeros((k + 1, k + 1))
        R[:k, :k] = self.R
        R[:k, k] = r
        R[k, k] = nv
        self.R = R
        self.Qm[:, k] = q
        self.k = k + 1
        qy = float(q @ self.y)
        self.qty.append(qy)
        self.resid = self.resid - qy * q
        self.kept.append(tag)
        return True

    def coef(self) -> np.ndarray:
        from scipy.linalg import solve_triangular

        if not self.k:
            return np.zeros(0)
        return solve_triangular(self.R, np.asarray(self.qty), lower=False)


class RBFNetwork(Estimator):
    """Gaussian RBF network grown like MATLAB ``newrb`` (spec 001 §3.8).

    Parameters
    ----------
    spread : float, default=1.2
        Distance (input units; Hz in spec 001, unscaled) at which a basis is 0.5.
        Seed value 1.2.
    goal : float, default=1e-4
        Training MSE at which growth stops (squared target unit; (deg/h)^2 in spec 001).
    centers : {"max_error", "ols", "random_fixed", "all"}, default="max_error"
        Centre selection (see module docstring). ``"all"`` is ``newrbe``.
        The seed says "random fixed"; the spec's default is newrb's documented
        "max_error".
    max_neurons : int or None, default=None
        MN; None means the number of training points.
    rcond : float, default=1e-12
        Relative tolerance below which a new column counts as dependent.
    rng : int, Generator or None, default=None
        Random order for ``"random_fixed"`` (seed 0 when None).

    Attributes
    ----------
    centers_ : ndarray (M, d)
    weights_ : ndarray (M,)
    bias_ : float
        w_0.
    b_ : float
        sqrt(ln 2) / spread.
    n_neurons_ : int
    mse_history_ : list of float
        Training MSE after 0, 1, ..., M neurons.
    mse_ : float
        Final training MSE.

    Examples
    --------
    One period of a sine from 40 points, read back between them:

    >>> import numpy as np
    >>> x = np.linspace(0.0, 1.0, 40)
    >>> net = RBFNetwork(spread=0.2, goal=1e-6).fit(x, np.sin(2 * np.pi * x))
    >>> x_new = np.array([0.25, 0.6])
    >>> bool(np.allclose(net.predict(x_new), np.sin(2 * np.pi * x_new), atol=1e-3))
    True
    """

    MODEL_TYPE = "rbf"

    def __init__(self, *, spread: float = 1.2, goal: float = 1e-4,
                 centers: str = "max_error", max_neurons: int | None = None,
                 rcond: float = 1e-12, rng=None):
        self.spread = spread
        self.goal = goal
        self.centers = centers
        self.max_neurons = max_neurons
        self.rcond = rcond
        self.rng = rng

    # ------------------------------------------------------------------------------
    def _basis(self, X: np.ndarray, C: np.ndarray) -> np.ndarray:
        return np.exp(-(self.b_**2) * _sqdist(X, C))

    def fit(self, X, y) -> RBFNetwork:
        """Grow the network on inputs ``X`` (n,) or (n, d) and targets ``y`` (n,)."""
        if self.centers not in _MODES:
            raise InputError(f"centers must be one of {', '.join(_MODES)}, got {self.centers!r}")
        if not (np.isfinite(self.spread) and self.spread > 0):
            raise InputError(f"spread must be positive, got {self.spread}")
        if not (np.isfinite(self.goal) and self.goal >= 0):
            raise InputError(f"goal must be >= 0, got {self.goal}")
        X = _as_2d(X)
        y = np.asarray(y, dtype=float).ravel()
        n = y.size
        if X.shape[0] != n:
            raise InputError(f"X has {X.shape[0]} rows but y has {n}")
        if n < 1:
            raise InputError("RBFNetwork needs at least one training sample")
        if not (np.all(np.isfinite(X)) and np.all(np.isfinite(y))):
            raise InputError("X and y must be finite")
        mn = n if self.max_neurons is None else int(self.max_neurons)
        if mn < 0:
            raise InputError(f"max_neurons must be >= 0, got {self.max_neurons}")
        mn = min(mn, n)
        self.b_ = math.sqrt(math.log(2.0)) / float(self.spread)
        P = self._basis(X, X)  # candidate columns, P[:, j] centred on X[j]

        qr = _IncrementalQR(y, self.rcond, min(n, mn + 1))
        qr.add(np.ones(n), -1)  # w_0 always present
        history = [float(np.mean(qr.resid**2))]
        chosen: list[int] = []
        used = np.zeros(n, dtype=bool)

        if self.centers == "all":
            order = list(range(mn))
        elif self.centers == "random_fixed":
            order = list(as_generator(self.rng).permutation(n)[:mn])
        else:
            order = None
        if self.centers == "ols":
            Pd = P.copy()
            yy = float(y @ y)

        while history[-1] > self.goal and len(chosen) < mn:
            if order is not None:
                j = int(order[len(chosen)])
            elif self.centers == "max_error":
                r = np.abs(qr.resid)
                r[used] = -np.inf
                j = int(np.argmax(r))
            else:  # ols
                num = (Pd.T @ y) ** 2
                den = yy * np.einsum("ij,ij->j", Pd, Pd)
                with np.errstate(divide="ignore", invalid="ignore"):
                    score = np.where(den > 0, num / den, -np.inf)
                score[used] = -np.inf
                j = int(np.argmax(score))
                p = Pd[:, j].copy()
                pp = float(p @ p)
                if pp > 0:
                    Pd -= np.outer(p, (p @ Pd) / pp)
            used[j] = True
            chosen.append(j)
            qr.add(P[:, j], j)
            if self.centers == "all" and len(chosen) < mn:
                continue  # newrbe: one solve with every centre
            history.append(float(np.mean(qr.resid**2)))
        if self.centers == "all":
            history = [history[0], float(np.mean(qr.resid**2))]

        coef = qr.coef()
        # map coefficients of independent columns back to neurons (dependent ones get 0)
        w_by_tag = dict(zip(qr.kept, coef))
        self.bias_ = float(w_by_tag.get(-1, 0.0))
        self.centers_ = X[chosen].copy() if chosen else np.zeros((0, X.shape[1]))
        self.weights_ = np.array([w_by_tag.get(j, 0.0) for j in chosen], dtype=float)
        self.center_index_ = np.asarray(chosen, dtype=int)
        self.n_neurons_ = len(chosen)
        self.mse_history_ = history
        self.mse_ = float(np.mean((self.predict(X) - y) ** 2))
        self.n_features_in_ = X.shape[1]
        return self

    def predict(self, X) -> np.ndarray:
        """Network output at ``X`` (n,) or (n, d)."""
        if not hasattr(self, "weights_"):
            raise NotFittedError("RBFNetwork.predict called before fit")
        X = _as_2d(X)
        if X.shape[1] != self.centers_.shape[1]:
            raise InputError(f"expected {self.centers_.shape[1]} input columns, got {X.shape[1]}")
        out = np.full(X.shape[0], self.bias_)
        if self.n_neurons_:
            # chunk so that memory stays bounded for long inputs (e.g. a whole record)
            step = max(1, 2_000_000 // max(self.n_neurons_, 1))
            for s in range(0, X.shape[0], step):
                out[s:s + step] += self._basis(X[s:s + step], self.centers_) @ self.weights_
        return out

    # model-file support -------------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-ready parameters (see :mod:`inertialab.io.modelfile`)."""
        return {
            "spread": float(self.spread),
            "goal": float(self.goal),
            "centers": self.centers,
            "max_neurons": None if self.max_neurons is None else int(self.max_neurons),
            "b": float(self.b_),
            "center_values": self.centers_.tolist(),
            "weights": self.weights_.tolist(),
            "bias": float(self.bias_),
            "mse_history": [float(v) for v in self.mse_history_],
            "mse": float(self.mse_),
        }

    @classmethod
    def from_dict(cls, d: dict) -> RBFNetwork:
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        obj = cls(spread=float(d["spread"]), goal=float(d["goal"]), centers=d["centers"],
                  max_neurons=d.get("max_neurons"))
        obj.b_ = float(d["b"])
        C = np.asarray(d["center_values"], dtype=float)
        obj.centers_ = C.reshape(-1, 1) if C.ndim == 1 else C
        obj.weights_ = np.asarray(d["weights"], dtype=float)
        if obj.weights_.size != obj.centers_.shape[0]:
            raise InputError("rbf model: number of centres and weights differ")
        obj.bias_ = float(d["bias"])
        obj.n_neurons_ = int(obj.weights_.size)
        obj.center_index_ = np.arange(0)
        obj.mse_history_ = list(d.get("mse_history", []))
        obj.mse_ = float(d.get("mse", float("nan")))
        obj.n_features_in_ = obj.centers_.shape[1]
        return obj
