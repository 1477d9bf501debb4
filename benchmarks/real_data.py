"""Where the real logs are: one setting, ``INERTIALAB_REAL_DATA``.

Real files written by other software (the two ADIS16405 logs of the R package imudata,
PX4 ULogs) are never copied into the repository. Benchmarks find them in the folder the
environment variable ``INERTIALAB_REAL_DATA`` names; unset, the folder ``shared/data``
beside the repository's own folder (where the project's checkouts keep it). A benchmark
that needs a file it does not find there says so and skips that part.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["ENV", "real_data_dir"]

#: the one setting that locates the real logs
ENV = "INERTIALAB_REAL_DATA"


def real_data_dir() -> Path:
    """The folder of the real logs: ``$INERTIALAB_REAL_DATA``, else ``shared/data`` beside
    the repository."""
    env = os.environ.get(ENV)
    if env:
        return Path(env).expanduser()
    return Path(__file__).resolve().parents[1].parent / "shared" / "data"
