"""D-optimal exact designs for linear models in one angle (spec 003 §7.2).

Given a basis ``f(theta)`` (default the trigonometric polynomial of degree 3, seven
columns), :func:`d_optimal_design` picks ``n`` angles from a candidate set that maximise
``log det(F^T W F)`` (``W`` the inverse noise variances), by a greedy start followed by
Fedorov-type exchange sweeps, each swap evaluated for all candidates at once with
batched ``slogdet``. Repeated angles are allowed (replicates). :func:`design_criteria`
gives D (log det), A (trace of the inverse) and E (smallest eigenvalue) criteria and the
condition number.

Equally spaced ``n >= 2 degree + 1`` positions give ``F^T F = diag(n, n/2, ..., n/2)``
and are D-optimal for trigonometric regression (Pukelsheim, *Optimal Design of
Experiments*, 1993, §9.16); the exchange recovers them when the candidate grid contains
them. No maintained Python library does exact D-optimal design on an arbitrary
candidate set with weights (pyDOE2 builds factorial and Latin-hypercube plans only), so
it is written here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from inertialab.errors import InputError, UnderdeterminedError

__all__ = ["DesignCriteria", "DesignResult", "d_optimal_design", "design_criteria",
           "trig_basis"]


def trig_basis(theta, degree: int = 3) -> np.ndarray:
    """``[1, cos t, sin t, ..., cos(degree t), sin(degree t)]`` for angles in rad, (n, 2 degree + 1)."""
    t = np.asarray(theta, dtype=float).ravel()
    cols = [np.ones_like(t)]
    for j in range(1, degree + 1):
        cols += [np.cos(j * t), np.sin(j * t)]
    return np.column_stack(cols)


@dataclass(frozen=True)
class DesignCriteria:
    """Optimality criteria of an information matrix ``M = F^T W F``."""

    log_det: float  # D: log det M (-inf when singular)
    a_trace_inv: float  # A: trace M^-1 (inf when singular)
    e_min_eig: float  # E: smallest eigenvalue of M
    cond: float  # condition number of sqrt(W) F
    rank: int


def design_criteria(theta, *, basis: Callable | None = None, weights=None) -> DesignCriteria:
    """D, A and E criteria of the design ``theta`` (rad) for ``basis`` (default trig degree 3)."""
    basis = basis or trig_basis
    F = np.asarray(basis(np.asarray(theta, dtype=float)), dtype=float)
    w = np.ones(F.shape[0]) if weights is None else np.asarray(weights, dtype=float)
    Fw = F * np.sqrt(w)[:, None]
    M = Fw.T @ Fw
    ev = np.linalg.eigvalsh(M)
    s = np.linalg.svd(Fw, compute_uv=False)
    rank = int(np.sum(s > 1e-10 * s[0])) if s.size and s[0] > 0 else 0
    full = rank == F.shape[1] and F.shape[0] >= F.shape[1]
    sign, ld = np.linalg.slogdet(M)
    return DesignCriteria(
        log_det=float(ld) if (full and sign > 0) else float("-inf"),
        a_trace_inv=float(np.sum(1.0 / ev)) if full else float("inf"),
        e_min_eig=float(max(ev[0], 0.0)),
        cond=float(s[0] / s[-1]) if full else float("inf"),
        rank=rank,
    )


@dataclass(frozen=True)
class DesignResult:
    """An exact design: the chosen angles (rad, sorted) and its criteria."""

    theta: np.ndarray
    criteria: DesignCriteria
    n_exchanges: int
    candidates: np.ndarray


def d_optimal_design(n: int, *, candidates=None, basis: Callable | None = None,
                     weights=None, max_sweeps: int = 50, rng=None) -> DesignResult:
    """Exact D-optimal design of ``n`` angles.

    Parameters
    ----------
    n : int
        Number of positions (>= number of basis columns).
    candidates : array_like, optional
        Candidate angles in rad; default a 1-degree grid on [0, 360).
    basis : callable, optional
        ``theta -> (len(theta), p)`` model matrix; default :func:`trig_basis` (degree 3).
    weights : array_like, optional
        Inverse noise variance per candidate (unequal noise); default equal.
    max_sweeps : int, default=50
        Exchange sweeps at most.
    rng : ignored
        Accepted for the common signature; the algorithm is deterministic.

    Raises
    ------
    UnderdeterminedError
        Fewer positions than basis columns, or candidates that cannot support the model.

    Examples
    --------
    Four positions for ``[1, cos t, sin t]``: the D-optimal design is four angles 90 deg
    apart, whose information matrix is ``diag(4, 2, 2)`` (log det = ln 16):

    >>> import numpy as np
    >>> design = d_optimal_design(4, basis=lambda t: trig_basis(t, degree=1))
    >>> np.diff(np.rad2deg(design.theta)).round(6).tolist()
    [90.0, 90.0, 90.0]
    >>> bool(np.isclose(design.criteria.log_det, np.log(16.0)))
    True
    """
    basis = basis or trig_basis
    cand = (np.deg2rad(np.arange(360.0)) if candidates is None
            else np.asarray(candidates, dtype=float).ravel())
    F = np.asarray(basis(cand), dtype=float)
    p = F.shape[1]
    if int(n) != n or n < p:
        raise UnderdeterminedError(f"a design for {p} model terms needs at least {p} "
                                   f"positions, got {n}")
    n = int(n)
    w = np.ones(cand.size) if weights is None else np.asarray(weights, dtype=float).ravel()
    if w.size != cand.size or not np.all(w > 0):
        raise InputError("weights must be positive, one per candidate")
    Fw = F * np.sqrt(w)[:, None]
    s = np.linalg.svd(Fw, compute_uv=False)
    if np.sum(s > 1e-10 * s[0]) < p:
        raise UnderdeterminedError(
            f"the candidate angles support only {int(np.sum(s > 1e-10 * s[0]))} of the "
            f"{p} model terms; widen the angle range")
    def logdet(ids):
        sign, ld = np.linalg.slogdet(Fw[ids].T @ Fw[ids])
        return ld if sign > 0 else -np.inf

    def exchange(idx_arr):
        best = logdet(idx_arr)
        n_ex = 0
        for _ in range(max_sweeps):
            improved = False
            for pos in range(n):
                base = Fw[np.delete(idx_arr, pos)]
                M0 = base.T @ base
                Ms = M0[None, :, :] + np.einsum("ci,cj->cij", Fw, Fw)
                sign, ld = np.linalg.slogdet(Ms)
                ld = np.where(sign > 0, ld, -np.inf)
                j = int(np.argmax(ld))
                if ld[j] > best + 1e-12 * max(1.0, abs(best)):
                    idx_arr[pos] = j
                    best = float(ld[j])
                    improved = True
                    n_ex += 1
            if not improved:
                break
        return idx_arr, best, n_ex

    # start 1: greedy, regularised sequential D-optimal additions
    eps = 1e-6 * np.trace(Fw.T @ Fw) / cand.size
    M = eps * np.eye(p)
    idx: list[int] = []
    for _ in range(n):
        gain = np.einsum("ij,jk,ik->i", Fw, np.linalg.inv(M), Fw)
        j = int(np.argmax(gain))
        idx.append(j)
        M = M + np.outer(Fw[j], Fw[j])
    # start 2: evenly spread over the sorted candidates (the optimum on a full circle)
    order_c = np.argsort(cand)
    spread = order_c[np.floor(np.arange(n) * cand.size / n).astype(int)]
    results = [exchange(np.array(idx)), exchange(spread.copy())]
    idx_arr, _, n_ex = max(results, key=lambda t: t[1])
    theta = np.sort(cand[idx_arr])
    order = np.argsort(cand[idx_arr])
    crit = design_criteria(cand[idx_arr][order], basis=basis, weights=w[idx_arr][order])
    return DesignResult(theta=theta, criteria=crit, n_exchanges=n_ex, candidates=cand)
