"""Polynomial least-squares regressor: the one polynomial baseline of every study.

Serves the 4th-order polynomial of spec 001 §3.9 (bias vs vibration frequency),
POLY-2D of spec 000 §4 (a tensor-product surface ``sum c_mn T^m N^n``, ``degrees=(3,
1)``), the cubic K0(T) and K1(T) of POLY-SEP (:class:`SeparatePolynomials`, spec 000
§4, two of these regressors) and the polynomial trend of spec 004 §4. Inputs are mapped to [-1, 1] per column before the monomials
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
from inertialab.estimator import Estimator
from inertialab.io.model_schemas import check_own_payload


def monomials(n_features: int, degree: int, *, interaction: bool,
               degrees=None) -> list[tuple[int, ...]]:
    """Exponent tuples of every monomial up to ``degree``.

    ``interaction=False`` keeps only single-variable powers (a separable model).
    ``degrees`` (one maximum per input) gives the tensor product instead, ordered with
    the first input's power outermost: ``T^0 N^0, T^0 N^1, T^1 N^0, ...``.
    """
    if degrees is not None:
        if len(degrees) != n_features:
            raise InputError(f"degrees has {len(degrees)} entries for {n_features} inputs")
        return [tuple(int(v) for v in e) for e in np.ndindex(*(int(d) + 1 for d in degrees))]
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


class PolynomialRegressor(Estimator):
    """Least-squares polynomial in one or more inputs.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.c_[np.arange(6.0)]
    >>> model = PolynomialRegressor(degree=2).fit(x, x[:, 0] ** 2 - 1)
    >>> np.round(model.predict(np.c_[[2.5]]), 6)
    array([5.25])

    Parameters
    ----------
    degree : int, default=4
        Total degree (spec 001 §3.9 uses 4).
    interaction : bool, default=True
        Include cross terms (POLY-2D); ``False`` gives a separable sum of
        single-variable polynomials.
    degrees : tuple of int, optional
        Maximum power per input: the tensor-product surface ``sum_{m<=M, n<=N} c_mn
        x1^m x2^n`` (POLY-2D of spec 000 §4 uses ``(3, 1)``). Overrides ``degree`` and
        ``interaction``.
    warn_extrapolation : bool, default=True
        Warn (:class:`~inertialab.errors.ExtrapolationWarning`) when ``predict``
        sees inputs outside the training range.
    """

    MODEL_TYPE = "polynomial"

    def __init__(self, *, degree: int = 4, interaction: bool = True, degrees=None,
                 warn_extrapolation: bool = True):
        self.degree = degree
        self.interaction = interaction
        self.degrees = degrees
        self.warn_extrapolation = warn_extrapolation

    def get_params(self, deep: bool = True) -> dict:
        return {"degree": self.degree, "interaction": self.interaction,
                "degrees": self.degrees, "warn_extrapolation": self.warn_extrapolation}

    def set_params(self, **params) -> PolynomialRegressor:
        for k, v in params.items():
            if k not in self.get_params():
                raise InputError(f"PolynomialRegressor has no parameter {k!r}")
            setattr(self, k, v)
        return self

    def _design(self, X: np.ndarray) -> np.ndarray:
        Z = 2.0 * (X - self.x_min_) / self.x_span_ - 1.0
        if self.degrees is not None:
            # tensor product: one power per input, multiplied column by column
            cols = [Z[:, 0] ** e[0] * Z[:, 1] ** e[1] if len(e) == 2
                    else np.prod(Z ** np.asarray(e), axis=1) for e in self.powers_]
        else:
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
        if self.degrees is None and (int(self.degree) != self.degree or self.degree < 0):
            raise InputError(f"degree must be a non-negative integer, got {self.degree}")
        if self.degrees is not None and any(int(d) != d or d < 0 for d in self.degrees):
            raise InputError(f"degrees must be non-negative integers, got {self.degrees}")
        X = self._as_2d(X)
        y = np.asarray(y, dtype=float).ravel()
        if X.shape[0] != y.size:
            raise InputError(f"X has {X.shape[0]} rows but y has {y.size}")
        if not (np.all(np.isfinite(X)) and np.all(np.isfinite(y))):
            raise InputError("X and y must be finite")
        self.powers_ = monomials(X.shape[1], int(self.degree), interaction=self.interaction,
                                  degrees=self.degrees)
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
        out = {
            "degree": int(self.degree),
            "interaction": bool(self.interaction),
            "powers": [list(p) for p in self.powers_],
            "x_min": self.x_min_.tolist(),
            "x_span": self.x_span_.tolist(),
            "coef": self.coef_.tolist(),
            "rank": self.rank_,
        }
        if self.degrees is not None:
            out["degrees"] = [int(v) for v in self.degrees]
        return out

    @classmethod
    def from_dict(cls, d: dict) -> PolynomialRegressor:
        check_own_payload(cls.MODEL_TYPE, d)  # types, shapes, ranges: one line naming the key
        degrees = d.get("degrees")
        obj = cls(degree=int(d["degree"]), interaction=bool(d["interaction"]),
                  degrees=None if degrees is None else tuple(int(v) for v in degrees))
        obj.powers_ = [tuple(int(v) for v in p) for p in d["powers"]]
        obj.x_min_ = np.asarray(d["x_min"], dtype=float)
        obj.x_span_ = np.asarray(d["x_span"], dtype=float)
        obj.coef_ = np.asarray(d["coef"], dtype=float)
        obj.rank_ = int(d["rank"])
        obj.n_features_in_ = obj.x_min_.size
        if len(obj.powers_) != obj.coef_.size:
            raise InputError("polynomial model: number of powers and coefficients differ")
        return obj


class SeparatePolynomials(Estimator):
    """POLY-SEP, the industry practice of spec 000 §4: bias and scale factor as separate
    polynomials of temperature.

    Per training set point the bias K0 from the positions with ``a_i = 0`` (0°/180°),
    else the intercept of a line fit, and the scale factor K1 by least squares over the
    other positions; then ``K0(T)`` and ``K1(T)`` as two :class:`PolynomialRegressor`
    of ``degree`` (cubic, spec 000 §4). Prediction: ``a_hat = (N - K0(T))/K1(T)`` and
    ``Nc_hat = K0c + K1c a_hat`` with the reference coefficients ``ref`` (a mapping with
    at least ``k0`` in mV and ``k1`` in mV/g; kept verbatim for the model file).

    Parameters
    ----------
    degree : int, default=3
        Degree of K0(T) and K1(T) (spec 000 §4: cubic).
    """

    def __init__(self, *, degree: int = 3):
        self.degree = degree

    def get_params(self, deep: bool = True) -> dict:
        return {"degree": self.degree}

    def set_params(self, **params) -> SeparatePolynomials:
        for k, v in params.items():
            if k != "degree":
                raise InputError(f"SeparatePolynomials has no parameter {k!r}")
            self.degree = v
        return self

    def fit(self, T, N, a_i, set_point, ref) -> SeparatePolynomials:
        """Fit on one row per (set point, position): temperature ``T`` (°C), output ``N``
        (mV), nominal input ``a_i`` (g), ``set_point`` (°C); ``ref`` as above."""
        T, N = np.asarray(T, float), np.asarray(N, float)
        a_i, set_point = np.asarray(a_i, float), np.asarray(set_point, float)
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
        self.ref_ = {k: float(v) for k, v in dict(ref).items()}
        return self

    def predict(self, X) -> np.ndarray:
        """``Nc_hat`` (mV) at ``X = [T, N]`` (n, 2)."""
        if not hasattr(self, "k0_"):
            raise NotFittedError("SeparatePolynomials.predict called before fit")
        X = np.asarray(X, float)
        a_hat = (X[:, 1] - self.k0_.predict(X[:, 0])) / self.k1_.predict(X[:, 0])
        return self.ref_["k0"] + self.ref_["k1"] * a_hat

    def to_dict(self) -> dict:
        if not hasattr(self, "k0_"):
            raise NotFittedError("SeparatePolynomials.to_dict called before fit")
        return {"degree": self.degree, "k0": self.k0_.to_dict(), "k1": self.k1_.to_dict(),
                "ref": dict(self.ref_)}

    @classmethod
    def from_dict(cls, d) -> SeparatePolynomials:
        obj = cls(degree=int(d["degree"]))
        obj.k0_ = PolynomialRegressor.from_dict(d["k0"])
        obj.k1_ = PolynomialRegressor.from_dict(d["k1"])
        obj.k0_.warn_extrapolation = obj.k1_.warn_extrapolation = False
        obj.ref_ = {k: float(v) for k, v in dict(d["ref"]).items()}
        if "k0" not in obj.ref_ or "k1" not in obj.ref_:
            raise InputError("POLY-SEP model: reference coefficients need k0 and k1")
        return obj
