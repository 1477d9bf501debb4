"""Subtractive clustering (Chiu 1994) with the semantics of MATLAB's ``subclust``.

Every data point is a candidate cluster centre. Its *potential* is the density of
the data around it; the point of highest potential becomes the first centre, the
potentials near an accepted centre are reduced, and the next candidate is judged
against the accept/reject ratios (spec 000 §3.2, seed eqs. 14-15).

Hand-written because neither SciPy nor any maintained package inertialab depends on
offers subtractive clustering; the algorithm is short and its O(P^2 D) potential is
vectorised with NumPy (P of a few hundred points takes milliseconds).

References
----------
S. L. Chiu, "Fuzzy model identification based on cluster estimation", J. Intelligent
and Fuzzy Systems 2 (1994) 267-278. MATLAB Fuzzy Logic Toolbox ``subclust``.
Spec 000 §3.2.
"""

from __future__ import annotations

import numpy as np

from inertialab.errors import InputError
from inertialab.estimator import Estimator

#: Default hyper-parameters of spec 000 §3.2 (= MATLAB's subclust defaults).
DEFAULTS = {"radius": 0.5, "squash": 1.25, "accept": 0.5, "reject": 0.15}


def _radii(radius, d: int) -> np.ndarray:
    r = np.atleast_1d(np.asarray(radius, dtype=float))
    if r.size == 1:
        r = np.full(d, float(r[0]))
    if r.size != d:
        raise InputError(f"radius has {r.size} values but the data have {d} columns")
    if not np.all(np.isfinite(r)) or np.any(r <= 0):
        raise InputError("radius values must be positive and finite")
    return r


class SubtractiveClustering(Estimator):
    """Subtractive clustering of points in D dimensions.

    Parameters
    ----------
    radius : float or array-like (D,), default=0.5
        Range of influence ``r_a`` of a centre per dimension, in normalised units
        (fraction of the data range or of ``bounds``). Spec 000 §3.2 / MATLAB default.
    squash : float, default=1.25
        Squash factor ``eta``; potentials are reduced within ``r_b = squash*r_a``.
    accept : float, default=0.5
        Accept ratio ``eps_up``: a candidate whose potential exceeds ``accept`` times the
        first centre's potential is accepted.
    reject : float, default=0.15
        Reject ratio ``eps_down``: at or below ``reject`` times the first potential the
        search stops. Between the two a candidate is accepted when
        ``d_min + ratio >= 1`` (``d_min`` in units of ``r_a``).
    bounds : array-like (2, D) or None, default=None
        Data bounds used for normalisation (row 0 minimum, row 1 maximum); ``None`` uses
        the data's min and max. Points outside the bounds are clipped to them.

    Attributes
    ----------
    centers_ : ndarray (R, D)
        Cluster centres in the units of the data, in the order they were found.
    centers_scaled_ : ndarray (R, D)
        The same in normalised [0, 1] units.
    sigmas_ : ndarray (D,)
        Common Gaussian width per dimension, ``r_a*(max - min)/sqrt(8)`` (data units).
    indices_ : ndarray (R,) of int
        Row index of each centre in the data.
    potentials_ : ndarray (R,)
        Potential of each centre at the time it was accepted.
    bounds_ : ndarray (2, D)
        The bounds used.
    """

    def __init__(self, *, radius=0.5, squash: float = 1.25, accept: float = 0.5,
                 reject: float = 0.15, bounds=None):
        self.radius = radius
        self.squash = squash
        self.accept = accept
        self.reject = reject
        self.bounds = bounds

    def _validate(self, Z) -> np.ndarray:
        Z = np.asarray(Z, dtype=float)
        if Z.ndim == 1:
            Z = Z[:, None]
        if Z.ndim != 2 or Z.shape[0] < 1:
            raise InputError(f"data must be a non-empty (n, d) array, got shape {Z.shape}")
        if not np.all(np.isfinite(Z)):
            raise InputError("data contain NaN or infinite values")
        if not self.squash > 0:
            raise InputError(f"squash must be > 0, got {self.squash}")
        if not (0 < self.reject <= self.accept <= 1):
            raise InputError(
                f"need 0 < reject <= accept <= 1, got reject={self.reject}, accept={self.accept}")
        return Z

    def fit(self, Z) -> SubtractiveClustering:
        """Find the cluster centres of ``Z`` (n, D). Returns ``self``."""
        Z = self._validate(Z)
        n, d = Z.shape
        r = _radii(self.radius, d)
        if self.bounds is None:
            lo, hi = Z.min(axis=0), Z.max(axis=0)
        else:
            b = np.asarray(self.bounds, dtype=float)
            if b.shape != (2, d):
                raise InputError(f"bounds must have shape (2, {d}), got {b.shape}")
            lo, hi = b[0], b[1]
        span = hi - lo
        span_safe = np.where(span > 0, span, 1.0)
        X = np.clip((Z - lo) / span_safe, 0.0, 1.0)

        # potentials (seed eq. 14): P_i = sum_j exp(-4 sum_d ((x_id - x_jd)/r_d)^2)
        Xa = X / r
        sq = np.sum(Xa * Xa, axis=1)
        d2 = np.maximum(sq[:, None] + sq[None, :] - 2.0 * (Xa @ Xa.T), 0.0)
        pot = np.exp(-4.0 * d2).sum(axis=1)

        rb = self.squash * r
        idx = int(np.argmax(pot))
        ref = float(pot[idx])
        centers: list[int] = []
        cpots: list[float] = []
        cur = ref
        while True:
            centers.append(idx)
            cpots.append(cur)
            dx = (X - X[idx]) / rb
            pot = np.maximum(pot - cur * np.exp(-4.0 * np.sum(dx * dx, axis=1)), 0.0)
            found = False
            while True:
                idx = int(np.argmax(pot))
                cur = float(pot[idx])
                if cur <= 0.0:
                    break
                ratio = cur / ref
                if ratio > self.accept:
                    found = True
                    break
                if ratio <= self.reject:
                    break
                dc = (X[idx] - X[centers]) / r
                dmin = float(np.sqrt(np.min(np.sum(dc * dc, axis=1))))
                if dmin + ratio >= 1.0:
                    found = True
                    break
                pot[idx] = 0.0  # rejected as a centre; look at the next candidate
            if not found:
                break

        ci = np.asarray(centers, dtype=int)
        self.indices_ = ci
        self.centers_scaled_ = X[ci].copy()
        self.centers_ = lo + X[ci] * span
        self.potentials_ = np.asarray(cpots)
        self.sigmas_ = r * span / np.sqrt(8.0)
        self.bounds_ = np.vstack([lo, hi])
        self.radii_ = r
        return self

    @property
    def n_clusters_(self) -> int:
        if not hasattr(self, "centers_"):
            raise RuntimeError("SubtractiveClustering has not been fitted")
        return int(self.centers_.shape[0])
