"""First-order Takagi-Sugeno-Kang fuzzy inference system with Gaussian memberships.

:class:`TSKFIS` evaluates the five ANFIS layers (membership, product, normalisation,
weighted consequent, sum; spec 000 §3.3, seed eqs. 8-13). Membership functions are
stored once per input and referenced by the rules, so one class serves both the
clustered FIS of :func:`genfis` (every rule owns its MFs) and the grid partition of
:func:`grid_fis` (rules share MFs), and ANFIS can train either.

:func:`genfis` follows MATLAB's ``genfis2``: subtractive clustering of inputs and
output together, one rule per centre, Gaussian MFs with the common cluster width,
linear consequents by global least squares (:func:`solve_lstsq`, minimum norm).

Normalised firing strengths are computed as ``exp(log w_i - max_k log w_k)/sum``,
which equals ``w_i/sum_k w_k`` whenever the sum is representable and, where all
``w`` underflow (an input far from every rule), falls back to the rule whose premise
is nearest in the Gaussian metric, as spec 000 §3.3 asks.

References
----------
T. Takagi, M. Sugeno, IEEE Trans. SMC 15 (1985) 116-132; MATLAB ``genfis2``;
spec 000 §3.3.
"""

from __future__ import annotations

from itertools import product

import numpy as np
import scipy.linalg

from inertialab.errors import InputError
from inertialab.learn.subclust import SubtractiveClustering

#: rcond of the consequent least squares (spec 000 §3.3).
LSTSQ_RCOND = 1e-12


def solve_lstsq(A: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Minimum-norm least squares ``min ||A theta - y||`` by LAPACK ``gelsy`` (complete
    orthogonal factorisation, rank decided with rcond 1e-12). It gives the same
    minimum-norm solution as the SVD-based ``gelsd`` of spec 000 §3.3 up to rounding and
    is 2-3x faster on the ~300 x 100 systems ANFIS solves every epoch (spec 000 §8.2.5)."""
    return scipy.linalg.lstsq(A, y, cond=LSTSQ_RCOND, lapack_driver="gelsy",
                              check_finite=False)[0]


def _as_2d(X, name: str = "X") -> np.ndarray:
    X = np.asarray(X, dtype=float)
    if X.ndim == 1:
        X = X[:, None]
    if X.ndim != 2:
        raise InputError(f"{name} must be 1-D or 2-D, got shape {X.shape}")
    if not np.all(np.isfinite(X)):
        raise InputError(f"{name} contains NaN or infinite values")
    return X


class TSKFIS:
    """First-order TSK fuzzy system ``y = sum_i wb_i (p_i . x + r_i)``.

    Parameters
    ----------
    mf_input : array-like (M,) of int
        Input index of each membership function.
    mf_center, mf_sigma : array-like (M,)
        Centre and width of each Gaussian MF ``exp(-(x - c)^2 / (2 sigma^2))``.
    rule_mf : array-like (R, n_in) of int
        For rule i and input j, the index of the MF used.
    consequents : array-like (R, n_in + 1) or None
        ``[p_i1, ..., p_in, r_i]`` per rule; None until :meth:`fit_consequents`.
    """

    def __init__(self, mf_input, mf_center, mf_sigma, rule_mf, consequents=None):
        self.mf_input = np.asarray(mf_input, dtype=int)
        self.mf_center = np.asarray(mf_center, dtype=float).copy()
        self.mf_sigma = np.asarray(mf_sigma, dtype=float).copy()
        self.rule_mf = np.atleast_2d(np.asarray(rule_mf, dtype=int))
        self.consequents = None if consequents is None else np.asarray(consequents, dtype=float)
        m = self.mf_input.size
        if self.mf_center.shape != (m,) or self.mf_sigma.shape != (m,):
            raise InputError("mf_input, mf_center and mf_sigma must have the same length")
        if np.any(self.mf_sigma <= 0):
            raise InputError("membership widths must be positive")
        if self.rule_mf.min() < 0 or self.rule_mf.max() >= m:
            raise InputError("rule_mf refers to a membership function that does not exist")
        for j in range(self.n_inputs):
            if np.any(self.mf_input[self.rule_mf[:, j]] != j):
                raise InputError(f"rule_mf column {j} uses a membership function of another input")
        if self.consequents is not None and self.consequents.shape != (self.n_rules, self.n_inputs + 1):
            raise InputError(
                f"consequents must have shape ({self.n_rules}, {self.n_inputs + 1})")

    @property
    def n_rules(self) -> int:
        return int(self.rule_mf.shape[0])

    @property
    def n_inputs(self) -> int:
        return int(self.rule_mf.shape[1])

    def copy(self) -> TSKFIS:
        return TSKFIS(self.mf_input, self.mf_center, self.mf_sigma, self.rule_mf,
                      None if self.consequents is None else self.consequents.copy())

    # layers ----------------------------------------------------------------------------
    def log_firing(self, X) -> np.ndarray:
        """``log w`` (n, R): sum over inputs of the log memberships (layers 1-2)."""
        X = _as_2d(X)
        if X.shape[1] != self.n_inputs:
            raise InputError(f"expected {self.n_inputs} input columns, got {X.shape[1]}")
        z = (X[:, self.mf_input] - self.mf_center) / self.mf_sigma
        logmu = -0.5 * z * z  # (n, M)
        return logmu[:, self.rule_mf].sum(axis=2)

    def normalized_firing(self, X) -> np.ndarray:
        """``wb`` (n, R), rows summing to one (layer 3)."""
        lw = self.log_firing(X)
        lw = lw - lw.max(axis=1, keepdims=True)
        w = np.exp(lw)
        return w / w.sum(axis=1, keepdims=True)

    def rule_outputs(self, X) -> np.ndarray:
        """``f_i(x) = p_i . x + r_i`` (n, R)."""
        if self.consequents is None:
            raise RuntimeError("the FIS has no consequents yet")
        X = _as_2d(X)
        return X @ self.consequents[:, :-1].T + self.consequents[:, -1]

    def predict(self, X) -> np.ndarray:
        """System output (n,) (layers 4-5)."""
        X = _as_2d(X)
        return np.sum(self.normalized_firing(X) * self.rule_outputs(X), axis=1)

    # least squares of the consequents ---------------------------------------------------
    def design(self, X) -> np.ndarray:
        """Regression matrix ``[wb_1 x, wb_1, ..., wb_R x, wb_R]`` (n, R (n_in + 1))."""
        X = _as_2d(X)
        wb = self.normalized_firing(X)
        Xe = np.hstack([X, np.ones((X.shape[0], 1))])
        return (wb[:, :, None] * Xe[:, None, :]).reshape(X.shape[0], -1)

    def fit_consequents(self, X, y) -> TSKFIS:
        """Least-squares consequents for fixed premises (spec 000 §3.3). Returns ``self``."""
        X = _as_2d(X)
        y = np.asarray(y, dtype=float).ravel()
        if y.size != X.shape[0]:
            raise InputError(f"X has {X.shape[0]} rows but y has {y.size}")
        theta = solve_lstsq(self.design(X), y)
        self.consequents = theta.reshape(self.n_rules, self.n_inputs + 1)
        return self

    # serialisation ----------------------------------------------------------------------
    def to_dict(self) -> dict:
        return {
            "mf_input": self.mf_input.tolist(),
            "mf_center": self.mf_center.tolist(),
            "mf_sigma": self.mf_sigma.tolist(),
            "rule_mf": self.rule_mf.tolist(),
            "consequents": None if self.consequents is None else self.consequents.tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict) -> TSKFIS:
        try:
            return cls(d["mf_input"], d["mf_center"], d["mf_sigma"], d["rule_mf"],
                       d.get("consequents"))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"fuzzy system: malformed parameters ({exc})") from exc


def genfis(X, y, *, radius=0.5, squash: float = 1.25, accept: float = 0.5,
           reject: float = 0.15, bounds=None) -> TSKFIS:
    """First-order TSK FIS from subtractive clustering (MATLAB ``genfis2`` semantics).

    Parameters
    ----------
    X : array-like (n, n_in)
        Inputs.
    y : array-like (n,)
        Output.
    radius, squash, accept, reject
        :class:`~inertialab.learn.subclust.SubtractiveClustering` parameters, defaults
        0.5, 1.25, 0.5, 0.15 (spec 000 §3.2). ``radius`` may have n_in + 1 values (the
        last for the output).
    bounds : array-like (2, n_in + 1) or None
        Normalisation bounds of ``[X, y]`` (None: data min/max).

    Returns
    -------
    TSKFIS
        One rule per centre, MF centre = the centre's input coordinates, MF width =
        ``r_a (max - min)/sqrt(8)`` per input, consequents by least squares on (X, y).
    """
    X = _as_2d(X)
    y = np.asarray(y, dtype=float).ravel()
    if y.size != X.shape[0]:
        raise InputError(f"X has {X.shape[0]} rows but y has {y.size}")
    sc = SubtractiveClustering(radius=radius, squash=squash, accept=accept, reject=reject,
                               bounds=bounds).fit(np.column_stack([X, y]))
    n_in = X.shape[1]
    R = sc.n_clusters_
    sig = sc.sigmas_[:n_in]
    sig = np.where(sig > 0, sig, 1e-12)  # a constant input column: degenerate width
    centers = sc.centers_[:, :n_in]
    mf_input = np.tile(np.arange(n_in), R)
    mf_center = centers.ravel()
    mf_sigma = np.tile(sig, R)
    rule_mf = np.arange(R * n_in).reshape(R, n_in)
    fis = TSKFIS(mf_input, mf_center, mf_sigma, rule_mf)
    return fis.fit_consequents(X, y)


def grid_fis(X, y=None, *, n_mfs=3, bounds=None) -> TSKFIS:
    """Grid-partition TSK FIS (ANFIS baseline of spec 000 §4).

    ``n_mfs`` Gaussian MFs per input evenly spaced over ``bounds`` (default the data
    range), width ``spacing/(2 sqrt(2 ln 2))`` so that neighbours cross at 0.5; one rule
    per combination (``prod(n_mfs)`` rules). Consequents by least squares when ``y`` is
    given.
    """
    X = _as_2d(X)
    n_in = X.shape[1]
    nm = np.broadcast_to(np.atleast_1d(np.asarray(n_mfs, dtype=int)), (n_in,))
    if np.any(nm < 1):
        raise InputError("n_mfs must be >= 1")
    if bounds is None:
        lo, hi = X.min(axis=0), X.max(axis=0)
    else:
        b = np.asarray(bounds, dtype=float)
        lo, hi = b[0][:n_in], b[1][:n_in]
    mf_input, mf_center, mf_sigma, per_input = [], [], [], []
    k = 0
    for j in range(n_in):
        span = hi[j] - lo[j] if hi[j] > lo[j] else 1.0
        cs = np.linspace(lo[j], hi[j], nm[j]) if nm[j] > 1 else np.array([(lo[j] + hi[j]) / 2])
        spacing = span / (nm[j] - 1) if nm[j] > 1 else span
        s = spacing / (2.0 * np.sqrt(2.0 * np.log(2.0)))
        mf_input += [j] * nm[j]
        mf_center += list(cs)
        mf_sigma += [s] * nm[j]
        per_input.append(list(range(k, k + nm[j])))
        k += nm[j]
    rule_mf = np.array(list(product(*per_input)), dtype=int)
    fis = TSKFIS(mf_input, mf_center, mf_sigma, rule_mf)
    if y is not None:
        fis.fit_consequents(X, y)
    return fis
