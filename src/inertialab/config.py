"""Settings of a workflow as a dataclass whose fields say, once, everything about
themselves: the help text, the command-line flag, the unit, the allowed values or the
numeric bounds. The command line builds its options from them and the library
validates with them, so a bound is declared in one place.

::

    @dataclass(frozen=True)
    class FitConfig(Config):
        horizon: int = setting(20, help="Forecast horizon K in grid steps.", lo=1, hi=1000)
        preset: str = setting("paper", help="paper | strict", choices=("paper", "strict"))

``FitConfig(horizon=0).validate()`` raises one :class:`~inertialab.errors.InputError`:
``argument 'horizon' must be from 1 to 1000, got 0``; the command line shows it as
``--horizon``. Library code never names a flag: ``flag`` is the argument's name with
``_`` as ``-`` unless the field says otherwise (without the leading dashes).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from inertialab.errors import InputError

__all__ = ["DEFAULT_CONFIDENCE", "Config", "read_run_config", "seed_setting", "setting"]

_KEY = "inertialab"

#: The two-sided confidence of an interval when the user gives none, per record kind (the
#: one place it is written): clocks 0.683, one sigma as Stable32 prints it; IMU logs 0.95,
#: the level at which the noise terms' coverage is benchmarked (docs/noise-terms.md).
DEFAULT_CONFIDENCE = {"clock": 0.683, "imu": 0.95}


def setting(default=dataclasses.MISSING, *, help: str, flag: str | None = None,
            lo: float | None = None, hi: float | None = None, choices=None,
            unit: str | None = None, cli: bool = True, default_factory=dataclasses.MISSING):
    """A dataclass field of a :class:`Config` with its help text, flag name (without
    dashes; default: the field name with ``_`` as ``-``), unit, ``choices`` or numeric
    bounds ``lo``/``hi`` (inclusive; NaN and infinities are refused too). ``cli=False``
    keeps a field off the command line."""
    meta = {_KEY: {"help": help, "flag": flag, "lo": lo, "hi": hi,
                   "choices": None if choices is None else tuple(choices), "unit": unit,
                   "cli": cli}}
    if default_factory is not dataclasses.MISSING:
        return dataclasses.field(default_factory=default_factory, metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def seed_setting(help: str = "Random seed (same seed, same numbers).", default: int | None = 0):
    """The ``seed`` setting every seeded workflow declares (a non-negative integer;
    ``default=None`` where the workflow derives one)."""
    return setting(default, help=help, lo=0, hi=2**63 - 1)


def _describe(v) -> str:
    return repr(v) if isinstance(v, str) else str(v)


@dataclass(frozen=True)
class Config:
    """Base of the workflows' settings: :meth:`validate`, :meth:`to_dict`,
    :meth:`fields` (what the command line reads)."""

    @classmethod
    def fields(cls) -> list[tuple[dataclasses.Field, dict]]:
        """``(field, metadata)`` of every declared setting, in order."""
        return [(f, {**f.metadata[_KEY], "flag": f.metadata[_KEY]["flag"]
                     or f.name.replace("_", "-")})
                for f in dataclasses.fields(cls) if _KEY in f.metadata]

    def validate(self):
        """``self`` when every setting is within its bounds or choices; else one-line
        :class:`InputError` naming the argument."""
        for f, m in self.fields():
            v = getattr(self, f.name)
            if v is None:
                continue
            if m["choices"] is not None and v not in m["choices"]:
                raise InputError(f"argument '{f.name}' must be one of "
                                 f"{', '.join(map(str, m['choices']))}, got {_describe(v)}")
            if m["lo"] is None and m["hi"] is None:
                continue
            for x in (v if isinstance(v, (tuple, list)) else (v,)):
                _check_number(f.name, x, m["lo"], m["hi"])
        return self

    def to_dict(self) -> dict:
        """The settings as plain JSON values (tuples as lists), in declaration order."""
        out = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            out[f.name] = list(v) if isinstance(v, tuple) else v
        return out


def _check_number(name, x, lo, hi) -> None:
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise InputError(f"argument '{name}' must be a number, got {_describe(x)}") from None
    span = (f"from {lo:g} to {hi:g}" if lo is not None and hi is not None else
            f">= {lo:g}" if lo is not None else f"<= {hi:g}")
    if not math.isfinite(v) or (lo is not None and v < lo) or (hi is not None and v > hi):
        raise InputError(f"argument '{name}' must be {span}, got {_describe(x)}")


#: Largest run-configuration file read (bytes); a run configuration is a few lines.
MAX_CONFIG_BYTES = 1 << 20


def read_run_config(path) -> dict:
    """A run configuration (TOML, at most :data:`MAX_CONFIG_BYTES`) as a dict; a missing,
    unreadable, non-UTF-8, too deeply nested or invalid file is one
    :class:`~inertialab.errors.InputError` naming it."""
    import tomllib

    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_CONFIG_BYTES + 1)
    except FileNotFoundError:
        raise InputError("no such configuration file", path=path) from None
    except IsADirectoryError:
        raise InputError("configuration is a directory, not a TOML file", path=path) from None
    except OSError as exc:
        raise InputError(f"cannot read configuration ({exc.strerror})", path=path) from None
    if len(raw) > MAX_CONFIG_BYTES:
        raise InputError(f"configuration is larger than {MAX_CONFIG_BYTES} bytes", path=path)
    try:
        return tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError:
        raise InputError("configuration is not UTF-8 text", path=path) from None
    except RecursionError:
        raise InputError("configuration is nested too deeply", path=path) from None
    except ValueError as exc:  # TOMLDecodeError, or an integer of thousands of digits
        raise InputError(f"configuration is not valid TOML ({' '.join(str(exc).split())})",
                         path=path) from None
