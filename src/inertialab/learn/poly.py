"""Polynomial least-squares regressor: the one polynomial baseline of every study.

Serves the 4th-order polynomial of spec 001 §3.9 (bias vs vibration frequency),
POLY-SEP and POLY-2D of spec 000 §4 (total degree in two inputs) and the polynomial
trend of spec 004 §4. Inputs are mapped to [-1, 1] per column before the monomials
are formed (conditioning; the fitted function is unchanged), and the least-squares
problem is solved with ``numpy.linalg.lstsq`` (SVD), so a rank-deficient design
still gives the minimum-norm fit; ``rank_`` reports it.

Written here rather than taken from scikit-learn because inertialab does not depend
on scikit-learn and the model has to serialise to a model file.
"""

from __future__ import annotations

from itertools import combinations_with_replacement

import numpy as np

from inertialab.errors import ExtrapolationWarning, InputError, NotFittedError


def _monomials(n_features: int, degree: int, *, interaction: bool) -> list[tuple[int, ...]]:
    """Exponent tuples of every monomial up to ``degree``.

    ``interaction=False`` keeps only single-variable powers (a separable model).
    """
    terms: list[tuple[int, ...]] = []
    for d in range(degree + 1):
        for combo in combinations_with_replacement(range(n_features), d):
            exps = [0] * n_features
            for j in combo:
                exps[j] += 1
            if not interaction and sum(1 for e in exps if e > 0) > 1:
                continue
            terms.append(tuple(exps))
    return terms


class PolynomialRegressor:
    """Least-squares polynomial in one or more inputs.

    Parameters
    ----------
    degree : int, default=4
        Total degree (spec 001 §3.9 uses 4).
    interaction : bool, default=True
        Include cross terms (POLY-2D); ``False`` gives a separable sum of
        single-variable polynomials (POLY-SEP uses its own product form, see 000 §4).
    warn_extrapolation : bool, default=True
        Warn (:class:`~inertialab.errors.ExtrapolationWarning`) when ``predict``
        sees inputs outside the training range.
    """

    MODEL_TYPE = "polynomial"

    def __init__(self, *, degree: int = 4, interaction: bool = True,
                 warn_extrapolation: bool = True):
        self.degree = degree
        self.interaction = interaction
        self.warn_extrapolation = warn_extrapolation

    def _design(self, X: np.ndarray) -> np.ndarray:
        Z = 2.0 * (X - self.x_min_) / self.x_span_ - 1.0
        cols = [np.prod(Z ** np.asarray(e), axis=1) for e in self.powers_]
        return np.column_stack(cols)

    @staticmethod
    def _as_2d(X) -> np.ndarray:
        X = np.asarray(X, dtype=float)
        if X.ndim == 1:
            X = X[:, None]
        if X.ndim != 2:
            raise InputError(f"X must be 1-D or 2-D, got shape {X.shape}")
        return X

    def fit(self, X, y) -> PolynomialRegressor:
        """Fit to ``X`` (n,) or (n, d) and ``y`` (n,). Returns ``self``."""
        if int(self.degree) != self.degree or self.degree < 0:
            raise InputError(f"degree must be a non-negative integer, got {self.degree}")
        X = self._as_2d(X)
        y = np.asarray(y, dtype=float).ravel()
        if X.shape[0] != y.size:
            raise InputError(f"X has {X.shape[0]} rows but y has {y.size}")
        if not (np.all(np.isfinite(X)) and np.all(np.isfinite(y))):
            raise InputError("X and y must be finite")
        self.powers_ = _monomials(X.shape[1], int(self.degree), interaction=self.interaction)
        if y.size < len(self.powers_):
            raise InputError(
                f"{y.size} samples cannot determine {len(self.powers_)} polynomial coefficients")
        self.x_min_ = X.min(axis=0)
        span = X.max(axis=0) - self.x_min_
        self.x_span_ = np.where(span > 0, span, 1.0)
        A = self._design(X)
        coef, _, rank, _ = np.linalg.lstsq(A, y, rcond=None)
        self.coef_ = coef
        self.rank_ = int(rank)
        self.n_features_in_ = X.shape[1]
        return self

    def predict(self, X) -> np.ndarray:
        """Evaluate the fitted polynomial at ``X``."""
        if not hasattr(self, "coef_"):
            raise NotFittedError("PolynomialRegressor.predict called before fit")
        X = self._as_2d(X)
        if X.shape[1] != self.n_features_in_:
            raise InputError(f"expected {self.n_features_in_} input columns, got {X.shape[1]}")
        if self.warn_extrapolation:
            lo, hi = self.x_min_, self.x_min_ + self.x_span_
            tol = 1e-9 * self.x_span_
            if np.any(X < lo - tol) or np.any(X > hi + tol):
                import warnings

                warnings.warn("polynomial evaluated outside its training range",
                              ExtrapolationWarning, stacklevel=2)
        return self._design(X) @ self.coef_

    # model-file support --------------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-ready parameters (see :mod:`inertialab.io.modelfile`)."""
        return {
            "degree": int(self.degree),
            "interaction": bool(self.interaction),
            "powers": [list(p) for p in self.powers_],
            "x_min": self.x_min_.tolist(),
            "x_span": self.x_span_.tolist(),
            "coef": self.coef_.tolist(),
            "rank": self.rank_,
        }

    @classmethod
    def from_dict(cls, d: dict) -> PolynomialRegressor:
        obj = cls(degree=int(d["degree"]), interaction=bool(d["interaction"]))
        obj.powers_ = [tuple(int(v) for v in p) for p in d["powers"]]
        obj.x_min_ = np.asarray(d["x_min"], dtype=float)
        obj.x_span_ = np.asarray(d["x_span"], dtype=float)
        obj.coef_ = np.asarray(d["coef"], dtype=float)
        obj.rank_ = int(d["rank"])
        obj.n_features_in_ = obj.x_min_.size
        if len(obj.powers_) != obj.coef_.size:
            raise InputError("polynomial model: number of powers and coefficients differ")
        return obj
