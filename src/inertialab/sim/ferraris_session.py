"""Virtual lab rig ``ferraris-session``: a 6-DOF IMU calibrated by hand with the Ferraris
protocol (Ferraris et al. 1995, as imucal records it).

The session, in time order: an initial rest, the six static faces ``x_p x_a y_p y_a z_p
z_a`` (sensor axis up / down), then one full turn about each axis ``x_rot y_rot z_rot``
(the sensor placed on the ``*_p`` face and turned about the vertical), each followed by a
rest. The hand is imperfect:

- every face is tilted from its nominal attitude by a random rotation with a
  ``placement_deg`` standard deviation per axis (and a random heading);
- every turn is ``360 deg + N(0, angle_sigma_deg)`` in a random sense (or ``senses``);
- moving the sensor shakes it (white acceleration ``shake_mps2`` while moving).

Sensor model (imucal's documented form): ``u_a = T_a a + b_a`` with ``T_a = K_a R_a``,
``u_g = T_g omega + K_ga a + b_g``, where ``a`` is the specific force and ``omega`` the
rate, both in the housing frame, plus white noise. The default device is the MPU6050-A of
spec 002 §6.1 (accelerometer), its gyro triad of the ``triaxial-poses`` rig, and a
g-sensitivity of ~0.1 deg/s/g. Units: acceleration m/s^2 and rate deg/s (as the real
session of the public MPU-6050 Ferraris recording: 102.4 Hz, m/s^2, deg/s), or 16-bit counts.

The truth holds the true matrices and the true sections in imucal's section-list format.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from inertialab.limits import bounded, check_budget
from inertialab.seeding import as_generator
from inertialab.sensors.triaxial import gain_matrix, rotation
from inertialab.sim.triaxial_poses import (
    GYRO_BIAS,
    GYRO_T,
    LSB_PER_G,
    SIGMA_S,
    X_MPU6050_A,
    SimRecord,
    _log_so3,
)

GENERATOR = "inertialab.sim.ferraris_session"
GENERATOR_VERSION = "1"
KIND = "ferraris-session"

FS_HZ = 102.4
"""Sample rate of the real Ferraris session (MPU-6050 recording), Hz."""
G_LOCAL = 9.81
K_GA_DPS_PER_MPS2 = np.array([[0.004, -0.010, 0.012],
                              [0.009, 0.003, -0.006],
                              [-0.006, 0.005, -0.002]])
"""True g-sensitivity K_ga, deg/s per m/s^2 (~0.1 deg/s/g, a MEMS gyro's order)."""
GYRO_SIGMA_DPS = 0.04
"""Gyro white noise per sample, deg/s."""
GYRO_LSB_PER_DPS = 131.0
PHI_HOUSING = np.array([0.004, -0.006, 0.003])
"""Rotation of the accelerometer's axes in the housing, rad (absorbed by R_a)."""

SECTION_NAMES = ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a", "x_rot", "y_rot", "z_rot")
"""Sections of a Ferraris session (imucal's names)."""
_UP = {"x_p": (1.0, 0, 0), "x_a": (-1.0, 0, 0), "y_p": (0, 1.0, 0), "y_a": (0, -1.0, 0),
       "z_p": (0, 0, 1.0), "z_a": (0, 0, -1.0)}


def face_attitude(up_body, heading: float = 0.0) -> np.ndarray:
    """World-from-body rotation with body vector ``up_body`` pointing up (world +z) and the
    given heading (rad) about the vertical."""
    u = np.asarray(up_body, dtype=float)
    u = u / np.linalg.norm(u)
    helper = np.array([0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    r0 = np.cross(helper, u)
    r0 /= np.linalg.norm(r0)
    r1 = np.cross(u, r0)
    R_wb = np.vstack([r0, r1, u])  # rows: world axes in the body frame
    c, s = np.cos(heading), np.sin(heading)
    Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return Rz @ R_wb


def _check_session(fs, g, placement_deg, angle_sigma_deg, rest_s, first_rest_s, move_s,
                   turn_s, shake_mps2) -> None:
    """The session's arguments within bounds and its length within the memory budget."""
    bounded("g_local", g, 1.0, 100.0)
    bounded("placement_deg", placement_deg, 0.0, 45.0)
    bounded("angle_sigma_deg", angle_sigma_deg, 0.0, 90.0)
    bounded("rate_hz", fs, 1e-3, 1e5)
    for name, v in (("rest_s", rest_s), ("first_rest_s", first_rest_s), ("move_s", move_s),
                    ("turn_s", turn_s)):
        bounded(name, v, 0.0, 3600.0)
    bounded("shake_mps2", shake_mps2, 0.0, 1e3)
    # six rests and three turns with the moves between them, about 20 doubles per sample
    seconds = first_rest_s + 6 * rest_s + 3 * turn_s + 9 * move_s
    check_budget(seconds * fs * 20 * 8, f"a simulated Ferraris session of {seconds:g} s at "
                 f"{fs:g} Hz")


def _hand(rng, placement_deg: float, angle_sigma_deg: float, senses):
    """The hand's draws, in order: each face's tilt and heading, each turn's start tilt and
    heading, the turn-angle errors and (when not given) the senses. Returns the
    world-from-body attitudes of the faces and of the turns' starts, the senses and the
    signed turn angles (rad)."""
    sig = np.deg2rad(placement_deg)
    atts = {}
    for name in ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a"):
        tilt = rng.standard_normal(3) * sig
        atts[name] = rotation(tilt) @ face_attitude(_UP[name], rng.uniform(0, 2 * np.pi))
    turn_att = {}
    for ax in "xyz":
        tilt = rng.standard_normal(3) * sig
        turn_att[ax] = rotation(tilt) @ face_attitude(_UP[f"{ax}_p"], rng.uniform(0, 2 * np.pi))
    ang_err = rng.standard_normal(3) * np.deg2rad(angle_sigma_deg)
    if senses is None:
        senses = np.where(rng.uniform(size=3) < 0.5, -1.0, 1.0)
    senses = np.asarray(senses, dtype=float)
    return atts, turn_att, senses, senses * (2 * np.pi + ang_err)


class _Timeline:
    """World-from-body attitudes, body rates (rad/s) and a moving flag, sample by sample,
    built from holds, smooth moves and turns about the vertical at rate ``fs`` (Hz)."""

    def __init__(self, fs: float):
        self.fs = fs
        self.R, self.w, self.moving = [], [], []
        self.cursor = 0

    def _ramp(self, n: int):
        """Raised-cosine progress 0 -> 1 over ``n`` samples and its time derivative (1/s)."""
        tt = (np.arange(n) + 1) / n
        return 0.5 * (1.0 - np.cos(np.pi * tt)), 0.5 * np.pi / (n / self.fs) * np.sin(np.pi * tt)

    def _add(self, R, w, moving: bool, n: int):
        self.R.append(R)
        self.w.append(w)
        self.moving.append(np.full(n, moving, dtype=bool))
        self.cursor += n

    def hold(self, R, n: int):
        self._add(np.repeat(R[None], n, axis=0), np.zeros((n, 3)), False, n)

    def move(self, R0, R1, n: int):
        v = _log_so3(R0.T @ R1)  # body-frame axis: R(s) = R0 Exp(s v)
        s, sdot = self._ramp(n)
        self._add(np.einsum("ij,njk->nik", R0, rotation(s[:, None] * v[None, :])),
                  sdot[:, None] * v[None, :], True, n)

    def turn(self, R0, angle: float, n: int):
        """Turn by ``angle`` (rad) about the world vertical; returns the final attitude."""
        s, sdot = self._ramp(n)
        psi = s * angle
        c, sn = np.cos(psi), np.sin(psi)
        Rz = np.zeros((n, 3, 3))
        Rz[:, 0, 0], Rz[:, 0, 1], Rz[:, 1, 0], Rz[:, 1, 1], Rz[:, 2, 2] = c, -sn, sn, c, 1.0
        up_body = R0.T @ np.array([0.0, 0.0, 1.0])
        self._add(Rz @ R0, (sdot * angle)[:, None] * up_body[None, :], True, n)
        return self.R[-1][-1]


def _session_timeline(atts, turn_att, angles, fs: float, rest_s: float, first_rest_s: float,
                      move_s: float, turn_s: float):
    """The session: a first rest, the six faces (moves between rests), then for each axis
    a move, a half rest, the turn and a half rest. Returns the attitudes (n, 3, 3), the
    body rates (n, 3, rad/s), the moving flag (n,) and the sections
    (``{name: {"start", "end"}}``, sample indices)."""
    n_rest, n_first, n_move, n_turn = (int(round(v * fs)) for v in (rest_s, first_rest_s,
                                                                     move_s, turn_s))
    tl = _Timeline(fs)
    sections: dict[str, dict] = {}
    R_prev = atts["x_p"]
    tl.hold(R_prev, n_first)
    for name in ("x_p", "x_a", "y_p", "y_a", "z_p", "z_a"):
        if name != "x_p":
            tl.move(R_prev, atts[name], n_move)
        start = tl.cursor
        tl.hold(atts[name], n_rest)
        sections[name] = {"start": start, "end": tl.cursor}
        R_prev = atts[name]
    for j, ax in enumerate("xyz"):
        tl.move(R_prev, turn_att[ax], n_move)
        tl.hold(turn_att[ax], n_rest // 2)
        start = tl.cursor
        R_end = tl.turn(turn_att[ax], angles[j], n_turn)
        sections[f"{ax}_rot"] = {"start": start, "end": tl.cursor}
        tl.hold(R_end, n_rest // 2)
        R_prev = R_end
    return (np.concatenate(tl.R), np.concatenate(tl.w), np.concatenate(tl.moving),
            sections)


def _columns(df: pd.DataFrame, acc, gyr, *, counts: bool, g: float) -> str:
    """Add the accelerometer and gyro columns to ``df`` (16-bit counts, or m/s^2 and
    deg/s); returns the ``units`` entry of the sidecar."""
    if counts:
        for j, c in enumerate("xyz"):
            df[f"a{c}_lsb"] = np.round(acc[:, j] / g * LSB_PER_G)
        for j, c in enumerate("xyz"):
            df[f"g{c}_lsb"] = np.round(gyr[:, j] * GYRO_LSB_PER_DPS)
        return "lsb"
    for j, c in enumerate("xyz"):
        df[f"a{c}_mps2"] = acc[:, j]
    for j, c in enumerate("xyz"):
        df[f"g{c}_dps"] = gyr[:, j]
    return "mps2"


def simulate_ferraris(*, seed=0, fs: float = FS_HZ, g: float = G_LOCAL,
                      placement_deg: float = 2.0, angle_sigma_deg: float = 1.0,
                      senses=None, rest_s: float = 6.0, first_rest_s: float = 5.0,
                      move_s: float = 3.0, turn_s: float = 8.0, shake_mps2: float = 0.3,
                      counts: bool = False, x_true=None, k_ga_dps=None) -> SimRecord:
    """Simulate one Ferraris calibration session (see the module docstring).

    Parameters
    ----------
    seed : int
        Draw order: face tilts and headings, turn angles and senses, noise.
    fs : float, default 102.4 (Hz)
    placement_deg : float, default 2
        Standard deviation of a face's tilt per axis, deg.
    angle_sigma_deg : float, default 1
        Standard deviation of a turn's angle around 360 deg.
    senses : sequence of three +-1, optional
        Turning sense of x_rot, y_rot, z_rot (+1 counterclockwise from above); default random.
    counts : bool
        Write 16-bit counts (16384 LSB/g, 131 LSB/(deg/s)) instead of m/s^2 and deg/s.

    Examples
    --------
    >>> import numpy as np
    >>> session = simulate_ferraris(seed=0)
    >>> session.kind, session.meta["fs_hz"], list(session.data.columns)[:4]
    ('triaxial_raw', 102.4, ['t_s', 'ax_mps2', 'ay_mps2', 'az_mps2'])
    >>> sorted(session.truth["sections"])[:3]
    ['x_a', 'x_p', 'x_rot']
    >>> face = session.truth["sections"]["z_p"]
    >>> raw = session.data[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy()
    >>> acc = raw[face["start"]:face["end"]].mean(axis=0)
    >>> true = np.linalg.solve(session.truth["T_a"], acc - session.truth["b_a"])
    >>> round(float(np.linalg.norm(true)), 2)  # at rest the true specific force is g
    9.81
    """
    _check_session(fs, g, placement_deg, angle_sigma_deg, rest_s, first_rest_s, move_s, turn_s,
                   shake_mps2)
    rng = as_generator(seed)
    x = X_MPU6050_A.copy() if x_true is None else np.asarray(x_true, dtype=float)
    T_a = gain_matrix(x) @ rotation(PHI_HOUSING)
    b_a = x[:3]
    T_g = GYRO_T.copy()  # raw rate per true rate (deg/s per deg/s)
    b_g = np.rad2deg(GYRO_BIAS)
    K_ga = K_GA_DPS_PER_MPS2 if k_ga_dps is None else np.asarray(k_ga_dps, dtype=float)
    atts, turn_att, senses, angles = _hand(rng, placement_deg, angle_sigma_deg, senses)
    R_wb, w_body, moving, sections = _session_timeline(atts, turn_att, angles, fs, rest_s,
                                                       first_rest_s, move_s, turn_s)
    n = R_wb.shape[0]
    t = np.arange(n) / fs
    f_body = g * R_wb[:, 2, :]  # specific force at rest: +g along the body's up
    f_body = f_body + rng.standard_normal((n, 3)) * shake_mps2 * moving[:, None]
    acc = f_body @ T_a.T + b_a + rng.standard_normal((n, 3)) * SIGMA_S
    w_dps = np.rad2deg(w_body)
    gyr = w_dps @ T_g.T + f_body @ K_ga.T + b_g + rng.standard_normal((n, 3)) * GYRO_SIGMA_DPS
    df = pd.DataFrame({"t_s": t})
    meta = {"generator": GENERATOR, "generator_version": GENERATOR_VERSION, "rig": KIND,
            "seed": seed if isinstance(seed, (int, np.integer)) else None,
            "g_local_mps2": g, "fs_hz": fs}
    meta.update(units=_columns(df, acc, gyr, counts=counts, g=g))
    truth = {"T_a": T_a, "b_a": b_a, "T_g_dps": T_g, "b_g_dps": b_g, "K_ga_dps": K_ga,
             "angles_rad": angles, "senses": senses, "sections": sections,
             "face_up_body": {k: v.T @ np.array([0.0, 0.0, 1.0]) for k, v in atts.items()},
             "turn_axis_body": {ax: v.T @ np.array([0.0, 0.0, 1.0]) for ax, v in turn_att.items()},
             "x": x, "counts": counts}
    return SimRecord(data=df, meta=meta, truth=truth, schedule=None, kind="triaxial_raw")
