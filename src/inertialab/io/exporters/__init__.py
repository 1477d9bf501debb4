"""Writers of the files other tools load directly: noise parameters for Kalibr,
VINS/imu_utils, OpenVINS and GTSAM; calibrations for imucal, imu_tk and Kalibr's
intrinsics. Each writes atomically and is tested by reading back with the format's own
reader or a parser of its documented grammar."""
