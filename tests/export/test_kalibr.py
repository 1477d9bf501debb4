"""export.kalibr: Kalibr's scale-misalignment intrinsics block."""

import numpy as np
import yaml

from inertialab.export.kalibr import write_kalibr


def test_yaml_reproduces_our_model(ferraris_model, tmp_path):
    # Kalibr's forward model with the written matrices, fed the true quantities in its imu
    # frame, gives the raw readings our model inverts
    model, acc, gyr = ferraris_model
    path = tmp_path / "imu_intrinsics.yaml"
    d = write_kalibr(model, path)
    imu0 = yaml.safe_load(path.read_text())["imu0"]
    assert imu0["model"] == "scale-misalignment"
    Ma = np.array(imu0["accelerometers"]["M"])
    Mg, A, C = (np.array(imu0["gyroscopes"][k]) for k in ("M", "A", "C_gyro_i"))
    assert np.allclose(Ma, np.tril(Ma)) and np.allclose(Mg, np.tril(Mg))
    assert np.allclose(C @ C.T, np.eye(3)) and np.linalg.det(C) > 0
    Q = np.array(d["C_i_ours"])
    b_a = np.array(d["biases"]["accelerometer_bias_mps2"])
    b_g = np.array(d["biases"]["gyroscope_bias_rps"])
    a = model.apply(acc)  # m/s^2, our frame
    w = model.apply_gyro(gyr, acc=a)  # rad/s
    a_i, w_i = a @ Q.T, w @ Q.T
    alpha = a_i @ Ma.T + b_a  # Kalibr: alpha = M_a a_i + b
    omega = (w_i @ C.T) @ Mg.T + (a_i @ C.T) @ A.T + b_g
    assert np.allclose(alpha, acc, rtol=1e-12, atol=1e-10)  # raw m/s^2
    assert np.allclose(omega, np.deg2rad(gyr), rtol=1e-10, atol=1e-12)  # raw deg/s -> rad/s
