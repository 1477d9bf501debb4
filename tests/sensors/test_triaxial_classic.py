"""Six-position method and ellipsoid initialiser (spec 002 §3.7, §3.8, §7.1 items 6, 10)."""

import numpy as np
import pytest

from inertialab.errors import InputError, UnderdeterminedError
from inertialab.regress.nlls import levenberg_marquardt
from inertialab.sensors import triaxial as tx
from inertialab.sensors.triaxial_classic import ellipsoid_fit, six_position

X_TRUE = np.array([0.25, -0.35, 0.55, 1.021, 0.985, 1.012, 0.012, -0.008, 0.015])
FACES = 9.8 * np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1.0]])


def test_twelve_parameter_form_is_exact():
    # §7.1 item 6: noise-free six faces, phi = 0 -> exact to 1e-12 (closed-form linear algebra)
    res = six_position(tx.forward(X_TRUE, FACES), g=9.8, form=12)
    assert np.max(np.abs(res.x - X_TRUE)) < 1e-12
    assert np.allclose(res.rotation, np.eye(3), atol=1e-12)


def test_six_parameter_form_recovers_b_k_and_zero_theta():
    # §7.1 item 6: K has a unit diagonal, so the diagonal reading gives b, k exactly; theta = 0
    res = six_position(tx.forward(X_TRUE, FACES), g=9.8, form=6)
    assert np.max(np.abs(res.x[:6] - X_TRUE[:6])) < 1e-12
    assert np.all(res.x[6:] == 0)
    assert np.allclose(res.x[6:] - X_TRUE[6:], -X_TRUE[6:])


def test_six_position_needs_six_faces():
    with pytest.raises(UnderdeterminedError):
        six_position(np.zeros((5, 3)))


def test_ellipsoid_fit_exact_on_clean_sphere():
    d = np.random.default_rng(0).standard_normal((50, 3))
    r = 9.8 * d / np.linalg.norm(d, axis=1)[:, None]
    fit = ellipsoid_fit(tx.forward(X_TRUE, r), g=9.8)
    assert fit.success
    # exact algebra on noise-free data; 1e-10 allows SVD round-off amplified by normalisation
    assert np.max(np.abs(fit.x - X_TRUE)) < 1e-10


def test_ellipsoid_fit_fails_softly_and_strictly():
    a = np.random.default_rng(1).standard_normal((6, 3))
    assert not ellipsoid_fit(a).success
    with pytest.raises(InputError, match="ellipsoid"):
        ellipsoid_fit(a, strict=True)


def counts_device(seed):
    rng = np.random.default_rng(seed)
    k = 640.0 * (1 + rng.uniform(-0.03, 0.03, 3))
    b = 32768 + rng.uniform(-200, 200, 3)
    th = rng.uniform(-0.02, 0.02, 3)
    x = np.r_[b, k, th]
    d = rng.standard_normal((38, 3))
    r = 9.80665 * d / np.linalg.norm(d, axis=1)[:, None]
    a = tx.forward(x, r) + 2.0 * rng.standard_normal((38, 3))
    return x, a


@pytest.mark.parametrize("seed", range(5))
def test_counts_mode_ellipsoid_then_lm_norm(seed):
    # §7.1 item 10: k within 1e-3 relative and theta within 1.5e-3 rad (prototype worst 4.7e-4, 6.7e-4)
    x, a = counts_device(seed)
    x_e = ellipsoid_fit(a, g=9.80665, strict=True).x
    res = levenberg_marquardt(lambda p: tx.residuals(p, a, objective="norm", g=9.80665), x_e,
                              jac=lambda p: tx.jacobian(p, a, objective="norm", g=9.80665))
    assert np.max(np.abs(res.x[3:6] / x[3:6] - 1)) < 1e-3
    assert np.max(np.abs(res.x[6:9] - x[6:9])) < 1.5e-3


def _tilted_faces(deg, seed=0, noise=0.0, g=9.81):
    from inertialab.sensors import triaxial as tx

    rng = np.random.default_rng(seed)
    d = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    out = []
    for v in d:
        w = rng.standard_normal(3) * np.deg2rad(deg)
        w -= v * (w @ v)
        out.append(tx.rotation(w) @ v)
    x = np.array([0.25, -0.35, 0.55, 1.021, 0.985, 1.012, 0.012, -0.008, 0.015])
    return tx.forward(x, g * np.array(out)) + noise * rng.standard_normal((6, 3)), x


def test_face_fit_closed_form_is_the_six_position_method():
    from inertialab.sensors.triaxial_classic import face_fit

    m, x = _tilted_faces(3.0)
    cf = face_fit(m, g=9.81, refine=False)
    assert np.allclose(cf.x, six_position(m, g=9.81).x, atol=1e-12)


@pytest.mark.parametrize("deg", [1.0, 3.0])
def test_face_fit_hand_placed_faces_have_gravity_magnitude(deg):
    # faces tilted by a few degrees; the closed form leaves |a| errors of
    # 0.3 % per degree (first order: the bias absorbs the tilts), the refinement none
    from inertialab.sensors.triaxial_classic import face_fit

    m, x = _tilted_faces(deg, noise=1e-4)
    cf = face_fit(m, g=9.81, refine=False)
    rf = face_fit(m, g=9.81)
    assert np.max(np.abs(cf.norm_residual)) > 2e-3 * 9.81 * deg
    assert np.max(np.abs(rf.norm_residual)) < 1e-4 * 9.81
    # and the parameters are no worse than the closed form's (measured: 2.6x better)
    assert np.max(np.abs(rf.x - x)) < np.max(np.abs(cf.x - x))
    # the face tilts it reports are of the size placed (1-sigma deg per axis, 2 axes)
    assert np.rad2deg(np.max(rf.tilt_rad)) < 4 * deg
