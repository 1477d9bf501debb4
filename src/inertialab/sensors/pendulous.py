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
