"""inertialab: inertial-sensor test records to noise figures, calibration, models and forecasts.

The package is layered (docs/architecture.md): ``units``, ``errors`` and ``seeding`` at the
bottom; ``io``; the method packages ``noise``, ``learn``, ``optim``, ``regress`` and
``metrics``; ``sensors``; ``sim`` (the virtual lab); ``workflows``; ``report``; ``cli``.
"""

from inertialab.errors import (
    ExtrapolationWarning,
    InputError,
    MissingReferenceError,
    NonIdentifiableWarning,
    ShrinkageWarning,
    UnderdeterminedError,
)

__version__ = "0.1.0"

__all__ = [
    "ExtrapolationWarning",
    "InputError",
    "MissingReferenceError",
    "NonIdentifiableWarning",
    "ShrinkageWarning",
    "UnderdeterminedError",
    "__version__",
]
