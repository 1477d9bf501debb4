"""Random-number handling: one rule for every stochastic function.

Every stochastic function takes ``rng: int | numpy.random.Generator | None``. An int
becomes ``Generator(PCG64(SeedSequence(int)))``; ``None`` means seed 0 (inertialab
is reproducible by default); a Generator is used as is.
Child streams are spawned with :func:`spawn` in the order the caller documents.
"""

from __future__ import annotations

import numpy as np

from inertialab.errors import InputError

RngLike = "int | np.random.Generator | np.random.SeedSequence | None"


def as_generator(rng=None) -> np.random.Generator:
    """Return a ``numpy.random.Generator`` for ``rng`` (int, Generator, SeedSequence or None=0)."""
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None:
        rng = 0
    if isinstance(rng, np.random.SeedSequence):
        return np.random.Generator(np.random.PCG64(rng))
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool):
        if rng < 0:
            raise InputError(f"argument 'seed' must be >= 0, got {rng}")
        return np.random.Generator(np.random.PCG64(np.random.SeedSequence(int(rng))))
    raise TypeError(f"rng must be an int, a numpy Generator or None, not {type(rng).__name__}")


def spawn(rng, n: int) -> list[np.random.Generator]:
    """Spawn ``n`` independent child generators from ``rng`` (deterministic given ``rng``)."""
    return as_generator(rng).spawn(n)
