"""Generalized method of wavelet moments (GMWM; Guerrier et al. 2013; issue 14 item 6).

Placeholder header; the estimator follows below the theoretical Allan variances of the
latent processes, which the virtual lab (:mod:`inertialab.sim.mems_presets`) uses for
its ground truth too.
"""

from __future__ import annotations

import math

import numpy as np

# ----------------------------------------------------------------------------- theory
# Exact Allan variance of each latent process of a rate record sampled at tau0, at the
# averaging factor m (tau = m tau0). The Haar wavelet variance at scale tau_j = 2^(j-1)
# is half of it: nu^2(tau_j) = AVAR(m = tau_j) / 2.


def avar_white(m, sigma2: float) -> np.ndarray:
    """White rate noise of per-sample variance ``sigma2``: ``sigma2 / m``."""
    m = np.asarray(m, dtype=float)
    return sigma2 / m


def avar_quant(m, q2: float, tau0: float = 1.0) -> np.ndarray:
    """Angle (phase) white noise of variance ``q2`` (angle unit^2), as rate increments
    ``(x_{k+1} - x_k)/tau0``: ``3 q2 / (m tau0)^2`` (IEEE 952 quantisation noise)."""
    m = np.asarray(m, dtype=float)
    return 3.0 * q2 / (m * tau0) ** 2


def avar_rw(m, gamma2: float) -> np.ndarray:
    """Rate random walk with per-sample increment variance ``gamma2``:
    ``gamma2 (2 m^2 + 1) / (6 m)`` (exact discrete form)."""
    m = np.asarray(m, dtype=float)
    return gamma2 * (2.0 * m * m + 1.0) / (6.0 * m)


def avar_drift(m, omega: float) -> np.ndarray:
    """Deterministic rate ramp of ``omega`` per sample: ``omega^2 m^2 / 2``."""
    m = np.asarray(m, dtype=float)
    return 0.5 * (omega * m) ** 2


def avar_ar1(m, phi: float, s2: float) -> np.ndarray:
    """Stationary AR(1) ``z_k = phi z_{k-1} + e_k`` with stationary variance ``s2``
    (a Gauss–Markov process of correlation time ``-tau0/ln(phi)``), exact discrete form.

    With ``S_m`` the sum of ``m`` consecutive values and ``S'_m`` the next one,
    ``AVAR(m) = (Var S_m - Cov(S_m, S'_m)) / m^2``, which reduces to
    ``s2 g(m, e) / (m^2 (1 - phi)^2)``, ``e = ln phi``,
    ``g = m - 3 phi - m phi^2 + 4 phi^(m+1) - phi^(2m+1)``. ``g`` is evaluated from its
    power series in ``e`` (the k = 1, 2 coefficients vanish) where ``(2m+1)|e| <= 1``,
    which keeps full precision for correlation times far above ``m tau0``.
    """
    m = np.asarray(m, dtype=float)
    phi = float(phi)
    if phi <= 0.0:
        if phi == 0.0:
            return s2 / m
        g = m - 3 * phi - m * phi**2 + 4 * phi ** (m + 1) - phi ** (2 * m + 1)
        return s2 * g / (m * m * (1 - phi) ** 2)
    e = math.log(phi)
    x = -math.expm1(e)
    small = (2 * m + 1) * abs(e) <= 1.0
    g = np.empty(m.shape)
    mm = m[~small]
    if mm.size:
        g[~small] = (mm - 3 * phi - mm * phi * phi + 4 * np.exp((mm + 1) * e)
                     - np.exp((2 * mm + 1) * e))
    ms = m[small]
    if ms.size:
        tot = np.zeros(ms.shape)
        fact = 2.0
        for k in range(3, 40):
            fact *= k
            c = (-3.0 - ms * 2.0**k + 4.0 * (ms + 1) ** k - (2 * ms + 1) ** k) / fact
            term = c * e**k
            tot += term
            if np.all(np.abs(term) <= 1e-18 * np.abs(tot)):
                break
        g[small] = tot
    return s2 * g / (m * m * x * x)


__all__ = ["avar_ar1", "avar_drift", "avar_quant", "avar_rw", "avar_white"]
