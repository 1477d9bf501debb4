"""Virtual lab rig ``triaxial-poses`` (spec 002 §6): a triaxial MEMS accelerometer (and
optionally a gyro triad) turned through static poses.

Scenarios (spec 002 §6.3, §6.4):

=========================  ==========================================================
``sphere1000-clean``       1000 uniform directions x g, references = truth, no noise
``sphere100-clean``        100 directions, no noise (iteration study)
``sphere1000-noisy``       1000 single samples, sigma_s = 0.04 m/s^2 per axis
``turntable62``            62-position schedule (§2.2), phi = 0, sigma_rec, 0.05 deg
``turntable62-mount``      as above with the mount rotation phi of §6.1
``turntable62-realistic``  mount + 16-bit quantisation + quadratic mismatch (§6.2)
``sixface``                six faces, sigma_rec, 0.5 deg reference error
``rawlog62``               continuous 100 Hz log through the 62 poses (SI, no gyro)
``rawlog62-gyro``          the same with a gyro triad (rad/s)
``rawlog62-counts``        the same in raw 16-bit counts (accelerometer and gyro)
``line5000``               5000 units on the 18-position fixture ``rig18`` (batch file)
=========================  ==========================================================

The device is "MPU6050-A" of §6.1. Static scenarios return a static-record table
(``triaxial_static`` kind: ``pos_id, ax_mps2 ... , n, ref_x/y/z`` with ``pitch_deg,
heading_deg`` or ``face`` where the rig has them, and ``true_*`` columns with the
noise-free sensor output); raw logs return ``t_s, ax_*, ay_*, az_*`` (and ``gx_*``
...) plus a schedule table. Random draws follow the order positions -> noise ->
reference errors (§6.3) from ``default_rng``-style generators made by
:func:`inertialab.seeding.as_generator`.

References
----------
Spec 002 §2.2, §6. TDK InvenSense MPU-6000/6050 Product Specification rev 3.4.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.limits import bounded, bounded_int, check_budget
from inertialab.seeding import as_generator
from inertialab.sensors.triaxial import G_PAPER, forward, k_matrix, rotation

GENERATOR = "inertialab.sim.triaxial_poses"
GENERATOR_VERSION = "1"
KIND = "triaxial-poses"

X_MPU6050_A = np.array([0.25, -0.35, 0.55, 1.021, 0.985, 1.012, 0.012, -0.008, 0.015])
"""True parameters of the reference device (spec 002 §6.1)."""
PHI_MOUNT = np.array([0.003, -0.004, 0.006])
"""Mount rotation on the turntable, rad (spec 002 §6.1)."""
KAPPA = np.array([0.002, -0.0015, 0.0025])
"""Quadratic mismatch of the realistic scenario (spec 002 §6.2)."""
SIGMA_S = 0.04
"""Per-sample white noise, m/s^2 per axis (spec 002 §6.2)."""
N_AVG = 200
"""Samples averaged per static record (2 s at 100 Hz)."""
LSB_PER_G = 16384.0
"""Accelerometer sensitivity, counts per g (±2 g range)."""
GYRO_LSB_PER_DPS = 131.0
"""Gyro sensitivity, counts per deg/s (±250 deg/s range)."""
GYRO_LSB_PER_RPS = GYRO_LSB_PER_DPS * 180.0 / np.pi
GYRO_BIAS = np.array([0.021, -0.015, 0.009])
"""True gyro bias, rad/s (about 1.2, -0.9, 0.5 deg/s)."""
GYRO_T = np.array([[1.018, 0.006, -0.004],
                   [-0.005, 0.986, 0.007],
                   [0.008, -0.003, 1.011]])
"""True gyro gain/misalignment T_g: omega_raw = T_g omega + b_g (M_g = T_g^-1)."""
GYRO_SIGMA = 7e-4
"""Gyro white noise, rad/s per sample (0.005 deg/s/sqrt(Hz) over a 44 Hz DLPF)."""

STATIC_SCENARIOS = ("sphere1000-clean", "sphere100-clean", "sphere1000-noisy", "turntable62",
                    "turntable62-mount", "turntable62-realistic", "sixface")
RAW_SCENARIOS = ("rawlog62", "rawlog62-gyro", "rawlog62-counts")
SCENARIOS = STATIC_SCENARIOS + RAW_SCENARIOS + ("line5000",)

FACE_DIRS = {"+x": (1.0, 0, 0), "-x": (-1.0, 0, 0), "+y": (0, 1.0, 0), "-y": (0, -1.0, 0),
             "+z": (0, 0, 1.0), "-z": (0, 0, -1.0)}


@dataclass(frozen=True)
class SimRecord:
    """A simulated record.

    Attributes
    ----------
    data : DataFrame in the ``triaxial_static`` or ``triaxial_raw`` schema
    meta : sidecar metadata (seed, scenario, g_local_mps2, units ...)
    truth : dict of true parameters (``x``, ``phi``, gyro ``bias``/``T`` ...)
    schedule : DataFrame or None
        Raw logs: ``pos_id, pitch_deg, heading_deg`` in time order, plus the true
        dwell bounds ``t_dwell_start_s, t_dwell_end_s`` (informative).
    kind : record kind (``triaxial_static`` or ``triaxial_raw``)
    """

    data: pd.DataFrame
    meta: dict
    truth: dict
    schedule: pd.DataFrame | None = None
    kind: str = "triaxial_static"
    extra: dict = field(default_factory=dict)


# ------------------------------------------------------------------------- schedules

def turntable_angles(pitches_deg=(0, 30, 60, 90, 120, 150, 180),
                     headings_per_pitch=(1, 8, 14, 16, 14, 8, 1)) -> tuple[np.ndarray, np.ndarray]:
    """The 62-position turntable schedule (spec 002 §2.1): pitch and heading in deg."""
    p, h = [], []
    for pi, n in zip(pitches_deg, headings_per_pitch):
        for j in range(n):
            p.append(float(pi))
            h.append(j * 360.0 / n)
    return np.array(p), np.array(h)


def turntable_direction(pitch_deg, heading_deg) -> np.ndarray:
    """Unit reference r = (sin p cos h, sin p sin h, cos p) (spec 002 §2.2)."""
    p = np.deg2rad(np.asarray(pitch_deg, dtype=float))
    h = np.deg2rad(np.asarray(heading_deg, dtype=float))
    return np.stack([np.sin(p) * np.cos(h), np.sin(p) * np.sin(h), np.cos(p)], axis=-1)


def sphere_directions(n: int, rng) -> np.ndarray:
    """n uniform unit vectors (normalised N(0, I) draws)."""
    d = as_generator(rng).standard_normal((n, 3))
    return d / np.linalg.norm(d, axis=1)[:, None]


def rig18() -> np.ndarray:
    """Fixture schedule ``rig18``: 6 faces plus the 12 edge directions (spec 002 §6.4)."""
    faces = [FACE_DIRS[f] for f in ("+x", "-x", "+y", "-y", "+z", "-z")]
    s = 1.0 / np.sqrt(2.0)
    edges = []
    for i, j in ((0, 1), (0, 2), (1, 2)):
        for si in (1, -1):
            for sj in (1, -1):
                v = [0.0, 0.0, 0.0]
                v[i], v[j] = si * s, sj * s
                edges.append(tuple(v))
    return np.array(faces + edges)


def _perturb(dirs, sigma_rad, rng):
    """Rotate each unit direction by R(psi), psi ~ N(0, sigma^2 I3)."""
    if sigma_rad <= 0:
        return dirs
    psi = rng.standard_normal(dirs.shape) * sigma_rad
    return np.einsum("nij,nj->ni", rotation(psi), dirs)


def _sensor(x, a_true, phi=None, kappa=None, g=G_PAPER):
    out = forward(x, a_true, phi=phi)
    if kappa is not None:
        lin = out - x[:3]
        out = out + np.asarray(kappa) * lin**2 / g
    return out


# ------------------------------------------------------------------------- static

def simulate_static(scenario: str, *, seed=0, g: float = G_PAPER, x_true=None) -> SimRecord:
    """A static-record scenario of spec 002 §6.3 (see the module table)."""
    if scenario not in STATIC_SCENARIOS:
        raise InputError(f"unknown static scenario '{scenario}' (known: {', '.join(STATIC_SCENARIOS)})")
    bounded("g_local", g, 1.0, 100.0)
    rng = as_generator(seed)
    x = X_MPU6050_A.copy() if x_true is None else np.asarray(x_true, dtype=float)
    phi = None
    kappa = None
    quantise = False
    cols: dict = {}
    if scenario.startswith("sphere"):
        n = 100 if scenario == "sphere100-clean" else 1000
        dirs = sphere_directions(n, rng)
        sigma = SIGMA_S if scenario.endswith("noisy") else 0.0
        n_avg, ref_sigma = 1, 0.0
    elif scenario.startswith("turntable62"):
        p, h = turntable_angles()
        dirs = turntable_direction(p, h)
        cols["pitch_deg"], cols["heading_deg"] = p, h
        sigma, n_avg, ref_sigma = SIGMA_S / np.sqrt(N_AVG), N_AVG, np.deg2rad(0.05)
        if scenario != "turntable62":
            phi = PHI_MOUNT.copy()
        if scenario.endswith("realistic"):
            kappa, quantise = KAPPA, True
    else:  # sixface
        faces = ("+x", "-x", "+y", "-y", "+z", "-z")
        dirs = np.array([FACE_DIRS[f] for f in faces])
        cols["face"] = list(faces)
        sigma, n_avg, ref_sigma = SIGMA_S / np.sqrt(N_AVG), N_AVG, np.deg2rad(0.5)
    n = dirs.shape[0]
    noise = rng.standard_normal((n, 3)) * sigma  # noise before reference errors (§6.3)
    actual = _perturb(dirs, ref_sigma, rng)
    clean = _sensor(x, g * actual, phi=phi, kappa=kappa, g=g)
    meas = clean + noise
    if quantise:
        q = g / LSB_PER_G
        meas = np.round(meas / q) * q
    df = pd.DataFrame({"pos_id": np.arange(1, n + 1)})
    for i, ax in enumerate("xyz"):
        df[f"a{ax}_mps2"] = meas[:, i]
    df["n"] = n_avg
    if sigma > 0:
        for ax in "xyz":
            df[f"a{ax}_sd_mps2"] = SIGMA_S
    for i, ax in enumerate("xyz"):
        df[f"ref_{ax}"] = dirs[:, i]
    for k, v in cols.items():
        df[k] = v
    for i, ax in enumerate("xyz"):
        df[f"true_a{ax}_mps2"] = clean[:, i]
    meta = _meta(scenario, seed, g)
    meta["units"] = "mps2"
    truth = {"x": x, "phi": None if phi is None else phi, "kappa": kappa,
             "sigma_rec_mps2": float(sigma), "ref_sigma_rad": float(ref_sigma),
             "directions_actual": actual}
    meta["true_params"] = dict(zip(_PN, x.tolist()))
    if phi is not None:
        meta["true_phi_rad"] = phi.tolist()
    return SimRecord(data=df, meta=meta, truth=truth, kind="triaxial_static")


_PN = ("bx", "by", "bz", "kx", "ky", "kz", "theta_yz", "theta_zy", "theta_zx")


def _meta(scenario, seed, g):
    return {"source": "virtual_lab", "generator": GENERATOR, "generator_version": GENERATOR_VERSION,
            "rig_kind": KIND, "scenario": scenario, "seed": int(seed) if seed is not None else 0,
            "g_local_mps2": float(g), "g_local": float(g), "device": "MPU6050-A"}


# ------------------------------------------------------------------------- raw logs

def attitude(pitch_deg, heading_deg) -> np.ndarray:
    """Body-from-world rotation of a turntable pose: Rz(h)·Ry(p), shape (..., 3, 3).

    Gravity-up (world e_z) in the body is then r = (sin p cos h, sin p sin h, cos p).
    """
    p = np.deg2rad(np.asarray(pitch_deg, dtype=float))
    h = np.deg2rad(np.asarray(heading_deg, dtype=float))
    z = np.zeros_like(p)
    o = np.ones_like(p)
    Ry = np.stack([np.stack([np.cos(p), z, np.sin(p)], -1), np.stack([z, o, z], -1),
                   np.stack([-np.sin(p), z, np.cos(p)], -1)], -2)
    Rz = np.stack([np.stack([np.cos(h), -np.sin(h), z], -1), np.stack([np.sin(h), np.cos(h), z], -1),
                   np.stack([z, z, o], -1)], -2)
    return Rz @ Ry


def _log_so3(R) -> np.ndarray:
    c = np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0)
    th = np.arccos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if th < 1e-9:
        return 0.5 * w
    if np.pi - th < 1e-6:
        # near pi: axis from the symmetric part
        B = (R + np.eye(3)) / 2.0
        ax = B[:, int(np.argmax(np.diag(B)))]
        return th * ax / np.linalg.norm(ax)
    return th / (2.0 * np.sin(th)) * w


def simulate_raw_log(scenario: str = "rawlog62", *, seed=0, g: float = G_PAPER, fs: float = 100.0,
                     first_dwell_s: float = 15.0, dwell_s: float = 5.0, transition_s: float = 3.0,
                     vibration_sigma: float = 0.2, gyro: bool | None = None,
                     counts: bool | None = None, x_true=None) -> SimRecord:
    """A continuous raw log through the 62 turntable poses (spec 002 §6.3 ``rawlog62``).

    The sensor rests ``first_dwell_s`` in position 1 (10 s initial rest + 5 s dwell),
    ``dwell_s`` in every later one, and moves between them in ``transition_s`` along a
    slerp with a raised-cosine time profile (constant body-frame rotation axis), with
    white vibration noise ``vibration_sigma`` on top of sigma_s while moving. With
    ``gyro`` the log has gyro channels ``omega_raw = T_g omega + b_g + noise``
    (omega in the calibrated accelerometer frame); with ``counts`` both are written
    as rounded 16-bit counts (16384 LSB/g, 131 LSB/(deg/s)), with the sensitivities
    in the metadata (``lsb_per_g``, ``gyro_lsb_per_rps``).
    """
    if scenario not in RAW_SCENARIOS:
        raise InputError(f"unknown raw-log scenario '{scenario}' (known: {', '.join(RAW_SCENARIOS)})")
    gyro = scenario != "rawlog62" if gyro is None else bool(gyro)
    counts = scenario == "rawlog62-counts" if counts is None else bool(counts)
    bounded("g_local", g, 1.0, 100.0)
    bounded("rate_hz", fs, 1e-3, 1e5)
    for name, v in (("first_dwell_s", first_dwell_s), ("dwell_s", dwell_s),
                    ("transition_s", transition_s)):
        bounded(name, v, 0.0, 3600.0)
    bounded("vibration_sigma", vibration_sigma, 0.0, 1e3)
    # 62 poses of dwell and transition, about 24 doubles per sample
    check_budget((first_dwell_s + 62 * (dwell_s + transition_s)) * fs * 24 * 8,
                 "a simulated raw log")
    rng = as_generator(seed)
    x = X_MPU6050_A.copy() if x_true is None else np.asarray(x_true, dtype=float)
    p, h = turntable_angles()
    C = attitude(p, h)  # body-from-world per pose
    npos = p.size
    dt = 1.0 / fs
    n_first, n_dwell, n_tr = (int(round(v * fs)) for v in (first_dwell_s, dwell_s, transition_s))
    seg_len = [n_first] + [n_dwell] * (npos - 1)
    total = sum(seg_len) + n_tr * (npos - 1)
    up_body = np.empty((total, 3))
    omega = np.zeros((total, 3))
    moving = np.zeros(total, dtype=bool)
    dwell_bounds = []
    i = 0
    for k in range(npos):
        up = C[k] @ np.array([0.0, 0.0, 1.0])
        up_body[i:i + seg_len[k]] = up
        dwell_bounds.append((i, i + seg_len[k]))
        i += seg_len[k]
        if k == npos - 1:
            break
        # world-from-body R_wb = C^T; R_wb(t) = R_wb_k Exp(s(t) v), v = Log(C_k C_{k+1}^T)
        v = _log_so3(C[k] @ C[k + 1].T)
        tt = (np.arange(n_tr) + 1) / n_tr  # sample instants inside the transition, end excl.
        s = 0.5 * (1.0 - np.cos(np.pi * tt))
        sdot = 0.5 * np.pi / transition_s * np.sin(np.pi * tt)
        R_wb = np.einsum("ij,njk->nik", C[k].T, rotation(s[:, None] * v[None, :]))
        up_body[i:i + n_tr] = R_wb[:, 2, :]  # R_bw e_z = row 2 of R_wb
        omega[i:i + n_tr] = sdot[:, None] * v[None, :]
        moving[i:i + n_tr] = True
        i += n_tr
    t = np.arange(total) * dt
    a_clean = forward(x, g * up_body)
    noise = rng.standard_normal((total, 3)) * SIGMA_S
    vib = rng.standard_normal((total, 3)) * vibration_sigma * moving[:, None]
    acc = a_clean + noise + vib
    df = pd.DataFrame({"t_s": t})
    meta = _meta(scenario, seed, g)
    meta["fs_hz"] = fs
    if counts:
        acc_c = np.round(acc / g * LSB_PER_G)
        for j, ax in enumerate("xyz"):
            df[f"a{ax}_lsb"] = acc_c[:, j]
        meta.update(units="lsb", lsb_per_g=LSB_PER_G, lsb_offset=0)
    else:
        for j, ax in enumerate("xyz"):
            df[f"a{ax}_mps2"] = acc[:, j]
        meta["units"] = "mps2"
    truth = {"x": x, "phi": None, "omega_body_rps": omega, "up_body": up_body,
             "dwell_bounds": np.array(dwell_bounds)}
    if gyro:
        w_raw = omega @ GYRO_T.T + GYRO_BIAS + rng.standard_normal((total, 3)) * GYRO_SIGMA
        if counts:
            w_c = np.round(w_raw * GYRO_LSB_PER_RPS)
            for j, ax in enumerate("xyz"):
                df[f"g{ax}_lsb"] = w_c[:, j]
            meta["gyro_lsb_per_rps"] = GYRO_LSB_PER_RPS
        else:
            for j, ax in enumerate("xyz"):
                df[f"g{ax}_rps"] = w_raw[:, j]
        truth.update(gyro_bias_rps=GYRO_BIAS.copy(), gyro_T=GYRO_T.copy(),
                     gyro_M=np.linalg.inv(GYRO_T))
        meta["true_gyro_bias_rps"] = GYRO_BIAS.tolist()
        meta["true_gyro_T"] = GYRO_T.tolist()
    meta["true_params"] = dict(zip(_PN, x.tolist()))
    sched = pd.DataFrame({"pos_id": np.arange(1, npos + 1), "pitch_deg": p, "heading_deg": h,
                          "t_dwell_start_s": t[[b[0] for b in dwell_bounds]],
                          "t_dwell_end_s": t[[b[1] - 1 for b in dwell_bounds]]})
    return SimRecord(data=df, meta=meta, truth=truth, schedule=sched, kind="triaxial_raw")


# ------------------------------------------------------------------------- line5000

def draw_line_truth(n_units: int, rng) -> np.ndarray:
    """Per-unit truth of ``line5000`` (spec 002 §6.4), truncated normals by clipping: (U, 9)."""
    rng = as_generator(rng)
    X = np.empty((n_units, 9))
    X[:, 0:2] = np.clip(rng.standard_normal((n_units, 2)) * 0.2, -0.49, 0.49)
    X[:, 2] = np.clip(rng.standard_normal(n_units) * 0.3, -0.78, 0.78)
    X[:, 3:6] = np.clip(1.0 + 0.01 * rng.standard_normal((n_units, 3)), 0.97, 1.03)
    X[:, 6:9] = np.clip(0.007 * rng.standard_normal((n_units, 3)), -0.02, 0.02)
    return X


def simulate_line(n_units: int = 5000, *, seed=0, g: float = G_PAPER,
                  ref_sigma_deg: float = 0.1, sigma_rec: float = 0.003) -> SimRecord:
    """Production-line batch ``line5000`` (spec 002 §6.4): one row per unit and position."""
    bounded_int("n_units", n_units, 1, 10_000_000)
    bounded("g_local", g, 1.0, 100.0)
    check_budget(n_units * 62 * 16 * 8, f"a simulated line of {n_units} units")
    rng = as_generator(seed)
    X = draw_line_truth(n_units, rng)
    dirs = rig18()
    m = dirs.shape[0]
    noise = rng.standard_normal((n_units, m, 3)) * sigma_rec
    psi = rng.standard_normal((n_units, m, 3)) * np.deg2rad(ref_sigma_deg)
    actual = np.einsum("umij,mj->umi", rotation(psi), dirs)
    L = X[:, 3:6, None] * k_matrix(X[:, 6:9])
    clean = np.einsum("uij,umj->umi", L, g * actual) + X[:, None, 0:3]
    meas = clean + noise
    uid = np.repeat([f"U{u:05d}" for u in range(n_units)], m)
    df = pd.DataFrame({"unit_id": uid, "pos_id": np.tile(np.arange(1, m + 1), n_units)})
    for j, ax in enumerate("xyz"):
        df[f"a{ax}_mps2"] = meas[:, :, j].ravel()
    df["n"] = N_AVG
    for j, ax in enumerate("xyz"):
        df[f"ref_{ax}"] = np.tile(dirs[:, j], n_units)
    for j, name in enumerate(_PN):
        df[f"true_{name}"] = np.repeat(X[:, j], m)
    meta = _meta("line5000", seed, g)
    meta.update(units="mps2", n_units=int(n_units), fixture="rig18",
                ref_sigma_deg=ref_sigma_deg, sigma_rec_mps2=sigma_rec)
    return SimRecord(data=df, meta=meta, truth={"X": X}, kind="triaxial_static")


def simulate(scenario: str = "turntable62", *, seed=0, g: float = G_PAPER, **options) -> SimRecord:
    """Any scenario of the rig by name (see the module table)."""
    if scenario in STATIC_SCENARIOS:
        return simulate_static(scenario, seed=seed, g=g, **options)
    if scenario in RAW_SCENARIOS:
        return simulate_raw_log(scenario, seed=seed, g=g, **options)
    if scenario == "line5000":
        return simulate_line(seed=seed, g=g, **options)
    raise InputError(f"unknown triaxial-poses scenario '{scenario}' (known: {', '.join(SCENARIOS)})")
