"""Pick the reader of a file by its suffix (or content) for the one front door.

Every reader returns a :class:`Loaded`: a frame whose column names are either the
user's (text, MATLAB, HDF5, ``.npy``: mapped afterwards by the column map) or already
canonical (ROS ``sensor_msgs/Imu`` and PX4 ULog: ``t_s gx_rps ... ax_mps2 ...``, the
units those formats define), plus metadata for the record.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.io.formats.base import Loaded, columns_frame, need
from inertialab.limits import regular_input

__all__ = ["Loaded", "is_bag_folder", "load_frame", "need"]

_TEXT = "text"
_MAT5 = b"MATLAB 5.0"
_HDF5 = b"\x89HDF\r\n\x1a\n"


def is_bag_folder(p: Path) -> bool:
    """A ROS 2 bag folder (holds ``metadata.yaml``)."""
    return p.is_dir() and (p / "metadata.yaml").is_file()


def _magic(p: Path, n: int = 128) -> bytes:
    with open(p, "rb") as fh:
        return fh.read(n)


def format_of(p: Path) -> str:
    """``text``, ``parquet``, ``npy``, ``mat5``, ``hdf5``, ``rosbag1``, ``rosbag2``, ``ulog``."""
    if p.is_dir():
        return "rosbag2"
    suf = p.suffix.lower()
    if suf in (".parquet", ".pq"):
        return "parquet"
    if suf == ".npy":
        return "npy"
    if suf == ".bag":
        return "rosbag1"
    if suf in (".db3", ".mcap"):
        return "rosbag2"
    if suf == ".ulg":
        return "ulog"
    if suf in (".mat", ".h5", ".hdf5", ".hdf", ".he5"):
        head = _magic(p)
        if head.startswith(_MAT5):
            # v7.3 files carry a MATLAB text header too, with the HDF5 signature at 512
            with open(p, "rb") as fh:
                fh.seek(512)
                if fh.read(8) == _HDF5:
                    return "hdf5"
            return "mat5"
        if head.startswith(_HDF5):
            return "hdf5"
        if suf == ".mat" and b"\0" not in head:
            return _TEXT  # imu_tk writes whitespace text with a .mat suffix
        if suf == ".mat":
            return "mat4"
        raise InputError("not an HDF5 file (no HDF5 signature)", path=p)
    return _TEXT


def load_frame(path, *, parse=None, options=None) -> Loaded:
    """Read ``path`` into a :class:`Loaded` (see the module docstring).

    Examples
    --------
    The columns as the file has them, before any mapping or validation; ``# key=value``
    lines become metadata:

    >>> import tempfile
    >>> from pathlib import Path
    >>> tmp = tempfile.TemporaryDirectory()
    >>> folder = Path(tmp.name)
    >>> _ = (folder / "log.txt").write_text("# fs_hz=200\\nrate_dps\\n0.5\\n0.7\\n")
    >>> loaded = load_frame(folder / "log.txt")
    >>> loaded.frame["rate_dps"].tolist(), loaded.meta
    ([0.5, 0.7], {'fs_hz': 200})
    >>> tmp.cleanup()
    """
    from inertialab.io.mapping import ReadOptions

    p = regular_input(path, allow_dir=is_bag_folder(Path(path)))
    opts = options if options is not None else ReadOptions()
    kind = format_of(p)
    if kind == _TEXT:
        from inertialab.io.formats.text import load_text
        from inertialab.io.sidecar import parse_header_lines

        tab = load_text(p, parse if parse is not None else opts.parse)
        meta = parse_header_lines(tab.layout.hash_lines, path=p)
        if tab.layout.bom:
            meta["bom_removed"] = True
        return Loaded(tab.frame, meta, dict(tab.header_units))
    if kind == "parquet":
        return Loaded(_parquet(p))
    if kind == "npy":
        return Loaded(_npy_frame(p))
    if kind in ("mat5", "mat4", "hdf5"):
        from inertialab.io.formats.matlab import read_matlab

        return read_matlab(p, kind, dataset=opts.dataset)
    if kind in ("rosbag1", "rosbag2"):
        from inertialab.io.formats.rosbag import read_bag

        return read_bag(p, topic=opts.topic)
    if kind == "ulog":
        from inertialab.io.formats.ulog import read_ulog

        return read_ulog(p, topic=opts.topic, instance=opts.instance)
    raise InputError(f"unknown file format '{kind}'", path=p)  # pragma: no cover


def _parquet(p: Path) -> pd.DataFrame:
    try:
        return pd.read_parquet(p)
    except ImportError:
        raise InputError("reading Parquet needs pyarrow: pip install 'inertialab[parquet]'",
                         path=p) from None
    except Exception as exc:  # pyarrow raises many types for corrupt files
        raise InputError(f"not a readable Parquet file ({type(exc).__name__})", path=p) from None


def _npy_frame(p: Path) -> pd.DataFrame:
    """A 2-D ``.npy`` (columns ``col1..colN``) or a structured one (its field names)."""
    try:
        arr = np.load(p, mmap_mode="r", allow_pickle=False)
    except (ValueError, OSError, EOFError) as exc:
        raise InputError(f"not a readable .npy file ({' '.join(str(exc).split())[:120]})",
                         path=p) from None
    if arr.dtype.names:
        if arr.ndim != 1:
            arr = arr.reshape(-1)
        return pd.DataFrame({n: np.asarray(arr[n]) for n in arr.dtype.names})
    if arr.ndim != 2:
        raise InputError(f".npy array must be 1-D or 2-D, got shape {arr.shape}", path=p)
    if not np.issubdtype(arr.dtype, np.number):
        raise InputError(f".npy log must be numeric, got dtype {arr.dtype}", path=p)
    return columns_frame(np.asarray(arr), meta=None)
