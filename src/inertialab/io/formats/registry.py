"""The file formats the one front door reads, each declared once: its name, suffixes,
signature (magic bytes), the reading options that apply to it and the extra it needs.

:func:`inertialab.io.formats.dispatch.format_of` recognises them; the command line's
reading-option help names the formats an option applies to from here; a conformance
test (``tests/test_registries.py``) checks that every suffix declared here is recognised
as its format and that every option is a reading option with a flag.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["FORMATS", "FileFormat", "formats_with_option"]


@dataclass(frozen=True)
class FileFormat:
    """One readable format.

    Attributes
    ----------
    name : str           what :func:`~inertialab.io.formats.dispatch.format_of` returns
    title : str          one line for help texts
    suffixes : tuple     file suffixes (lower case; ``/`` for a folder)
    magic : bytes        the signature at offset 0 when the suffix is shared, else b""
    options : tuple      fields of :class:`~inertialab.io.mapping.ReadOptions` that
                         choose what is read from it (beyond the column map, units,
                         time column, rate and resampling, which apply to every format)
    extra : str or None  the pip extra it needs (``inertialab[formats]``)

    Examples
    --------
    >>> ulog = next(f for f in FORMATS if ".ulg" in f.suffixes)
    >>> ulog.name, "topic" in ulog.options
    ('ulog', True)
    >>> [f.name for f in FORMATS if ".mat" in f.suffixes]
    ['mat5', 'mat4', 'hdf5']
    """

    name: str
    title: str
    suffixes: tuple[str, ...]
    magic: bytes = b""
    options: tuple[str, ...] = ()
    extra: str | None = None


#: Every format, in the order :func:`format_of` tries them.
FORMATS: tuple[FileFormat, ...] = (
    FileFormat("text", "CSV / whitespace / headerless text (imu_tk .mat text too)",
               (".csv", ".txt", ".tsv", ".dat", ".log"),
               options=("parse",)),
    FileFormat("parquet", "Apache Parquet table", (".parquet", ".pq"), extra="parquet"),
    FileFormat("npy", "NumPy .npy array (2-D or structured)", (".npy",)),
    FileFormat("mat5", "MATLAB v5 .mat", (".mat",), magic=b"MATLAB 5.0", options=("dataset",)),
    FileFormat("mat4", "MATLAB v4 .mat", (".mat",), options=("dataset",)),
    FileFormat("hdf5", "HDF5 / MATLAB v7.3", (".h5", ".hdf5", ".hdf", ".he5", ".mat"),
               magic=b"\x89HDF\r\n\x1a\n", options=("dataset",), extra="formats"),
    FileFormat("rosbag1", "ROS 1 bag (sensor_msgs/Imu)", (".bag",), options=("topic",),
               extra="formats"),
    FileFormat("rosbag2", "ROS 2 bag (folder, .db3 or .mcap; sensor_msgs/Imu)",
               ("/", ".db3", ".mcap"), options=("topic",), extra="formats"),
    FileFormat("ulog", "PX4 ULog (sensor_combined, sensor_gyro, sensor_accel)", (".ulg",),
               options=("topic", "instance"), extra="formats"),
)


def formats_with_option(option: str) -> tuple[str, ...]:
    """Names of the formats that use reading option ``option``.

    Examples
    --------
    >>> formats_with_option("topic")
    ('rosbag1', 'rosbag2', 'ulog')
    """
    return tuple(f.name for f in FORMATS if option in f.options)
