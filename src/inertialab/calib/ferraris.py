"""Ferraris protocol on arrays: six static faces plus one turn about each axis
(Ferraris et al. 1995; the model imucal documents).

Model (raw -> physical)::

    a     = M_a (u_a - b_a)                      M_a = T_a^-1 = R_a^-1 K_a^-1
    omega = M_g (u_g - b_g - K_ga a)             M_g = T_g^-1 = R_g^-1 K_g^-1

with ``u_a``, ``u_g`` the raw outputs, ``a`` in m/s^2, ``omega`` in rad/s, ``K_ga`` the
gyro's g-sensitivity (raw gyro unit per m/s^2).

Estimation:

1. **Sections** (:func:`detect_sections`) from the accelerometer *and* the gyro: a rest
   has a still accelerometer and a gyro at its bias; a turn is a motion during which the
   gravity direction stays put (a rotation about the vertical) and one gyro axis
   dominates. Or given in imucal's section-list format (:func:`sections_from_dict`).
2. **Accelerometer** (12 parameters, T_a and b_a): the six face means through
   :func:`~inertialab.sensors.triaxial_classic.face_fit` (the Ferraris closed form, refined
   so that every hand-placed face has |a| = g).
3. **Gyro bias and g-sensitivity**: least squares ``u_g = b_g + K_ga a_f`` over the six
   faces with their calibrated specific forces ``a_f`` (12 unknowns, 18 equations).
4. **Gyro scale and misalignment** (T_g): each turn's integrated, bias- and g-corrected
   rate is ``W_j = T_g (theta_j n_j)``, where ``n_j`` is the rotation axis in the body
   frame (the vertical: the calibrated accelerometer's mean direction during the turn)
   and ``theta_j = +-rotation_deg`` (the sense detected from the sign of ``W_j . n_j``).
   Three turns give T_g = W N^-1 exactly. Using the measured axis instead of the nominal
   one keeps a face's placement tilt out of the misalignment.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

from inertialab.calib.base import GyroBlock
from inertialab.calib.triaxial import TriaxialCalibration
from inertialab.errors import InputError, UnderdeterminedError
from inertialab.io.modelfile import unique_keys
from inertialab.noise.segments.static_intervals import gyro_rest
from inertialab.sensors import triaxial as tx
from inertialab.sensors.triaxial_classic import PLACEMENT_RAD, FaceFit, face_fit

FACE_SECTIONS = ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a")
ROT_SECTIONS = ("x_rot", "y_rot", "z_rot")
SECTIONS = FACE_SECTIONS + ROT_SECTIONS
"""imucal's section names, in its order."""


# =========================================================================== model

@dataclass
class FerrarisCalibration(TriaxialCalibration):
    """A Ferraris calibration (model-file tag ``"ferraris-calibration"``): the
    accelerometer block of a :class:`~inertialab.calib.triaxial.TriaxialCalibration`
    (``a = correction_matrix @ (raw - offset)``, m/s^2; ``method = "ferraris"``,
    ``objective = "faces"``) and a typed gyro block, a
    :class:`~inertialab.calib.base.GyroBlock` with the g-sensitivity:
    ``omega = M_g (u_g - b_g - K_ga a)`` in rad/s.

    It is a triaxial calibration: applied, exported and accepted wherever one is (a
    model file asked for as ``triaxial-calibration`` may hold it), with the same payload
    keys. Files written before this type existed carry the ``triaxial-calibration`` tag
    and load as a :class:`TriaxialCalibration` with the same numbers.

    Examples
    --------
    The model of a simulated session: at rest on a face it reads gravity and a zero rate
    (the bias and the g-sensitivity taken off):

    >>> import numpy as np
    >>> from inertialab.sim import simulate_ferraris
    >>> session = simulate_ferraris(seed=0)  # six faces and three turns, 102.4 Hz, m/s^2, deg/s
    >>> acc = session.data[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy()
    >>> gyro = session.data[["gx_dps", "gy_dps", "gz_dps"]].to_numpy()
    >>> sections = {k: (v["start"], v["end"]) for k, v in session.truth["sections"].items()}
    >>> model = to_model(fit_ferraris(acc, gyro, 102.4, sections, g=9.81),
    ...                  acc_unit="mps2", gyro_unit="dps", g=9.81)
    >>> model.MODEL_TYPE, model.gyro.method
    ('ferraris-calibration', 'ferraris')
    >>> start, end = sections["x_p"]
    >>> a = model.apply(acc[start:end])
    >>> round(float(np.linalg.norm(a.mean(axis=0))), 3)
    9.81
    >>> bool(np.all(np.abs(model.apply_gyro(gyro[start:end], a).mean(axis=0)) < 1e-4))  # rad/s
    True
    """

    MODEL_TYPE = "ferraris-calibration"
    FORMAT_VERSION = 1
    """Version of the payload layout (the triaxial one; fixture
    ``tests/data/models/ferraris-calibration-v1.json``)."""

    gyro: GyroBlock | None = None

    def __post_init__(self):
        if self.gyro is None:
            raise InputError("a Ferraris calibration needs its gyro block")
        if not isinstance(self.gyro, GyroBlock):
            self.gyro = GyroBlock.from_dict(self.gyro)

    @classmethod
    def from_dict(cls, d: dict) -> FerrarisCalibration:
        if not isinstance(d, dict) or d.get("gyro") is None:
            raise InputError("not a valid ferraris-calibration payload (no gyro block)")
        return super().from_dict(d)


# =========================================================================== sections

def sections_from_dict(d: dict, n: int, *, where="sections") -> dict[str, tuple[int, int]]:
    """imucal's section list ``{"x_p": {"start": i, "end": j}, ...}`` -> ``{name: (i, j)}``
    (sample positions, ``[i, j)``), checked against a record of ``n`` samples."""
    if not isinstance(d, dict):
        raise InputError("a section list must be a JSON object of sections", path=where)
    missing = [s for s in SECTIONS if s not in d]
    if missing:
        raise InputError(f"section list lacks {', '.join(missing)} (needs {', '.join(SECTIONS)})",
                         path=where)
    out = {}
    for s in SECTIONS:
        try:
            i, j = int(d[s]["start"]), int(d[s]["end"])
        except (KeyError, TypeError, ValueError):
            raise InputError(f"section '{s}' needs integer 'start' and 'end'", path=where) from None
        if not 0 <= i < j <= n:
            raise InputError(f"section '{s}' [{i}, {j}) is outside the record's {n} samples "
                             "or empty", path=where)
        out[s] = (i, j)
    return out


def sections_to_dict(sections: dict) -> dict:
    """``{name: (i, j)}`` -> imucal's section-list JSON object."""
    return {k: {"start": int(v[0]), "end": int(v[1])} for k, v in sections.items()}


def load_sections(path, n: int) -> dict[str, tuple[int, int]]:
    """Read an imucal section-list JSON file (see :func:`sections_from_dict`)."""
    try:
        with open(path, encoding="utf-8") as fh:
            d = json.load(fh, object_pairs_hook=unique_keys)
    except FileNotFoundError:
        raise InputError("no such section list", path=path) from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise InputError(f"not a JSON section list ({exc})", path=path) from None
    return sections_from_dict(d, n, where=path)


def _moving_var(x: np.ndarray, w: int) -> np.ndarray:
    """Centred moving variance of each column over ``w`` samples, summed over columns."""
    c1 = np.cumsum(np.vstack([np.zeros((1, x.shape[1])), x]), axis=0)
    c2 = np.cumsum(np.vstack([np.zeros((1, x.shape[1])), x * x]), axis=0)
    n = x.shape[0]
    h = w // 2
    lo = np.clip(np.arange(n) - h, 0, n)
    hi = np.clip(np.arange(n) + h + 1, 0, n)
    cnt = (hi - lo)[:, None]
    m = (c1[hi] - c1[lo]) / cnt
    v = (c2[hi] - c2[lo]) / cnt - m * m
    return np.maximum(v, 0).sum(axis=1)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    d = np.diff(np.r_[0, mask.astype(np.int8), 0])
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


@dataclass(frozen=True)
class Detection:
    """What :func:`detect_sections` found: the sections, every rest and motion, and the
    quantities it decided on (for the figure the user checks)."""

    sections: dict
    rests: list
    motions: list
    rest_mask: np.ndarray
    gyro_rest: np.ndarray
    senses: dict
    acc_var: np.ndarray
    gyro_dev: np.ndarray
    thresholds: dict = field(default_factory=dict)


def detect_sections(acc, gyro, fs: float, *, window_s: float = 0.5, min_rest_s: float = 1.5,
                    trim_s: float = 0.2, k_acc: float = 10.0, k_gyro: float = 8.0,
                    turn_tilt_deg: float = 20.0) -> Detection:
    """Ferraris sections from the accelerometer *and* the gyro.

    A sample is at rest when the accelerometer's moving variance (``window_s``) is below
    ``k_acc`` times its noise floor (the 10th percentile) and the gyro is within ``k_gyro``
    robust standard deviations of its rest value (the median over the accelerometer-still
    samples, refined once): a turn about the vertical keeps the accelerometer still but
    not the gyro. Rests shorter than ``min_rest_s`` are dropped, the others trimmed by
    ``trim_s`` at each end. A rest is a face by its dominant accelerometer axis and sign
    (the longest rest of each face is kept). A motion between two rests is a turn when
    the gravity direction of the two rests differs by less than ``turn_tilt_deg`` and
    its integrated rate has one dominant axis; its sense is the sign of that component.

    Raises
    ------
    InputError
        A face or a turn is missing (the message lists what was found).
    """
    acc = np.asarray(acc, dtype=float)
    gyro = np.asarray(gyro, dtype=float)
    w = max(3, int(round(window_s * fs)) | 1)
    va = _moving_var(acc, w)
    floor = float(np.percentile(va, 10))
    floor = floor if floor > 0 else float(np.finfo(float).tiny)
    still = va < k_acc * floor
    gr = gyro_rest(gyro, still, fs, k_gyro=k_gyro)
    b, dev_s = gr.bias, gr.dev
    rest = still & gr.rest
    trim = int(round(trim_s * fs))
    rests = []
    for i, j in _runs(rest):
        if (j - i) / fs >= min_rest_s and j - i > 2 * trim:
            rests.append((int(i + trim), int(j - trim)))
    if len(rests) < 2:
        raise InputError(f"{len(rests)} rests of at least {min_rest_s:g} s found; a Ferraris "
                         "session needs six faces and three turns between rests")
    means = np.array([acc[i:j].mean(axis=0) for i, j in rests])
    # faces: dominant axis and sign of the (raw) mean
    faces: dict[str, tuple[int, int]] = {}
    mid = (means.max(axis=0) + means.min(axis=0)) / 2  # offset (unsigned counts too)
    for (i, j), m in zip(rests, means - mid):
        k = int(np.argmax(np.abs(m)))
        name = f"{'xyz'[k]}_{'p' if m[k] > 0 else 'a'}"
        if name not in faces or (j - i) > faces[name][1] - faces[name][0]:
            faces[name] = (i, j)
    # turns: motions between consecutive rests with (nearly) the same gravity direction
    motions, turns, senses = [], {}, {}
    cos_lim = np.cos(np.deg2rad(turn_tilt_deg))
    for r0, r1, m0, m1 in zip(rests[:-1], rests[1:], means[:-1], means[1:]):
        i, j = r0[1], r1[0]
        W = (gyro[i:j] - b).sum(axis=0) / fs
        v0, v1 = m0 - mid, m1 - mid
        c = float(v0 @ v1 / (np.linalg.norm(v0) * np.linalg.norm(v1)))
        k = int(np.argmax(np.abs(W)))
        dominant = abs(W[k]) / (np.linalg.norm(W) + 1e-300)
        is_turn = c > cos_lim and dominant > 0.8 and np.linalg.norm(W) > 0
        motions.append({"start": int(i), "end": int(j), "integrated": W.tolist(),
                        "gravity_cos": c, "dominant_axis": "xyz"[k],
                        "dominant_share": float(dominant), "turn": bool(is_turn)})
        if is_turn:
            name = f"{'xyz'[k]}_rot"
            if name not in turns or abs(W[k]) > abs(turns[name][2]):
                turns[name] = (int(i), int(j), float(W[k]))
    missing = [s for s in FACE_SECTIONS if s not in faces] + \
        [s for s in ROT_SECTIONS if s not in turns]
    if missing:
        found = ", ".join(sorted(faces) + sorted(turns)) or "nothing"
        raise InputError(f"Ferraris sections not found: {', '.join(missing)} (found: {found}; "
                         f"{len(rests)} rests, {len(motions)} motions); give the sections "
                         "(argument 'sections', imucal's section list)")
    sections = {s: faces[s] for s in FACE_SECTIONS}
    for s in ROT_SECTIONS:
        i, j, wk = turns[s]
        sections[s] = (i, j)
        senses[s] = 1 if wk > 0 else -1
    return Detection(sections=sections, rests=rests, motions=motions, rest_mask=rest,
                     gyro_rest=b, senses=senses, acc_var=va, gyro_dev=dev_s,
                     thresholds={"acc_var": k_acc * floor, "gyro_dev": gr.threshold})


# =========================================================================== fit

@dataclass(frozen=True)
class FerrarisFit:
    """Result of :func:`fit_ferraris` (raw units ``u_a``, ``u_g``; see module docstring).

    Attributes
    ----------
    faces : FaceFit
        The accelerometer: ``T`` (T_a, raw per m/s^2), ``b`` (b_a), ``M`` = inv(T_a).
    T_g : ndarray (3, 3)
        Gyro gain/misalignment, raw gyro unit per rad/s.
    M_g : ndarray (3, 3)
        inv(T_g): rad/s per raw gyro unit.
    b_g : ndarray (3,)
        Gyro bias, raw unit.
    K_ga : ndarray (3, 3)
        g-sensitivity, raw gyro unit per m/s^2.
    face_acc : ndarray (6, 3)
        Calibrated specific force of each face, m/s^2.
    turn_axes : ndarray (3, 3)
        Unit rotation axes of x_rot, y_rot, z_rot in the body frame (rows).
    senses : ndarray (3,)
        +1 counterclockwise seen from above, -1 clockwise.
    integrated : ndarray (3, 3)
        Integrated corrected raw rate of each turn (rows), raw unit x s.
    gyro_static_rms : float
        RMS of the static gyro residuals ``u_g - b_g - K_ga a_f``, raw unit.
    sections : dict
    cov_gyro_static : ndarray (12, 12) or None
        Covariance of ``(b_g, K_ga.ravel())``.
    """

    faces: FaceFit
    T_g: np.ndarray
    M_g: np.ndarray
    b_g: np.ndarray
    K_ga: np.ndarray
    face_acc: np.ndarray
    turn_axes: np.ndarray
    senses: np.ndarray
    integrated: np.ndarray
    gyro_static_rms: float
    sections: dict
    rotation_deg: float
    cov_gyro_static: np.ndarray | None = None


def fit_ferraris(acc, gyro, fs: float, sections: dict, *, g: float, rotation_deg: float = 360.0,
                 refine: bool = True, placement_rad: float = PLACEMENT_RAD,
                 g_sensitivity: bool = True) -> FerrarisFit:
    """Calibrate accelerometer and gyro from a Ferraris session (see module docstring).

    Parameters
    ----------
    acc, gyro : arrays (n, 3)
        Raw samples (any unit; the model maps them to m/s^2 and rad/s).
    fs : float
        Sample rate, Hz (integration step 1/fs).
    sections : dict
        ``{name: (start, end)}`` for the nine sections (:data:`SECTIONS`).
    g : float
        Local gravity, m/s^2.
    rotation_deg : float, default 360
        Magnitude of every turn, deg (the sense is detected).
    refine, placement_rad
        Accelerometer face fit (:func:`~inertialab.sensors.triaxial_classic.face_fit`).
    g_sensitivity : bool, default True
        Estimate K_ga (else zero; the bias is then the mean of the six faces).

    Examples
    --------
    A simulated session with known gyro bias and g-sensitivity; both come back within
    their noise:

    >>> import numpy as np
    >>> from inertialab.sim import simulate_ferraris
    >>> session = simulate_ferraris(seed=0)  # six faces and three turns, 102.4 Hz, m/s^2, deg/s
    >>> acc = session.data[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy()
    >>> gyro = session.data[["gx_dps", "gy_dps", "gz_dps"]].to_numpy()
    >>> sections = {k: (v["start"], v["end"]) for k, v in session.truth["sections"].items()}
    >>> fit = fit_ferraris(acc, gyro, 102.4, sections, g=9.81)
    >>> bool(np.allclose(fit.b_g, session.truth["b_g_dps"], atol=0.005))
    True
    >>> bool(np.allclose(fit.K_ga, session.truth["K_ga_dps"], atol=0.002))
    True
    """
    acc = np.asarray(acc, dtype=float)
    gyro = np.asarray(gyro, dtype=float)
    if acc.shape != gyro.shape or acc.ndim != 2 or acc.shape[1] != 3:
        raise InputError(f"accelerometer and gyro need shape (n, 3) each, got {acc.shape} and "
                         f"{gyro.shape}")
    if not fs > 0:
        raise InputError(f"argument 'fs' must be a positive sample rate, got {fs}")
    U = np.array([acc[slice(*sections[s])].mean(axis=0) for s in FACE_SECTIONS])
    G = np.array([gyro[slice(*sections[s])].mean(axis=0) for s in FACE_SECTIONS])
    ff = face_fit(U, g=g, placement_rad=placement_rad, refine=refine)
    A = (U - ff.b) @ ff.M.T  # calibrated specific force per face
    if g_sensitivity:
        D = np.column_stack([np.ones(6), A])
        sol, *_ = np.linalg.lstsq(D, G, rcond=None)
        b_g, K_ga = sol[0], sol[1:].T
        r = G - D @ sol
        dof = max(6 - 4, 1)
        s2 = np.sum(r * r, axis=0) / dof
        try:
            XtXi = np.linalg.inv(D.T @ D)
            cov = np.zeros((12, 12))
            # parameters ordered (b_g (3), K_ga row-major (9)); rows of K_ga are axes
            for ax in range(3):
                idx = [ax] + [3 + 3 * ax + c for c in range(3)]
                cov[np.ix_(idx, idx)] = s2[ax] * XtXi
        except np.linalg.LinAlgError:
            cov = None
    else:
        b_g, K_ga = G.mean(axis=0), np.zeros((3, 3))
        r = G - b_g
        cov = None
    rms = float(np.sqrt(np.mean(r * r)))
    W = np.zeros((3, 3))
    axes = np.zeros((3, 3))
    senses = np.zeros(3)
    theta = np.deg2rad(rotation_deg)
    for j, s in enumerate(ROT_SECTIONS):
        i0, i1 = sections[s]
        a_t = (acc[i0:i1] - ff.b) @ ff.M.T
        corr = gyro[i0:i1] - b_g - a_t @ K_ga.T
        W[j] = corr.sum(axis=0) / fs
        n_j = a_t.mean(axis=0)
        nn = np.linalg.norm(n_j)
        if nn < 0.5 * g:
            raise InputError(f"turn '{s}': the mean specific force is {nn:.3g} m/s^2, not "
                             "gravity; the section is not a turn about the vertical")
        n_j = n_j / nn
        axes[j] = n_j
        senses[j] = 1.0 if W[j] @ n_j > 0 else -1.0
    N = (senses * theta)[None, :] * axes.T  # columns theta_j n_j
    if abs(np.linalg.det(axes)) < 0.2:
        raise UnderdeterminedError("the three turns are not about three independent axes "
                                   f"(det of their axes {np.linalg.det(axes):.3g}); turn about "
                                   "x, y and z")
    T_g = W.T @ np.linalg.inv(N)
    M_g = np.linalg.inv(T_g)
    return FerrarisFit(faces=ff, T_g=T_g, M_g=M_g, b_g=np.asarray(b_g, dtype=float),
                       K_ga=np.asarray(K_ga, dtype=float), face_acc=A, turn_axes=axes,
                       senses=senses, integrated=W, gyro_static_rms=rms,
                       sections=dict(sections), rotation_deg=float(rotation_deg),
                       cov_gyro_static=cov)


def to_model(fit: FerrarisFit, *, acc_unit: str, gyro_unit: str, g: float,
             n_samples: int | None = None) -> FerrarisCalibration:
    """The Ferraris fit as a :class:`FerrarisCalibration` (``method = "ferraris"``):
    ``correction_matrix = M_a``, ``offset = b_a``; the gyro block, a typed
    :class:`~inertialab.calib.base.GyroBlock`, carries ``M_g``, ``b_g`` and
    ``g_sensitivity`` = K_ga, the turns' senses and axes, so that ``apply_gyro(raw, acc)``
    gives ``M_g (raw - b_g - K_ga acc)``."""
    ff = fit.faces
    stderr = dict.fromkeys(tx.PARAM_NAMES)
    if ff.cov is not None:
        # standard errors of (b, k, theta) from the covariance of (M, b) by a numerical
        # Jacobian of the LQ reduction
        p0 = np.r_[ff.M.ravel(), ff.b]

        def reduce(p):
            M, b = p[:9].reshape(3, 3), p[9:]
            return np.r_[b, tx.lq_to_params(np.linalg.inv(M)).x_tail]

        J = np.zeros((9, 12))
        for c in range(12):
            h = 1e-7 * max(1.0, abs(p0[c]))
            dp = np.zeros(12)
            dp[c] = h
            J[:, c] = (reduce(p0 + dp) - reduce(p0 - dp)) / (2 * h)
        cv = J @ ff.cov @ J.T
        stderr = {n: float(np.sqrt(max(cv[i, i], 0.0))) for i, n in enumerate(tx.PARAM_NAMES)}
    gyro = GyroBlock(
        method="ferraris", raw_unit=gyro_unit, correction_matrix=fit.M_g, offset=fit.b_g,
        g_sensitivity=fit.K_ga,
        params={"bgx": float(fit.b_g[0]), "bgy": float(fit.b_g[1]), "bgz": float(fit.b_g[2]),
                **{f"m{i + 1}{j + 1}": float(fit.M_g[i, j]) for i in range(3)
                   for j in range(3)},
                **{f"kga{i + 1}{j + 1}": float(fit.K_ga[i, j]) for i in range(3)
                   for j in range(3)}},
        residual_rms=fit.gyro_static_rms, n_records=6, static_intervals=6,
        extra={"turns": {s: {"sense": int(fit.senses[j]), "axis": fit.turn_axes[j].tolist()}
                         for j, s in enumerate(ROT_SECTIONS)},
               "rotation_deg": fit.rotation_deg})
    return FerrarisCalibration(
        method="ferraris", objective="faces", params=dict(zip(tx.PARAM_NAMES, ff.x.tolist())),
        correction_matrix=ff.M, offset=ff.b, raw_unit=acc_unit, g_local=float(g),
        stderr=stderr, phi=None,
        residual_rms=float(np.sqrt(np.mean(ff.norm_residual ** 2))), iterations=0, nfev=0,
        n_records=6, static_intervals=None if n_samples is None else 6, gyro=gyro)


# =========================================================================== checks

def check_ferraris(fit: FerrarisFit, *, acc_nominal: float | None, gyro_nominal: float | None,
                   g: float, limits=None) -> list:
    """Plausibility of a Ferraris fit (bounds of
    :mod:`inertialab.calib.triaxial_checks`).

    ``acc_nominal``/``gyro_nominal`` are the nominal raw units per m/s^2 and per rad/s
    (None for counts without a sensitivity: each axis then relative to the median axis).
    Checks: scales (row norms of T) within 0.5-2 of nominal, misalignments (off-diagonal
    of R = K^-1 T) within 0.2 rad, biases (accelerometer in m/s^2, gyro in rad/s) within
    their limits, |a| on every face within the norm tolerance. (Each turn's angle recomputed with the fitted model equals the stated one by
    construction, three turns for nine unknowns, so it is no check.)
    """
    from inertialab.calib.triaxial_checks import (
        BIAS_LIMIT_G,
        GYRO_BIAS_LIMIT,
        NORM_TOL_G,
        Finding,
        Limits,
    )

    lim = limits or Limits()
    out = []
    lo, hi = lim.scale
    for what, T, nominal, b, blim, unit in (
            ("accelerometer", fit.faces.T, acc_nominal, fit.faces.M @ fit.faces.b,
             lim.bias if lim.bias is not None else BIAS_LIMIT_G * g, "m/s^2"),
            ("gyro", fit.T_g, gyro_nominal, fit.M_g @ fit.b_g,
             lim.gyro_bias if lim.gyro_bias is not None else GYRO_BIAS_LIMIT, "rad/s")):
        k = np.linalg.norm(T, axis=1)
        rel = k / (nominal if nominal is not None else float(np.median(k)))
        pre = "K_a" if what == "accelerometer" else "K_g"
        bad = [f"{pre}{i + 1}{i + 1}" for i in range(3) if not lo <= rel[i] <= hi]
        if bad:
            out.append(Finding("implausible", tuple(bad), f"{what} scale relative to nominal "
                               + ", ".join(f"{r:.4g}" for r in rel) + f" outside {lo:g}-{hi:g}",
                               f"check the {what} unit"))
        R = T / k[:, None]
        off = R - np.diag(np.diag(R))
        pre = "R_a" if what == "accelerometer" else "R_g"
        bad = [f"{pre}{i + 1}{j + 1}" for i in range(3) for j in range(3)
               if i != j and abs(off[i, j]) > lim.angle]
        if bad:
            out.append(Finding("implausible", tuple(bad), f"{what} misalignment beyond "
                               f"{lim.angle:g} rad", "check the section labels and turn axes"))
        if nominal is not None or what == "gyro":
            # counts without a sensitivity: the accelerometer offset is no bias
            badb = [f"b_{'a' if what == 'accelerometer' else 'g'}{'xyz'[i]}" for i in range(3)
                    if abs(b[i]) > blim]
            if badb:
                out.append(Finding("implausible", tuple(badb), f"{what} bias "
                                   + ", ".join(f"{v:.4g}" for v in b) + f" {unit} beyond "
                                   f"±{blim:.3g}", "start at rest; check the unit"))
    tol = lim.norm_tol if lim.norm_tol is not None else NORM_TOL_G * g
    err = np.abs(fit.faces.norm_residual)
    if np.max(err) > tol:
        out.append(Finding("implausible", ("|a|",), f"faces off gravity by up to "
                           f"{np.max(err):.3g} m/s^2", "check that each face section is a rest"))
    return out
