"""Pin every loaded OpenBLAS (NumPy's and SciPy's) to one thread for a block of code.

Small dense least-squares problems (SCM/ANFIS fits inside the IAFSA search, LM steps)
run far slower threaded on a shared 2-core machine (measured: ~300 x 100 least squares
100x slower; SciPy's ``gelsy`` running multi-threaded cost 20x CPU). Written by hand with
ctypes because threadpoolctl is not a dependency and this needs only the two OpenBLAS
thread-count symbols. A floor-0 module: every package may use it.
"""

from __future__ import annotations

from contextlib import contextmanager


def _openblas_handles() -> list:
    """(get, set) thread-count functions of every OpenBLAS loaded in this process (NumPy
    and SciPy each bundle their own), Linux only; empty when none can be reached."""
    import ctypes

    try:
        with open("/proc/self/maps") as fh:
            paths = {ln.split()[-1] for ln in fh
                     if "openblas" in ln.lower() and ln.split()[-1].startswith("/")}
    except OSError:
        return []
    found = []
    for path in sorted(paths):
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for name in ("scipy_openblas{}64_", "scipy_openblas{}", "openblas{}64_", "openblas{}"):
            get = getattr(lib, name.format("_get_num_threads"), None)
            put = getattr(lib, name.format("_set_num_threads"), None)
            if get is not None and put is not None:
                found.append((get, put))
                break
    return found


@contextmanager
def single_threaded_blas():
    """Run every loaded OpenBLAS single-threaded inside the block (multi-threaded least
    squares on ~300 x 100 matrices was measured 100x slower on 2 cores). A no-op where no
    BLAS can be reached; the previous thread counts are restored on exit.

    Examples
    --------
    The numbers are those of the threaded run; only the thread count changes, and it is
    back to what it was after the block:

    >>> import numpy as np
    >>> from inertialab.blas import _openblas_handles
    >>> before = [int(get()) for get, _ in _openblas_handles()]
    >>> rng = np.random.default_rng(0)
    >>> a, x = rng.normal(size=(300, 100)), rng.normal(size=100)
    >>> with single_threaded_blas():
    ...     inside = {int(get()) for get, _ in _openblas_handles()}
    ...     x_hat = np.linalg.lstsq(a, a @ x, rcond=None)[0]
    >>> inside <= {1}, bool(np.allclose(x_hat, x))
    (True, True)
    >>> [int(get()) for get, _ in _openblas_handles()] == before
    True
    """
    handles = _openblas_handles()
    old = [int(get()) for get, _ in handles]
    for _, put in handles:
        put(1)
    try:
        yield
    finally:
        for (_, put), n in zip(handles, old):
            put(n)
