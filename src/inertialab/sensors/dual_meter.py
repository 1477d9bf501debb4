"""Two orthogonal pendulous accelerometers tumbled about their pendulous axes (spec 003 §1–2).

Forward models and design matrices of the dual-meter dividing-head calibration:

* :func:`ieee1293_output` — the single-axis accelerometer model equation of IEEE Std
  1293-1998 (output over K1 as a function of the input, pendulous and output-axis
  accelerations); :func:`pa_tumble_output` — the form it takes in a tumble about the
  pendulous axis (a_p = 0), where only K0, k1, K2, K3, K_io (here ``Kx``) and K_oo
  survive (spec §1.3).
* :func:`meter_outputs` — exact normalised outputs of meters A and B at head angle
  phi (spec §1.2–1.4), with all second-order terms.
* :func:`single_design` — the single-meter regression of spec §1.4 (rank 5).
* :func:`g2_observation`, :func:`g2_design` — the g^2 observation ``y = (u_A^2 + u_B^2 - 1)/2``
  and its 9-column linearised design (spec §1.5), in which the head angle errors
  cancel to first order; :func:`harmonic_matrix` and :func:`harmonic_map` — its
  7-harmonic standard form ``A = H M`` (spec §1.6), rank 7, null directions n1, n2.
* :func:`estimable_combinations` — the named estimable combinations (weights on the 9
  coefficients) for the given OA signs.
* :func:`reduce_to_g` — DMM voltage to local-g units (spec §2.3 step 3);
  :func:`average_directions` — CCW/CW mean and difference (§2.3 step 4).

Coefficient units: K0 in g, k1 dimensionless (g/g), K2 and Kx in g/g^2, K3 in g/g^3,
angles in rad. "g" is local gravity throughout.

The spec-000 module ``sensors/pendulous.py`` models the same IEEE 1293 accelerometer for
multi-position tumbles at several temperatures; :func:`ieee1293_output` is the general
equation both can share (see the study report on merging them).
"""

from __future__ import annotations

import numpy as np

from inertialab import units
from inertialab.errors import InputError

__all__ = [
    "COEF_NAMES",
    "COEF_UNITS",
    "PAPER_ALIASES",
    "TURN_ON_TAU",
    "SINGLE_NAMES",
    "average_directions",
    "canonical_coef_name",
    "estimable_combinations",
    "g2_design",
    "g2_exact",
    "g2_observation",
    "harmonic_map",
    "harmonic_matrix",
    "head_error_bias",
    "ieee1293_output",
    "meter_outputs",
    "null_directions",
    "pa_tumble_output",
    "reduce_to_g",
    "single_design",
]

#: The nine g^2-model coefficients in the paper's order (spec §1.5); case-sensitive.
COEF_NAMES = ("KA0", "KB0", "kA1", "kB1", "eta", "KA2", "KB2", "KAx", "KBx")
#: Units of the coefficients.
COEF_UNITS = {"KA0": "g", "KB0": "g", "kA1": "g/g", "kB1": "g/g", "eta": "rad",
              "KA2": "g/g^2", "KB2": "g/g^2", "KAx": "g/g^2", "KBx": "g/g^2",
              "delta_A": "rad", "delta_B": "rad"}
#: Unknowns of the single-meter fits (spec §3.1): meter A, meter B.
SINGLE_NAMES = {"A": ("KA0", "kA1", "delta_A", "KA2", "KAx"),
                "B": ("KB0", "kB1", "delta_B", "KB2", "KBx")}
#: Harmonic columns of the standard form (spec §1.6 order).
HARMONIC_NAMES = ("h0", "hc2", "hs2", "hs1", "hc1", "hs3", "hc3")
#: The paper's spelling of the cross-coupling coefficients (spec 003 §1.3): the seed calls
#: the term K_ip (``KAip``, ``KBip``); in a tumble about the pendulous axis it can only be
#: K_io, named ``Kx`` here. Tables that mirror the paper label ``KAx``/``KBx`` with these
#: aliases, and prior and model files may use them in place of the canonical names.
PAPER_ALIASES = {"KAx": "KAip_paper", "KBx": "KBip_paper"}
#: Turn-on repeatability tau of each coefficient (spec §6.5): K0 20 ug, k1 30 ppm,
#: eta 5 urad, K2/Kx 5 ug/g^2 (assumed, QA-2000-class one-year repeatabilities). The
#: virtual lab draws units with it; a prior from past calibrations floors its SDs at tau/2.
TURN_ON_TAU = {"KA0": 2e-5, "KB0": 2e-5, "kA1": 3e-5, "kB1": 3e-5, "eta": 5e-6,
               "KA2": 5e-6, "KB2": 5e-6, "KAx": 5e-6, "KBx": 5e-6}


def ieee1293_output(a_i, a_p=0.0, a_o=0.0, *, K0=0.0, K2=0.0, K3=0.0, K_ip=0.0, K_io=0.0,
                    K_po=0.0, K_pp=0.0, K_oo=0.0, delta_o=0.0, delta_p=0.0, k1=0.0):
    """IEEE Std 1293-1998 model equation, output divided by the nominal scale factor.

    ``E/K1 = K0 + (1 + k1) a_i + K2 a_i^2 + K3 a_i^3 + K_ip a_i a_p + K_io a_i a_o
    + K_po a_p a_o + K_pp a_p^2 + K_oo a_o^2 + delta_o a_p - delta_p a_o`` (accelerations
    in g; k1 is the scale-factor correction relative to the nominal K1).
    """
    a_i, a_p, a_o = (np.asarray(v, dtype=float) for v in (a_i, a_p, a_o))
    return (K0 + (1.0 + k1) * a_i + K2 * a_i**2 + K3 * a_i**3 + K_ip * a_i * a_p
            + K_io * a_i * a_o + K_po * a_p * a_o + K_pp * a_p**2 + K_oo * a_o**2
            + delta_o * a_p - delta_p * a_o)


def pa_tumble_output(a_i, a_o, *, K0, k1, K2, Kx, K3=0.0, K_oo=0.0):
    """IEEE 1293 restricted to a tumble about the pendulous axis (a_p = 0, spec §1.3).

    ``Kx`` is the observable in-plane cross-coupling K_io (the paper's "K_ip").
    """
    return ieee1293_output(a_i, 0.0, a_o, K0=K0, k1=k1, K2=K2, K3=K3, K_io=Kx, K_oo=K_oo)


def meter_outputs(phi, coef: dict, *, s_a: int = 1, s_b: int = 1, K3=(0.0, 0.0),
                  K_oo=(0.0, 0.0)):
    """Exact normalised outputs (u_A, u_B) in local g at true head angle ``phi`` (rad).

    Meter A: ``a_i = sin phi``, ``a_o = s_A cos phi``. Meter B (IA turned by 90 deg + eta):
    ``a_i = cos(phi + eta)``, ``a_o = -s_B sin(phi + eta)`` (spec §1.2). ``phi`` already
    contains delta_A and the head error; ``coef`` maps :data:`COEF_NAMES` to values.
    """
    phi = np.asarray(phi, dtype=float)
    eta = coef["eta"]
    ua = pa_tumble_output(np.sin(phi), s_a * np.cos(phi), K0=coef["KA0"], k1=coef["kA1"],
                          K2=coef["KA2"], Kx=coef["KAx"], K3=K3[0], K_oo=K_oo[0])
    ub = pa_tumble_output(np.cos(phi + eta), -s_b * np.sin(phi + eta), K0=coef["KB0"],
                          k1=coef["kB1"], K2=coef["KB2"], Kx=coef["KBx"], K3=K3[1],
                          K_oo=K_oo[1])
    return ua, ub


def single_design(theta, meter: str, *, s: int = 1):
    """Single-meter regression (spec §1.4 / §3.1).

    Returns ``(X, offset)`` with the model ``u - offset = X b``: meter A
    ``X = [1, s, c, s^2, s_A s c]`` (KA0, kA1, delta_A, KA2, KAx), offset ``sin theta``;
    meter B ``X = [1, c, -s, c^2, -s_B s c]`` (KB0, kB1, delta_B, KB2, KBx), offset
    ``cos theta``.
    """
    t = np.asarray(theta, dtype=float).ravel()
    sn, cs = np.sin(t), np.cos(t)
    one = np.ones_like(t)
    if meter == "A":
        return np.column_stack([one, sn, cs, sn**2, s * sn * cs]), sn
    if meter == "B":
        return np.column_stack([one, cs, -sn, cs**2, -s * sn * cs]), cs
    raise InputError(f"meter must be 'A' or 'B', got {meter!r}")


def g2_observation(u_a, u_b):
    """``y = (u_A^2 + u_B^2 - 1)/2`` (spec §1.5)."""
    u_a = np.asarray(u_a, dtype=float)
    u_b = np.asarray(u_b, dtype=float)
    return 0.5 * (u_a * u_a + u_b * u_b - 1.0)


def g2_design(theta, *, s_a: int = 1, s_b: int = 1) -> np.ndarray:
    """Linearised g^2 design ``a_n = [s, c, s^2, c^2, -s c, s^3, c^3, s_A s^2 c, -s_B s c^2]``."""
    t = np.asarray(theta, dtype=float).ravel()
    s, c = np.sin(t), np.cos(t)
    return np.column_stack([s, c, s * s, c * c, -s * c, s**3, c**3, s_a * s * s * c,
                            -s_b * s * c * c])


def harmonic_matrix(theta) -> np.ndarray:
    """``H = [1, cos 2t, sin 2t, sin t, cos t, sin 3t, cos 3t]`` (spec §1.6 / §3.2(a))."""
    t = np.asarray(theta, dtype=float).ravel()
    return np.column_stack([np.ones_like(t), np.cos(2 * t), np.sin(2 * t), np.sin(t),
                            np.cos(t), np.sin(3 * t), np.cos(3 * t)])


def harmonic_map(*, s_a: int = 1, s_b: int = 1) -> np.ndarray:
    """The 7x9 matrix M with ``g2_design(theta) = harmonic_matrix(theta) @ M`` exactly."""
    M = np.zeros((7, 9))
    # columns: KA0 KB0 kA1 kB1 eta KA2 KB2 KAx KBx; rows: h0 hc2 hs2 hs1 hc1 hs3 hc3
    M[3, 0] = 1.0
    M[4, 1] = 1.0
    M[0, 2], M[1, 2] = 0.5, -0.5
    M[0, 3], M[1, 3] = 0.5, 0.5
    M[2, 4] = -0.5
    M[3, 5], M[5, 5] = 0.75, -0.25
    M[4, 6], M[6, 6] = 0.75, 0.25
    M[4, 7], M[6, 7] = 0.25 * s_a, -0.25 * s_a
    M[3, 8], M[5, 8] = -0.25 * s_b, -0.25 * s_b
    return M


def null_directions(*, s_a: int = 1, s_b: int = 1) -> np.ndarray:
    """The exact null directions n1, n2 of the g^2 design as columns (9, 2), spec §1.6."""
    n = np.zeros((9, 2))
    n[[0, 5, 8], 0] = (-1.0, 1.0, -float(s_b))
    n[[1, 6, 7], 1] = (-1.0, 1.0, float(s_a))
    return n


def estimable_combinations(*, s_a: int = 1, s_b: int = 1) -> dict[str, np.ndarray]:
    """Named estimable combinations: weights on :data:`COEF_NAMES` (spec §3.2(a)).

    ``kA1``, ``kB1``, ``eta`` alone and ``KA2 + s_B KBx``, ``KB2 - s_A KAx``,
    ``KA0 + KA2``, ``KB0 + KB2``; together a basis of the estimable space (dimension 7).
    """
    idx = {n: i for i, n in enumerate(COEF_NAMES)}

    def vec(**w):
        v = np.zeros(9)
        for k, x in w.items():
            v[idx[k]] = x
        return v

    sb = "+" if s_b > 0 else "-"
    sa = "-" if s_a > 0 else "+"
    return {
        "kA1": vec(kA1=1.0),
        "kB1": vec(kB1=1.0),
        "eta": vec(eta=1.0),
        f"KA2{sb}KBx": vec(KA2=1.0, KBx=float(s_b)),
        f"KB2{sa}KAx": vec(KB2=1.0, KAx=-float(s_a)),
        "KA0+KA2": vec(KA0=1.0, KA2=1.0),
        "KB0+KB2": vec(KB0=1.0, KB2=1.0),
    }


def g2_exact(theta, coef: dict, *, delta_a: float = 0.0, s_a: int = 1, s_b: int = 1):
    """Exact g^2 observation at commanded angle ``theta`` for ``phi = theta + delta_a``."""
    ua, ub = meter_outputs(np.asarray(theta, dtype=float) + delta_a, coef, s_a=s_a, s_b=s_b)
    return g2_observation(ua, ub)


def head_error_bias(a1: float, psi1: float, *, s_a: int = 1) -> dict[str, float]:
    """First-order bias of the single-meter A fit from a head error ``a1 sin(theta + psi1)``.

    Spec §1.4: ``dKA2 = -a1 sin psi1``, ``dKA0 = +a1 sin psi1``, ``dKAx = s_A a1 cos psi1``.
    """
    return {"KA0": a1 * np.sin(psi1), "KA2": -a1 * np.sin(psi1),
            "KAx": s_a * a1 * np.cos(psi1)}


def reduce_to_g(v, *, k1_nom_ma_per_g: float, r_load_ohm: float, g_local_mps2: float,
                t_r_c=None, r_alpha_per_c: float = 0.0, r_t0_c: float | None = None):
    """DMM voltage (V) to normalised output in local g (spec §2.3 step 3).

    ``S_nom = K1_nom R_L(T_R) g_local/g_n`` with ``R_L(T) = R_0 (1 + alpha (T - T_R0))``;
    K1_nom is per standard g (mA/g). Returns ``V / S_nom``.
    """
    k1 = units.to_si(float(k1_nom_ma_per_g), "ma_per_g")  # A per standard g
    if not (np.isfinite(k1) and k1 != 0 and np.isfinite(r_load_ohm) and r_load_ohm > 0):
        raise InputError("k1_nom_ma_per_g must be non-zero and r_load_ohm positive")
    r = float(r_load_ohm)
    if r_alpha_per_c:
        if r_t0_c is None or t_r_c is None:
            raise InputError("r_alpha_per_c != 0 needs r_t0_c and the resistor temperature T_R_C")
        r = r * (1.0 + r_alpha_per_c * (np.asarray(t_r_c, dtype=float) - r_t0_c))
    s_nom = k1 * r * g_local_mps2 / units.G_STANDARD
    return np.asarray(v, dtype=float) / s_nom


def average_directions(u_ccw, u_cw):
    """CCW/CW mean and difference per position: ``(mean, ccw - cw)`` (spec §2.3 step 4)."""
    u_ccw = np.asarray(u_ccw, dtype=float)
    u_cw = np.asarray(u_cw, dtype=float)
    return 0.5 * (u_ccw + u_cw), u_ccw - u_cw


def canonical_coef_name(name: str) -> str:
    """The canonical coefficient name of ``name``: a :data:`PAPER_ALIASES` alias
    (``KAip_paper`` -> ``KAx``) or the name itself (names are case-sensitive)."""
    for canon, alias in PAPER_ALIASES.items():
        if name == alias:
            return canon
    return name
