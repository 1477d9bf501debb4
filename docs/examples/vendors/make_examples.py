"""Write the small vendor-style example logs of docs/vendor-files.md (seeded; run once).

Each file is a 100 Hz, 2 s static IMU log (z axis up) in the layout of one vendor's
export; its mapping file beside it turns it into inertialab's canonical columns.
"""

import numpy as np

N, FS = 200, 100.0
rng = np.random.default_rng(20260101)
g = 9.80665
acc = np.column_stack([0.002 * rng.standard_normal(N) + 0.01,
                       0.002 * rng.standard_normal(N) - 0.02,
                       g + 0.002 * rng.standard_normal(N)])           # m/s^2
gyr = 0.001 * rng.standard_normal((N, 3)) + [1e-4, -2e-4, 5e-5]       # rad/s


def xsens():
    deg = np.degrees(gyr)
    lines = ["// General information:", "//  MT Manager version: 2022.0.0 (style example)",
             "//  XDA version: 2022.0.0", "// Device information:", "//  DeviceId: 0123ABCD",
             "// Device settings:", "//  Filter Profile: General", "// Update Rate: 100.0Hz", "",
             "PacketCounter;SampleTimeFine;Acc_X;Acc_Y;Acc_Z;Gyr_X;Gyr_Y;Gyr_Z"]
    for i in range(N):
        vals = [f"{v:.6f}".replace(".", ",") for v in (*acc[i], *deg[i])]
        lines.append(";".join([str(1000 + i), str(3_000_000 + 100 * i), *vals]))
    open("xsens.txt", "w").write("\n".join(lines) + "\n")


def vectornav():
    lines = ["TimeStartup,UncompAccX,UncompAccY,UncompAccZ,UncompGyroX,UncompGyroY,UncompGyroZ,"
             "Temperature"]
    t0 = 512_000_000_000
    for i in range(N):
        lines.append(",".join([str(t0 + 10_000_000 * i),
                               *(f"{v:.6f}" for v in acc[i]), *(f"{v:.7f}" for v in gyr[i]),
                               "24.5"]))
    open("vectornav.csv", "w").write("\n".join(lines) + "\n")


def px4():
    lines = ["timestamp,gyro_rad[0],gyro_rad[1],gyro_rad[2],gyro_integral_dt,"
             "accelerometer_timestamp_relative,accelerometer_m_s2[0],accelerometer_m_s2[1],"
             "accelerometer_m_s2[2],accelerometer_integral_dt,accelerometer_clipping"]
    for i in range(N):
        lines.append(",".join([str(95_000_123 + 10_000 * i), *(f"{v:.7f}" for v in gyr[i]),
                               "10000", "0", *(f"{v:.6f}" for v in acc[i]), "10000", "0"]))
    open("px4_sensor_combined.csv", "w").write("\n".join(lines) + "\n")


def ros():
    lines = ["%time,field.header.seq,field.header.stamp,field.header.frame_id,"
             "field.angular_velocity.x,field.angular_velocity.y,field.angular_velocity.z,"
             "field.linear_acceleration.x,field.linear_acceleration.y,field.linear_acceleration.z"]
    t0 = 1_767_225_600_123_456_789  # ns since the epoch: needs integer differencing
    for i in range(N):
        t = t0 + 10_000_000 * i
        lines.append(",".join([str(t), str(i), str(t), "imu_link",
                               *(f"{v:.7f}" for v in gyr[i]), *(f"{v:.6f}" for v in acc[i])]))
    open("ros_imu.csv", "w").write("\n".join(lines) + "\n")


if __name__ == "__main__":
    for make in (xsens, vectornav, px4, ros):
        make()
