"""Exact discrete Allan variances of the GMWM latent processes (:mod:`inertialab.noise.gmwm.fit`);
the Haar wavelet variance at a dyadic scale is half of each."""

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


#: 1/k! for k = 15 .. 3, the Horner coefficients of h(z)/z^3 (:func:`_h3`)
_H3_COEF = np.array([1.0 / math.factorial(k) for k in range(15, 2, -1)])


def _h3(z: np.ndarray) -> np.ndarray:
    """``exp(z) - 1 - z - z^2/2`` without cancellation (Horner series to z^15 for
    |z| < 0.5, evaluated on those elements only)."""
    z = np.asarray(z, dtype=float)
    out = np.expm1(z) - z - 0.5 * z * z
    small = np.abs(z) < 0.5
    if small.any():
        zs = z[small]
        out[small] = np.polyval(_H3_COEF, zs) * zs**3
    return out


def avar_ar1(m, phi: float, s2: float) -> np.ndarray:
    """Stationary AR(1) ``z_k = phi z_{k-1} + e_k`` with stationary variance ``s2``
    (a Gauss–Markov process of correlation time ``-tau0/ln(phi)``), exact discrete form.

    With ``S_m`` the sum of ``m`` consecutive values and ``S'_m`` the next one,
    ``AVAR(m) = (Var S_m - Cov(S_m, S'_m)) / m^2``, which reduces to
    ``s2 g(m, e) / (m^2 (1 - phi)^2)``, ``e = ln phi``,
    ``g = m - 3 phi - m phi^2 + 4 phi^(m+1) - phi^(2m+1)``. The constant, linear and
    quadratic parts of ``g`` in ``e`` cancel exactly, so ``g`` is evaluated as
    ``-3 h(e) - m h(2e) + 4 h((m+1)e) - h((2m+1)e)`` with ``h(z) = e^z - 1 - z - z^2/2``
    computed without cancellation: full precision for correlation times far above
    ``m tau0``.
    """
    m = np.asarray(m, dtype=float)
    phi = float(phi)
    if phi == 0.0:
        return s2 / m
    if phi < 0.0:
        g = m - 3 * phi - m * phi**2 + 4 * phi ** (m + 1) - phi ** (2 * m + 1)
        return s2 * g / (m * m * (1 - phi) ** 2)
    e = math.log(phi)
    x = -math.expm1(e)
    mr = m.ravel()
    hz = _h3(np.concatenate([[e, 2 * e], (mr + 1) * e, (2 * mr + 1) * e]))
    h1, h2 = hz[0], hz[1]
    n = m.size
    g = -3.0 * h1 - m * h2 + 4.0 * hz[2:n + 2].reshape(m.shape) - hz[n + 2:].reshape(m.shape)
    return s2 * g / (m * m * x * x)


__all__ = ["avar_ar1", "avar_drift", "avar_quant", "avar_rw", "avar_white"]
