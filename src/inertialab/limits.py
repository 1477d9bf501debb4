"""Budgets and numeric bounds: the one place every layer asks "is this too big, out of
range or not a number?" before it allocates, loops or writes.

- :func:`check_budget` refuses an allocation a file or an argument *declares* (an HDF5
  dataset's shape, a ``.mat`` variable's dimensions, a bag record's length, a resampled
  grid, a simulated record, a day span) when it exceeds :func:`memory_budget`, before
  a byte is allocated, so a 4 MB file declaring 4 GiB of zeros is one error line instead
  of a trip to the out-of-memory killer.
- :func:`bounded` (and :func:`bounded_int`) refuse a non-finite or out-of-range argument
  with one line naming it; :func:`finite` refuses NaN, infinity and magnitudes above
  :data:`MAX_MAGNITUDE` (squares and sums of larger values overflow a double).
- :func:`regular_input` refuses an input that is not a regular file (a FIFO would block
  the reader forever, ``/dev/zero`` never ends) unless the format is a directory.

Library functions call these themselves, so a check holds whatever the command line
looks like; messages name arguments (``argument 'order'``), and the command line turns
them into flags. Units: bytes for budgets.
"""

from __future__ import annotations

import math
import os
import stat
from pathlib import Path

from inertialab.errors import InputError

__all__ = ["MAX_COLUMNS", "MAX_HORIZON", "MAX_MAGNITUDE", "MAX_WORK", "MAX_WORKERS", "bounded",
           "bounded_int", "check_budget", "check_horizon", "check_work", "finite",
           "memory_budget", "regular_input"]

#: Default budget of one allocation declared by an input or an argument (bytes);
#: ``INERTIALAB_MAX_BYTES`` in the environment overrides it (e.g. ``8e9``).
DEFAULT_BUDGET = 1 << 30
#: Largest magnitude of a number that a model, a matrix or an argument may hold: the
#: square of a larger value overflows a double.
MAX_MAGNITUDE = 1e100
#: Most columns a table may have (a header of a million names is not a sensor log).
MAX_COLUMNS = 10_000
#: Longest forecast horizon of a storage-drift model in grid steps (about 2.7 years of a daily programme). A
#: closed-loop forecast far past the 20 steps of spec 004 §5 says nothing, and its cost
#: (bootstrap paths x steps) grows linearly: 1e8 steps ran for minutes.
MAX_HORIZON = 1000


def check_horizon(horizon) -> int:
    """``horizon`` as an int in 1..:data:`MAX_HORIZON`, else an InputError naming it."""
    try:
        k = int(horizon)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"argument 'horizon' must be an integer, got {horizon!r}") from None
    if k != horizon or not 1 <= k <= MAX_HORIZON:
        raise InputError(f"argument 'horizon' must be an integer from 1 to {MAX_HORIZON} "
                         f"steps, got {horizon}")
    return k

#: Most worker processes a run may start.
MAX_WORKERS = 256


def memory_budget() -> int:
    """The allocation budget in bytes: ``INERTIALAB_MAX_BYTES`` or 1 GiB."""
    env = os.environ.get("INERTIALAB_MAX_BYTES", "").strip()
    if env:
        try:
            v = float(env)
        except ValueError:
            v = float("nan")
        if math.isfinite(v) and v > 0:
            return int(v)
    return DEFAULT_BUDGET


def _gib(n: float) -> str:
    return f"{n / 2**30:.3g} GiB" if n >= 2**20 else f"{n:.0f} bytes"


def check_budget(nbytes: float, what: str, path=None, *, scanned: bool = False) -> None:
    """Refuse (:class:`InputError`) an allocation of ``nbytes`` for ``what`` above
    :func:`memory_budget`; ``path`` names the file that declared it. ``scanned``: the
    count stopped once past the budget (the message says "more than")."""
    budget = memory_budget()
    n = float(nbytes)
    if not math.isfinite(n) or n > budget:
        size = _gib(n) if math.isfinite(n) else "an unbounded amount"
        if scanned:
            size = f"more than {_gib(budget)}"
        raise InputError(f"{what} needs {size}, above the memory budget of {_gib(budget)} "
                         "(set INERTIALAB_MAX_BYTES to allow more)", path=path)


#: Most elementary steps (about one multiply-add each) one computation may take when an
#: argument asks for everything (``taus="all"`` on a long record is O(N^2)): about half
#: a minute (measured: TOTDEV at every tau of 60 000 samples, 1.8e9 steps, 53 s on a
#: loaded 2-core machine).
MAX_WORK = 1e9


def check_work(steps: float, what: str, hint: str, path=None) -> None:
    """Refuse a computation of about ``steps`` elementary steps above :data:`MAX_WORK`
    (it would run for minutes to hours with no sign of progress); ``hint`` says what to
    ask for instead."""
    if not float(steps) <= MAX_WORK:
        raise InputError(f"{what} takes about {float(steps):.2g} steps, more than the "
                         f"{MAX_WORK:.0g} a run may take; {hint}", path=path)


def _number(name: str, value) -> float:
    if isinstance(value, bool):
        raise InputError(f"argument '{name}' must be a number, got {value!r}")
    try:
        return float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"argument '{name}' must be a number, got {str(value)[:40]!r}") from None


def bounded(name: str, value, lo: float | None = None, hi: float | None = None, *,
            path=None, lo_open: bool = False):
    """Return ``value`` when it is a finite number in ``[lo, hi]`` (``(lo, hi]`` with
    ``lo_open``; a None bound is open); else raise one :class:`InputError` line naming
    argument ``name``. None passes through (an unset option)."""
    if value is None:
        return None
    v = _number(name, value)
    lo_ok = lo is None or (v > lo if lo_open else v >= lo)
    if not math.isfinite(v) or not lo_ok or (hi is not None and v > hi):
        rng = ("(" if lo_open else "[") + ("-inf" if lo is None else f"{lo:g}") + ", " + \
            ("inf" if hi is None else f"{hi:g}") + "]"
        raise InputError(f"argument '{name}' must be a finite number in {rng}, got "
                         f"{str(value)[:40]}", path=path)
    return value


def bounded_int(name: str, value, lo: int | None = None, hi: int | None = None, *,
                path=None) -> int | None:
    """:func:`bounded` for a whole number; returns it as ``int``."""
    if value is None:
        return None
    bounded(name, value, lo, hi, path=path)
    v = float(value)
    if v != int(v):
        raise InputError(f"argument '{name}' must be a whole number, got {str(value)[:40]}",
                         path=path)
    return int(v)


def finite(name: str, values, *, max_abs: float = MAX_MAGNITUDE, path=None):
    """Refuse NaN, infinity or a magnitude above ``max_abs`` anywhere in ``values`` (a
    number or an array); names ``name`` and the first offending index. Returns
    ``values``."""
    import numpy as np

    try:
        arr = np.asarray(values, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"'{name}' must hold numbers", path=path) from None
    bad = ~np.isfinite(arr) | (np.abs(np.where(np.isfinite(arr), arr, 0.0)) > max_abs)
    if bad.any():
        flat = int(np.flatnonzero(bad.ravel())[0])
        at = "" if arr.ndim == 0 else \
            f"[{', '.join(str(int(i)) for i in np.unravel_index(flat, arr.shape))}]"
        raise InputError(f"'{name}{at}' is {float(arr.ravel()[flat])!r}; values must be finite with "
                         f"magnitude at most {max_abs:g}", path=path)
    return values


def regular_input(path, *, allow_dir: bool = False) -> Path:
    """Return ``Path(path)`` when it names a regular file (or, with ``allow_dir``, a
    directory); a FIFO, device or socket is refused before anything opens it (opening a
    FIFO blocks until a writer comes; a device never ends)."""
    p = Path(path)
    try:
        mode = os.stat(p).st_mode
    except FileNotFoundError:
        raise InputError("no such file", path=p) from None
    except OSError as exc:
        raise InputError(f"cannot read ({exc.strerror or type(exc).__name__})",
                         path=p) from None
    if stat.S_ISREG(mode) or (allow_dir and stat.S_ISDIR(mode)):
        return p
    if stat.S_ISDIR(mode):
        raise InputError("is a directory, expected a file", path=p)
    kind = ("a FIFO" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode)
            else "a device")
    raise InputError(f"is {kind}, not a regular file; inputs are read only from regular "
                     "files", path=p)
