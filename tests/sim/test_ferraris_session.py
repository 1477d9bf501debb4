"""sim.ferraris_session: the virtual Ferraris session."""

import numpy as np

from inertialab.sim.ferraris_session import SECTION_NAMES, simulate_ferraris


def test_session_layout_and_physics():
    rec = simulate_ferraris(seed=1, placement_deg=0.0, angle_sigma_deg=0.0, shake_mps2=0.0)
    d, tr = rec.data, rec.truth
    assert list(tr["sections"]) == list(SECTION_NAMES)
    acc = d[["ax_mps2", "ay_mps2", "az_mps2"]].to_numpy()
    gyr = d[["gx_dps", "gy_dps", "gz_dps"]].to_numpy()
    # a face at rest reads T_a (g e) + b_a; with a perfect hand e is the nominal axis
    i, j = tr["sections"]["y_a"]["start"], tr["sections"]["y_a"]["end"]
    want = tr["T_a"] @ np.array([0.0, -9.81, 0.0]) + tr["b_a"]
    assert np.allclose(acc[i:j].mean(axis=0), want, atol=0.01)
    # a turn integrates to T_g (theta n) + K_ga a + b_g over its samples
    i, j = tr["sections"]["z_rot"]["start"], tr["sections"]["z_rot"]["end"]
    W = (gyr[i:j] - tr["b_g_dps"] - 9.81 * tr["K_ga_dps"][:, 2]).sum(axis=0) / 102.4
    theta = np.rad2deg(tr["angles_rad"][2])
    assert abs(theta) == 360.0
    assert np.allclose(W, tr["T_g_dps"] @ np.array([0.0, 0.0, theta]), atol=0.5)


def test_counts_and_reproducibility():
    a = simulate_ferraris(seed=4, counts=True)
    b = simulate_ferraris(seed=4, counts=True)
    assert a.data.equals(b.data)
    assert {"ax_lsb", "gz_lsb"} <= set(a.data.columns)
    assert np.all(a.data["az_lsb"] == np.round(a.data["az_lsb"]))
