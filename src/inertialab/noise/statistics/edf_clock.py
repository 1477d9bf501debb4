"""Published EDFs and bias factors of the clock statistics.

Equivalent degrees of freedom per tau of the total and Theo statistics, as NIST SP 1065
(W. J. Riley, *Handbook of Frequency Stability Analysis*, 2008, §5.2.11-5.2.15 and its
Tables 7-11) and Stable32 give them; ``n_phase`` is the number of phase points ``N``,
``m`` the averaging factor, ``alpha`` the frequency-noise exponent (+2 WPM, +1 FPM, 0 WFM,
-1 FFM, -2 RWFM, -3 FWFM, -4 RRFM).

* **TOTDEV** (Table 7, Howe & Greenhall): ``edf = b (N/m) - c``, FM noises only
  (``WFM 1.50/0, FFM 1.17/0.22, RWFM 0.93/0.36``); phase noises: the overlapping-Allan
  EDF (Greenhall & Riley 2003), as allantools' ``edf_totdev`` falls back to its simple
  EDF. Lives in :func:`inertialab.noise.statistics.edf.edf_totdev_sp1065`.
* **MTOTDEV and TTOTDEV** (Table 8): ``edf = b (N/m) - c`` (``WPM 1.90/2.10, FPM
  1.20/1.40, WFM 1.10/1.20, FFM 0.85/0.50, RWFM 0.75/0.31``) for ``m >= 16``; below
  ``m = 16`` the MDEV EDF (Greenhall & Riley 2003). TTOT uses the MTOT EDF (Stable32
  prints identical interval ratios for both). Stable32 1.6 uses the MDEV EDF up to
  ``m = 8`` (its printed bounds match it to 5e-5 with its chi-square, below), but from
  ``m = 10`` on a rule that is not Table 8 and that no published source here gives
  (docs/allan.md, "Against Stable32"); Table 8 stays.
* **HTOTDEV** (Howe, Beard, Greenhall & Riley, PTTI 2000; SP 1065 §5.2.14):
  ``edf = (N/m) / (b0 + b1 m/N)`` for ``m >= 16`` (``WFM 0.559/1.004, FFM
  0.868/1.140, RWFM 0.938/1.696``); below ``m = 16`` and for the phase noises SP 1065
  Table 5's simple EDF (Stable32's choice as its printed bounds show, see
  :func:`edf_htotdev`), the overlapping-Hadamard EDF (Greenhall & Riley 2003) for
  alpha -3, -4; ``method="greenhall"`` restores that EDF everywhere below m = 16.
* **Theo1** (Howe & Peppler 2003; SP 1065 §5.2.15), with ``r = 0.75 m`` (the Theo1
  tau in units of tau0)::

      WPM   0.86 (N+1)(N - 4r/3) / (N - r) * r / (r + 1.14)
      FPM   (4.798 N^2 - 6.374 N r + 12.387 r) / (sqrt(r + 36.6) (N - r)) * r / (r + 0.3)
      WFM   ((4.1 N + 0.8)/r - (3.1 N + 6.5)/N) * r^1.5 / (r^1.5 + 5.2)
      FFM   (2 N^2 - 1.3 N r - 3.5 r) / (N r) * r^3 / (r^3 + 2.3)
      RWFM  (4.4 N - 2)/(2.9 r) * ((4.4 N - 1)^2 - 8.6 r (4.4 N - 1) + 11.4 r^2) / (4.4 N - 3)^2

  (the FPM ``12.387 r`` term is linear as printed in Riley's Stable32 and Theo1BR code).

Bias factors (Stable32's corrections, the variance is *divided* by them):

* TOTVAR ``1 - a tau/T``, ``a = 0`` WFM, ``0.481`` FFM (``1/(3 ln 2)`` rounded as SP 1065 prints it), ``0.750`` RWFM
  (Howe 1999, "Total variance explained", Table 1; SP 1065 §5.2.11; T the record length).
* Mod Totvar / TTOT ``WPM 0.94, FPM 0.83, WFM 0.73, FFM 0.70, RWFM 0.69`` (Riley,
  "Confidence intervals and bias corrections for the Stable32 variance functions").
* Htotvar ``1 + a``, ``a = -0.005 WFM, -0.149 FFM, -0.229 RWFM, -0.283 FWFM, -0.321 RRFM``
  (Howe et al. PTTI 2000, Table 3), i.e. 0.995, 0.851, 0.771, 0.717, 0.679.
* Theo1 ``Avar/Theo1 = a + b / r^c`` (Howe & Tasset 2004, Table 1; SP 1065 §5.2.15), ``r =
  0.75 m``: ``WPM 0.09/0.74/0.40, FPM 0.14/0.82/0.30, WFM 1/0/0, FFM 1.87/-1.05/0.79,
  RWFM 2.70/-1.53/0.85``; here the Theo1 variance is *multiplied* by it (it is the ratio
  that maps Theo1 onto the Allan variance). TheoBR replaces it by the data's own ratio.

Stable32's chi-square quantiles (:func:`chi2_stable32`, :func:`stable32_chi2_interval`):
for EDF > 100 Stable32 does not invert the chi-square distribution exactly but uses
Abramowitz & Stegun 26.4.17 with 26.2.22, one coefficient mistyped (A. Wallin, "Fun with
Chi-Squared", 2020); offered as an option, the statistics use the exact quantiles.

Verified (not committed: third-party data): on Stable32's tables of a 1253-point Sr87
clock record (allantoolkit ``tests/assets/Sr87``) and of PHASE.DAT (allantools
``tests/phasedat``) these EDFs give Stable32's printed bounds to 6.6e-4 for TOTDEV (FM),
Theo1, TheoH, MTOT/TTOT up to m = 8 and HTOTDEV (FM; white PM) with the exact quantiles
(with Stable32's: MTOT/TTOT 4.7e-5, TheoH 1.1e-4, HTOTDEV below m = 16 3.6e-4); not for
MTOT/TTOT from m = 10 (up to 6.4e-2) nor for flicker-PM HTOTDEV/TOTDEV rows (1e-3 to
1.4e-2). Figures and the method: docs/allan.md.
"""

from __future__ import annotations

import math

import numpy as np

from inertialab.errors import InputError

__all__ = ["HTOT_BIAS", "HTOT_EDF", "MTOT_BIAS", "MTOT_EDF", "STABLE32_AS_A1",
           "THEO1_BIAS", "TOTDEV_BIAS_A", "chi2_stable32", "edf_htotdev", "edf_mtotdev",
           "edf_theo1", "htot_bias", "mtot_bias", "stable32_chi2_interval", "theo1_bias",
           "totdev_bias"]

#: SP 1065 Table 8: Mod Totvar (and TTOT) EDF ``b (N/m) - c`` by alpha.
MTOT_EDF = {2: (1.90, 2.10), 1: (1.20, 1.40), 0: (1.10, 1.20), -1: (0.85, 0.50),
            -2: (0.75, 0.31)}
#: Htotvar EDF ``(N/m) / (b0 + b1 m/N)`` by alpha (Howe et al. 2000; SP 1065 §5.2.14).
HTOT_EDF = {0: (0.559, 1.004), -1: (0.868, 1.140), -2: (0.938, 1.696)}
#: Smallest m at which the Htotvar EDF formula is used (Stable32; below: SP 1065 Table 5).
HTOT_EDF_MMIN = 16
#: Smallest m at which Table 8 is used for MTOT/TTOT (Stable32; below: MDEV's EDF).
MTOT_EDF_MMIN = 16
#: Mod Totvar / TTOT bias factors by alpha (variance divided by them).
MTOT_BIAS = {2: 0.94, 1: 0.83, 0: 0.73, -1: 0.70, -2: 0.69}
#: Htotvar bias ``1 + a`` by alpha (variance divided by them; phase noises 1.0).
HTOT_BIAS = {2: 1.0, 1: 1.0, 0: 0.995, -1: 0.851, -2: 0.771, -3: 0.717, -4: 0.679}
#: TOTVAR bias coefficient ``a`` of ``1 - a tau/T`` by alpha (0 for the other noises).
TOTDEV_BIAS_A = {-1: 0.481, -2: 0.750}
#: Theo1 bias ``Avar/Theo1 = a + b / r^c`` by alpha, ``r = 0.75 m``.
THEO1_BIAS = {2: (0.09, 0.74, 0.40), 1: (0.14, 0.82, 0.30), 0: (1.0, 0.0, 0.0),
              -1: (1.87, -1.05, 0.79), -2: (2.70, -1.53, 0.85)}


def _clip(alpha, lo: int = -2, hi: int = 2) -> int:
    return max(min(int(alpha), hi), lo)


def edf_mtotdev(n_phase: int, m, alpha) -> np.ndarray:
    """Mod Totvar / TTOT EDF: SP 1065 Table 8 for ``m >= 16``, the MDEV EDF of Greenhall
    & Riley (2003) below (as Stable32); alpha clipped to [-2, 2]."""
    from inertialab.noise.statistics import edf as _edf

    m = np.atleast_1d(np.asarray(m, dtype=np.int64))
    a = np.broadcast_to(np.asarray(alpha, dtype=np.int64), m.shape)
    out = np.empty(m.size)
    for i, (mm, aa) in enumerate(zip(m, a)):
        mm, aa = int(mm), _clip(aa)
        if mm >= MTOT_EDF_MMIN:
            b, c = MTOT_EDF[aa]
            out[i] = b * (float(n_phase) / mm) - c
        else:
            out[i] = _edf.edf_greenhall("mdev", int(n_phase), mm, aa)
    return out


def edf_htotdev(n_phase: int, m, alpha, *, method: str = "stable32") -> np.ndarray:
    """Htotvar EDF per tau.

    ``(N/m) / (b0 + b1 m/N)`` (Howe et al. 2000, :data:`HTOT_EDF`) for ``m >= 16`` and
    alpha in {0, -1, -2}, with either rule elsewhere:

    * ``method="stable32"`` (default): NIST SP 1065 Table 5, the simple overlapping-Allan
      EDF (:func:`inertialab.noise.statistics.edf.edf_oadev_sp1065`), below ``m = 16`` and for the
      phase noises (alpha 1, 2) at every m; the overlapping-Hadamard Greenhall EDF for
      alpha -3, -4 (Table 5 has no rows). That Stable32 uses Table 5 there is inferred
      from its printed bounds (two records, 14 FM rows below m = 16 and 9 white-PM rows:
      agreement 3.6e-4 and 1.8e-4), not documented; see docs/allan.md.
    * ``method="greenhall"``: the overlapping-Hadamard Greenhall & Riley (2003) EDF
      wherever the Howe formula does not apply (the earlier rule).
    """
    from inertialab.noise.statistics import edf as _edf

    if method not in ("stable32", "greenhall"):
        raise InputError(f"edf_htotdev: unknown method '{method}' (stable32 | greenhall)")
    m = np.atleast_1d(np.asarray(m, dtype=np.int64))
    a = np.broadcast_to(np.asarray(alpha, dtype=np.int64), m.shape)
    N = float(n_phase)
    out = np.empty(m.size)
    for i, (mm, aa) in enumerate(zip(m, a)):
        mm, aa = int(mm), int(aa)
        if mm >= HTOT_EDF_MMIN and aa in HTOT_EDF:
            b0, b1 = HTOT_EDF[aa]
            out[i] = (N / mm) / (b0 + b1 * mm / N)
        elif method == "stable32" and aa >= -2:
            out[i] = float(_edf.edf_oadev_sp1065(int(n_phase), mm, min(aa, 2)))
        else:
            out[i] = _edf.edf_greenhall("ohdev", int(n_phase), mm, _clip(aa, -4, 2))
    return out


def edf_theo1(n_phase: int, m, alpha) -> np.ndarray:
    """Theo1 EDF of Howe & Peppler (SP 1065 §5.2.15) at even ``m`` (``r = 0.75 m``);
    alpha clipped to [-2, 2]."""
    m = np.atleast_1d(np.asarray(m, dtype=float))
    a = np.broadcast_to(np.asarray(alpha, dtype=np.int64), m.shape)
    N = float(n_phase)
    out = np.empty(m.size)
    for i, (mm, aa) in enumerate(zip(m, a)):
        r = 0.75 * mm
        aa = _clip(aa)
        if aa == 2:
            e = 0.86 * (N + 1) * (N - 4.0 * r / 3.0) / (N - r) * r / (r + 1.14)
        elif aa == 1:
            e = ((4.798 * N * N - 6.374 * N * r + 12.387 * r)
                 / (math.sqrt(r + 36.6) * (N - r)) * r / (r + 0.3))
        elif aa == 0:
            e = ((4.1 * N + 0.8) / r - (3.1 * N + 6.5) / N) * r**1.5 / (r**1.5 + 5.2)
        elif aa == -1:
            e = (2 * N * N - 1.3 * N * r - 3.5 * r) / (N * r) * r**3 / (r**3 + 2.3)
        else:
            u = 4.4 * N - 1
            e = (4.4 * N - 2) / (2.9 * r) * (u * u - 8.6 * r * u + 11.4 * r * r) / (4.4 * N - 3) ** 2
        out[i] = e
    return out


def mtot_bias(alpha) -> np.ndarray:
    """Mod Totvar / TTOT bias factor per tau (1.0 outside the table)."""
    return np.array([MTOT_BIAS.get(int(v), 1.0) for v in np.atleast_1d(alpha)])


def htot_bias(alpha) -> np.ndarray:
    """Htotvar bias factor per tau (1.0 outside the table)."""
    return np.array([HTOT_BIAS.get(int(v), 1.0) for v in np.atleast_1d(alpha)])


def totdev_bias(alpha, taus_s, record_s) -> np.ndarray:
    """TOTVAR bias factor ``1 - a tau / T`` per tau (variance divided by it)."""
    a = np.array([TOTDEV_BIAS_A.get(int(v), 0.0) for v in np.atleast_1d(alpha)])
    return 1.0 - a * np.asarray(taus_s, dtype=float) / float(record_s)


def theo1_bias(alpha, m) -> np.ndarray:
    """Theo1 bias ``Avar/Theo1 = a + b / (0.75 m)^c`` per tau (alpha clipped to [-2, 2])."""
    m = np.atleast_1d(np.asarray(m, dtype=float))
    a = np.broadcast_to(np.asarray(alpha, dtype=np.int64), m.shape)
    if np.any(m <= 0):
        raise InputError("Theo1 bias needs averaging factors > 0")
    out = np.empty(m.size)
    for i, (mm, aa) in enumerate(zip(m, a)):
        p, q, c = THEO1_BIAS[_clip(aa)]
        out[i] = p + q / (0.75 * mm) ** c
    return out


# ------------------------------------------------------------- Stable32's chi-square

#: Abramowitz & Stegun 26.2.22 coefficients ``a0, a1, b1, b2`` of the normal quantile.
AS_26_2_22 = (2.30753, 0.27061, 0.99229, 0.04481)
#: The ``a1`` Stable32 uses in 26.2.22: 0.27601, A&S's 0.27061 with two digits swapped
#: (A. Wallin, "Fun with Chi-Squared", anderswallin.net, 2020-12, from Stable32's source).
STABLE32_AS_A1 = 0.27601
#: Above this EDF Stable32 uses the A&S approximation; at or below, an iterative
#: solution that agrees with the exact quantile to about 4 digits (Wallin 2020).
STABLE32_AS_EDF_MIN = 100.0


def chi2_stable32(q, edf, a1: float = STABLE32_AS_A1) -> np.ndarray:
    """Stable32's chi-square quantile: the value below which a fraction ``q`` lies.

    For ``edf > 100`` Abramowitz & Stegun 26.4.17 (Wilson-Hilferty)
    ``edf (1 - h + x sqrt(h))^3``, ``h = 2/(9 edf)``, with the normal quantile ``x`` from
    A&S 26.2.22 ``t - (a0 + a1 t)/(1 + b1 t + b2 t^2)``, ``t = sqrt(-2 ln p)``,
    ``p = min(q, 1 - q)`` (sign of ``x`` that of ``q - 1/2``) and Stable32's
    ``a1 = 0.27601`` (:data:`STABLE32_AS_A1`; pass ``a1=0.27061`` for the book's value).
    For ``edf <= 100`` the exact quantile (Stable32 iterates to it within ~1e-4).
    Source: A. Wallin, "Fun with Chi-Squared" (2020), describing Stable32's CI code.
    """
    from scipy.special import gammaincinv

    q = np.asarray(q, dtype=float)
    e = np.asarray(edf, dtype=float)
    a0, _, b1, b2 = AS_26_2_22
    p = np.minimum(q, 1.0 - q)
    t = np.sqrt(-2.0 * np.log(p))
    x = t - (a0 + a1 * t) / (1.0 + b1 * t + b2 * t * t)
    x = np.where(q < 0.5, -x, np.where(q == 0.5, 0.0, x))
    with np.errstate(invalid="ignore", divide="ignore"):
        h = 2.0 / (9.0 * e)
        approx = e * (1.0 - h + x * np.sqrt(h)) ** 3
        exact = 2.0 * gammaincinv(0.5 * e, q)
    return np.where(e > STABLE32_AS_EDF_MIN, approx, exact)


def stable32_chi2_interval(dev, edf, confidence: float = 0.683):
    """Two-sided interval of a deviation with Stable32's chi-square quantiles
    (:func:`chi2_stable32`): ``dev sqrt(edf / chi2((1 +- p)/2))``. Same form and return
    as :func:`inertialab.noise.statistics.edf.chi2_interval`; NaN where ``edf <= 0``."""
    dev = np.asarray(dev, dtype=float)
    e = np.asarray(edf, dtype=float)
    p = float(confidence)
    ok = e > 0
    ee = np.where(ok, e, 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        lo = dev * np.sqrt(ee / chi2_stable32(0.5 * (1 + p), ee))
        hi = dev * np.sqrt(ee / chi2_stable32(0.5 * (1 - p), ee))
    return np.where(ok, lo, np.nan), np.where(ok, hi, np.nan)

