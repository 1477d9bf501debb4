"""Single-axis pendulous (quartz flexure, force-rebalance) accelerometer, IEEE Std 1293
style static model, and the tumble-test reductions of spec 000.

Static model (spec 000 §1 eq. 1)::

    U = K0 + K1*a_i + K2*a_i^2 + Kip*a_i*a_p + Kp*a_p

with ``a_i``/``a_p`` the specific force along the input/pendulous axis in g and ``U``
the output in any unit (mV in spec 000, V in spec 003); the coefficients carry that
unit per g^k. ``Kp = K1*delta`` is the input-axis misalignment toward the pendulous
axis. A multi-position tumble about the horizontal output axis visits
``theta_k = 360/n * k`` with ``a_i = sin(theta)``, ``a_p = cos(theta)`` (spec 000
§2.2, the common convention; the seed does not state it).

The pieces here are general so that other studies (the dual-meter model of spec 003)
can reuse them: the coefficients dataclass with its forward model, the least-squares
fit of eq. 1 over tumble positions, the 0°/180° bias, the eq.-3 scale factor, the
integrated output Ua of eq. 5 and the reference-temperature target of eq. 6.

References
----------
IEEE Std 1293-2018, Specification format guide and test procedure for linear
single-axis, nongyroscopic accelerometers. Spec 000 §1-§3.1.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from inertialab.errors import InputError, UnderdeterminedError

#: Names of the eq.-1 terms in design-matrix order.
TERMS = ("k0", "k1", "k2", "kip", "kp")


@dataclass(frozen=True)
class SingleAxisCoefficients:
    """Coefficients of eq. 1, in output units per g^k.

    Attributes
    ----------
    k0 : bias (output units)
    k1 : scale factor (output units per g)
    k2 : second-order coefficient (per g^2)
    kip : input-pendulous cross-coupling (per g^2)
    kp : misalignment term ``K1*delta`` (per g)
    """

    k0: float
    k1: float
    k2: float = 0.0
    kip: float = 0.0
    kp: float = 0.0

    def output(self, a_i, a_p=0.0) -> np.ndarray:
        """Eq. 1 without noise: the output for inputs ``a_i``, ``a_p`` in g."""
        a_i = np.asarray(a_i, dtype=float)
        a_p = np.asarray(a_p, dtype=float)
        return self.k0 + self.k1 * a_i + self.k2 * a_i**2 + self.kip * a_i * a_p + self.kp * a_p

    @property
    def bias_g(self) -> float:
        """Bias in g, ``K0/K1``."""
        return self.k0 / self.k1

    @property
    def misalignment_rad(self) -> float:
        """Input-axis misalignment toward the pendulous axis, ``Kp/K1`` (rad)."""
        return self.kp / self.k1

    def to_dict(self) -> dict:
        return {k: float(v) for k, v in asdict(self).items()}

    @classmethod
    def from_dict(cls, d: dict) -> SingleAxisCoefficients:
        try:
            return cls(**{k: float(d[k]) for k in TERMS if k in d})
        except (TypeError, ValueError) as exc:
            raise InputError(f"single-axis coefficients: {exc}") from exc


@dataclass(frozen=True)
class TumblePositions:
    """Nominal tumble positions: ``angle_deg``, ``a_in_g = sin``, ``a_pend_g = cos``."""

    angle_deg: np.ndarray
    a_in_g: np.ndarray
    a_pend_g: np.ndarray


def tumble_positions(n: int = 24) -> TumblePositions:
    """``n`` equally spaced positions (default 24, every 15°; spec 000 §2.2)."""
    if n < 1:
        raise InputError(f"need at least one position, got {n}")
    ang = np.arange(n) * (360.0 / n)
    rad = np.deg2rad(ang)
    s, c = np.sin(rad), np.cos(rad)
    # exact zeros at the axes so eq. 3 and the 0/180 bias see clean values
    s[np.isclose(s, 0.0, atol=1e-12)] = 0.0
    c[np.isclose(c, 0.0, atol=1e-12)] = 0.0
    return TumblePositions(ang, s, c)


def design_matrix(a_i, a_p, *, include_kp: bool = True) -> np.ndarray:
    """Regressors of eq. 1: columns 1, a_i, a_i^2, a_i*a_p and (optionally) a_p."""
    a_i = np.asarray(a_i, dtype=float).ravel()
    a_p = np.asarray(a_p, dtype=float).ravel()
    cols = [np.ones_like(a_i), a_i, a_i**2, a_i * a_p]
    if include_kp:
        cols.append(a_p)
    return np.column_stack(cols)


@dataclass(frozen=True)
class SingleAxisFit:
    """Least-squares fit of eq. 1.

    Attributes
    ----------
    coefficients : SingleAxisCoefficients
    stderr : dict
        Standard error of each fitted term (output units per g^k), from the residual
        variance; terms not fitted are absent.
    residual_rms : float
        RMS residual in output units.
    n : int
        Number of equations.
    """

    coefficients: SingleAxisCoefficients
    stderr: dict
    residual_rms: float
    n: int


def fit_single_axis(a_i, a_p, output, *, include_kp: bool = True) -> SingleAxisFit:
    """Fit eq. 1 by linear least squares (spec 000 §3.1 step 1).

    Parameters
    ----------
    a_i, a_p : array-like (n,)
        Inputs in g (nominal tumble values).
    output : array-like (n,)
        Measured output.
    include_kp : bool, default=True
        Fit the misalignment term ``Kp`` (not in the seed's eq. 1; spec 000 adds it).

    Raises
    ------
    UnderdeterminedError
        When the positions cannot separate the terms (rank < number of terms).
    """
    A = design_matrix(a_i, a_p, include_kp=include_kp)
    y = np.asarray(output, dtype=float).ravel()
    if y.size != A.shape[0]:
        raise InputError(f"{A.shape[0]} positions but {y.size} outputs")
    if not np.all(np.isfinite(A)) or not np.all(np.isfinite(y)):
        raise InputError("tumble fit: inputs and outputs must be finite")
    p = A.shape[1]
    beta, _, rank, sv = np.linalg.lstsq(A, y, rcond=None)
    if rank < p:
        raise UnderdeterminedError(
            f"the {y.size} tumble positions determine only {rank} of the {p} eq.-1 terms")
    res = y - A @ beta
    dof = y.size - p
    s2 = float(res @ res / dof) if dof > 0 else float("nan")
    cov = s2 * np.linalg.inv(A.T @ A)
    names = TERMS[:p]
    coef = SingleAxisCoefficients(**{k: float(v) for k, v in zip(names, beta)})
    stderr = {k: float(np.sqrt(max(cov[j, j], 0.0))) for j, k in enumerate(names)}
    return SingleAxisFit(coef, stderr, float(np.sqrt(np.mean(res * res))), int(y.size))


def bias_0_180(u_0, u_180):
    """Bias from the two horizontal-input positions, ``(U(0°) + U(180°))/2`` (spec 000 §2.2);
    the mean cancels ``Kp*a_p``."""
    return 0.5 * (np.asarray(u_0, dtype=float) + np.asarray(u_180, dtype=float))


def scale_factor_eq3(output, k0, a_i):
    """Apparent scale factor ``(U - K0)/a_i`` of spec 000 eq. 3 (positions with a_i = 0
    give nan)."""
    a = np.asarray(a_i, dtype=float)
    u = np.asarray(output, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a != 0.0, (u - k0) / np.where(a != 0.0, a, 1.0), np.nan)


def integrated_output(output, a_i, a_p, ref: SingleAxisCoefficients) -> np.ndarray:
    """``Ua = U - K2c a_i^2 - Kipc a_i a_p - Kpc a_p`` (spec 000 eq. 5, sign corrected)."""
    a_i = np.asarray(a_i, dtype=float)
    a_p = np.asarray(a_p, dtype=float)
    return np.asarray(output, dtype=float) - ref.k2 * a_i**2 - ref.kip * a_i * a_p - ref.kp * a_p


def reference_target(a_i, ref: SingleAxisCoefficients) -> np.ndarray:
    """``Nc = K0c + K1c a_i`` (spec 000 eq. 6)."""
    return ref.k0 + ref.k1 * np.asarray(a_i, dtype=float)


def higher_order_terms(a_i, a_p, ref: SingleAxisCoefficients) -> np.ndarray:
    """``K2c a_i^2 + Kipc a_i a_p + Kpc a_p``: what eq. 5 subtracts."""
    a_i = np.asarray(a_i, dtype=float)
    a_p = np.asarray(a_p, dtype=float)
    return ref.k2 * a_i**2 + ref.kip * a_i * a_p + ref.kp * a_p


def estimate_input(output, a_p, ref: SingleAxisCoefficients, *, passes: int = 1) -> np.ndarray:
    """Deployment estimate of ``a_i`` when it is unknown (spec 000 §3.1): start from
    ``(U - K0c)/K1c`` and apply ``passes`` fixed-point passes of eq. 1 (one is enough:
    K2 and Kip are µg-level)."""
    u = np.asarray(output, dtype=float)
    a_p = np.asarray(a_p, dtype=float)
    a = (u - ref.k0 - ref.kp * a_p) / ref.k1
    for _ in range(passes):
        a = (u - ref.k0 - ref.kp * a_p - ref.k2 * a**2 - ref.kip * a * a_p) / ref.k1
    return a


@dataclass(frozen=True)
class BiasScaleFactorDrift:
    """Bias and eq.-3 scale factor of a multi-temperature tumble per set point (spec 000
    §2.1-§2.2, the seed's Figs. 3 and 4).

    Attributes
    ----------
    set_point_c : (n_T,) set points, ascending; ``temp_c`` : (n_T,) mean measured
        temperature of each (°C)
    bias_mv : (n_T,) ``(U(0°) + U(180°))/2`` (mV; nan where a set point lacks them)
    bias_drift_mg : (n_T,) ``(K0(T) - K0(T_ref))/K1c`` in mg
    levels_g : (n_L,) input levels a_i != 0, signed, ascending (g; the mean nominal a_i
        of the positions of the level)
    scale_factor_mv_per_g : (n_T, n_L) eq. 3 ``(U - K0(T))/a_i`` averaged over the
        positions of each level (mV/g)
    scale_factor_drift_mv_per_g : (n_T, n_L) ``K1(T, a) - K1(T_ref, a)`` (mV/g)
    scale_factor_drift_ppm : the same relative to K1c (ppm)
    reference_temp_c : the reference set point
    """

    set_point_c: np.ndarray
    temp_c: np.ndarray
    bias_mv: np.ndarray
    bias_drift_mg: np.ndarray
    levels_g: np.ndarray
    scale_factor_mv_per_g: np.ndarray
    scale_factor_drift_mv_per_g: np.ndarray
    scale_factor_drift_ppm: np.ndarray
    reference_temp_c: float

    def to_dict(self) -> dict:
        return {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                for k, v in asdict(self).items()}

    def summary(self) -> dict:
        """Maxima over set points (and levels): the seed's 1.7 mg bias drift and 6 mV/g
        scale-factor drift (spec 000 §6)."""
        with np.errstate(invalid="ignore"):
            return {"max_bias_drift_mg": float(np.nanmax(np.abs(self.bias_drift_mg))),
                    "max_scale_factor_drift_mv_per_g":
                        float(np.nanmax(np.abs(self.scale_factor_drift_mv_per_g))),
                    "max_scale_factor_drift_ppm":
                        float(np.nanmax(np.abs(self.scale_factor_drift_ppm)))}


def bias_scale_factor_drift(set_point_c, temp_c, a_in_g, output, *, k1_ref: float,
                            reference_temp_c: float = 55.0,
                            decimals: int = 3) -> BiasScaleFactorDrift:
    """Bias (0°/180° mean) and eq.-3 scale factor per set point and input level, and their
    drift against the reference set point (spec 000 §2.1.1, §2.1.2, eq. 3).

    One value per (set point, position) is expected (averaged tumble rows); positions with
    the same nominal ``a_i`` (rounded to ``decimals``) form one input level. ``k1_ref``
    (output units per g) converts the bias drift to mg and the scale-factor drift to ppm.
    """
    sp_all = np.asarray(set_point_c, dtype=float)
    t_all = np.asarray(temp_c, dtype=float)
    a_exact = np.asarray(a_in_g, dtype=float)
    a_all = np.round(a_exact, decimals)  # grouping key only
    u_all = np.asarray(output, dtype=float)
    sps = np.unique(sp_all)
    keys = np.unique(a_all[a_all != 0.0])
    levels = np.array([np.mean(a_exact[a_all == k]) for k in keys])
    bias = np.full(sps.size, np.nan)
    temp = np.full(sps.size, np.nan)
    sf = np.full((sps.size, levels.size), np.nan)
    for i, sp in enumerate(sps):
        m = sp_all == sp
        temp[i] = np.mean(t_all[m])
        zero = m & (a_all == 0.0)
        if np.any(zero):
            bias[i] = np.mean(u_all[zero])
        k = scale_factor_eq3(u_all[m], bias[i], a_exact[m])
        for j, key in enumerate(keys):
            sel = a_all[m] == key
            if np.any(sel):
                sf[i, j] = np.mean(k[sel])
    is_ref = np.isclose(sps, reference_temp_c, atol=1e-6)
    if not np.any(is_ref):
        raise InputError(f"no set point at the reference temperature {reference_temp_c:g} °C")
    r = int(np.flatnonzero(is_ref)[0])
    sf_drift = sf - sf[r]
    return BiasScaleFactorDrift(
        set_point_c=sps, temp_c=temp, bias_mv=bias,
        bias_drift_mg=(bias - bias[r]) / k1_ref * 1e3, levels_g=levels,
        scale_factor_mv_per_g=sf, scale_factor_drift_mv_per_g=sf_drift,
        scale_factor_drift_ppm=sf_drift / k1_ref * 1e6, reference_temp_c=float(reference_temp_c))
