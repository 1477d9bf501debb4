"""Readers of the binary and container formats robots and rigs log in (ROS 1/2 bags,
PX4 ULog, MATLAB/HDF5), each returning a DataFrame for the one front door
(:func:`inertialab.io.read_record`). Each needs the ``[formats]`` extra; a missing
extra is a one-line :class:`~inertialab.errors.InputError` naming it."""
