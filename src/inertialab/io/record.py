"""The validated record every reader returns (its own module so that the format
readers and :mod:`inertialab.io.readers` both use it without importing each other)."""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from inertialab.errors import InputError
from inertialab.io.timestamps import Timebase
from inertialab.units import split_suffix


@dataclass
class Record:
    """A validated record.

    Attributes
    ----------
    kind : schema kind
    data : DataFrame with canonical lower-case column names (units as suffixes)
    meta : sidecar / header metadata
    path : source file (or ``"<frame>"``)
    units : canonical column -> unit suffix, for unit-flexible columns
    sha256 : hash of the validated canonical columns (format-independent)
    arrays : for ``.npy`` logs, the memory-mapped column (not copied into ``data``)
    timebase : the record's one time base (sample rate, tau0, grid slots, jitter, lost
        samples, source), decided once on reading
        (:func:`inertialab.io.timestamps.decide_timebase`); None for a record that is not
        a continuous log, or a log with neither time stamps nor a rate

    Examples
    --------
    >>> import numpy as np
    >>> import pandas as pd
    >>> from inertialab.io import validate_frame
    >>> frame = pd.DataFrame({"t_s": np.arange(5) / 100.0, "rate_dph": [1.0, 2.0, 3.0, 2.0, 1.0]})
    >>> rec = validate_frame(frame, "gyro_log")
    >>> rec.kind, rec.n, rec.units, rec.timebase.rate_hz
    ('gyro_log', 5, {'rate_dph': 'dph'}, 100.0)
    >>> float(rec.column("rate_dph").mean())
    1.8
    """

    kind: str
    data: pd.DataFrame
    meta: dict
    path: str
    units: dict[str, str]
    sha256: str
    arrays: dict[str, np.ndarray] = field(default_factory=dict)
    timebase: Timebase | None = None

    def column(self, name: str) -> np.ndarray:
        """Values of a canonical column as a float ndarray (memmap for .npy logs)."""
        if name in self.arrays:
            return self.arrays[name]
        if name not in self.data.columns:
            raise InputError("no such column", path=self.path, column=name)
        return self.data[name].to_numpy()

    def series(self, name: str) -> np.ndarray:
        """Values of a canonical column on the record's time grid, as floats: NaN in the
        slots of samples lost in a dropout (never interpolated), so that a statistic
        cannot splice the data across a gap (``oadev`` refuses NaN;
        :func:`inertialab.noise.gap_deviation` takes it). The values of :meth:`column`
        when nothing was lost or the record has no time base.

        Examples
        --------
        >>> import warnings
        >>> import pandas as pd
        >>> from inertialab.io import validate_frame
        >>> frame = pd.DataFrame({"t_s": [0.0, 0.1, 0.2, 0.5, 0.6],  # two samples lost
        ...                       "rate_dph": [1.0, 2.0, 3.0, 4.0, 5.0]})
        >>> with warnings.catch_warnings():
        ...     warnings.simplefilter("ignore")  # the dropout's DataQualityWarning
        ...     rec = validate_frame(frame, "gyro_log")
        >>> rec.column("rate_dph").tolist()
        [1.0, 2.0, 3.0, 4.0, 5.0]
        >>> rec.series("rate_dph").tolist()
        [1.0, 2.0, 3.0, nan, nan, 4.0, 5.0]
        """
        values = np.asarray(self.column(name), dtype=np.float64)
        if self.timebase is None:
            return values
        return np.asarray(self.timebase.place(values), dtype=np.float64)

    def find(self, base: str) -> str | None:
        """Canonical name of the unit-flexible column with ``base`` (e.g. ``rate`` ->
        ``rate_dph``), or None."""
        for col in list(self.arrays) + list(self.data.columns):
            b, suf = split_suffix(col)
            if b == base and suf is not None:
                return col
        return None

    @property
    def topic(self) -> str | None:
        """The ROS topic a bag record was read from (``meta["bag"]["topic"]``), else None:
        the default of an exporter's ``rostopic`` (a Kalibr ``imu.yaml`` names the
        topic the user's bag publishes, not ``/imu0``)."""
        bag = self.meta.get("bag")
        return bag.get("topic") if isinstance(bag, dict) else None

    @property
    def n(self) -> int:
        if self.arrays:
            return int(next(iter(self.arrays.values())).shape[0])
        return len(self.data)


@contextmanager
def naming(path):
    """Inside it, an :class:`InputError` that names no file is raised again naming
    ``path`` (the record being analysed), so every error a command prints names its
    file: ``with naming(record.path): detect(...)``."""
    try:
        yield
    except InputError as exc:
        if exc.path is not None or path is None:
            raise
        text = str(exc)
        try:
            new = type(exc)(text, path=path)
        except TypeError:
            new = InputError(text, path=path)
        raise new from None
