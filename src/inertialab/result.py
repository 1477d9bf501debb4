"""The spine as a type: what every command's result is to the one runner
(:class:`inertialab.cli.runner.Run`).

A workflow's ``run*`` function returns a :class:`Result`: its own JSON keys
(``to_json()``), the ``settings`` it ran with and the ``units`` of its numbers (dicts),
the files it writes with ``--out`` (``artifacts()``: ``{"models": [(file name, model,
units)], "files": {file name: text}, "records": [(path, frame, meta)]}``), the tables it
prints (``summary_rows()``: ``(title, columns, rows)`` tuples and plain lines), the
``inputs`` the run read (paths, or ``{"path", "sha256"}`` dicts, for the JSON envelope),
its own ``warnings`` (lines, beside the Python warnings raised while it ran) and
``sha256``, the canonical hash of the record a model was trained on (None when no
model is trained). :class:`ResultBase` gives the last three their defaults, and
:meth:`ResultBase.with_inputs` is the one way to set ``inputs``, so the runner never
probes a result for an attribute.

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass
... class Mean(ResultBase):
...     value: float
...     settings: dict
...     units = {"value": "dph"}
...     def to_json(self):
...         return {"value": self.value}
...     def artifacts(self):
...         return {}
...     def summary_rows(self):
...         return [f"mean {self.value:.3f} dph"]
>>> r = Mean(0.25, {"column": "rate_dph"}).with_inputs(["gyro.csv"])
>>> isinstance(r, Result), r.inputs, r.warnings, r.sha256
(True, ['gyro.csv'], [], None)
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

__all__ = ["Result", "ResultBase", "check_result"]


@runtime_checkable
class Result(Protocol):
    """What the runner reads from a command's result (module docstring)."""

    settings: dict
    units: dict
    inputs: list
    warnings: list
    sha256: str | None

    def to_json(self) -> dict: ...

    def artifacts(self) -> dict: ...

    def summary_rows(self) -> list: ...

    def with_inputs(self, items) -> Result: ...


class ResultBase:
    """Defaults of :class:`Result`: no own warnings, no training hash, and the inputs the
    runner names (set once, through :meth:`with_inputs`). A result that has warnings or a
    training hash declares them itself (a field or a property of the same name)."""

    sha256: str | None = None

    @property
    def warnings(self) -> list:
        """The result's own warning lines (none unless the result says otherwise)."""
        return []

    @property
    def inputs(self) -> list:
        """What the run read, for the JSON envelope (``[]`` until the runner sets it).

        >>> ResultBase().inputs
        []
        """
        return list(self.__dict__.get("_inputs", ()))

    def with_inputs(self, items) -> ResultBase:
        """Set :attr:`inputs` (paths or ``{"path", "sha256"}`` dicts); returns ``self``.

        >>> ResultBase().with_inputs(["a.csv", {"path": "b.csv", "sha256": "00"}]).inputs
        ['a.csv', {'path': 'b.csv', 'sha256': '00'}]
        """
        self.__dict__["_inputs"] = list(items)
        return self


def check_result(result, command: str) -> Result:
    """``result`` when it is a :class:`Result`, else a ``TypeError`` naming ``command``
    and the members it lacks (a workflow bug, not the user's input).

    >>> check_result(object(), "allan")
    Traceback (most recent call last):
    ...
    TypeError: allan returned a object, not a Result: lacks settings, units, inputs, warnings, sha256, to_json, artifacts, summary_rows, with_inputs
    """
    if isinstance(result, Result):
        return result
    members = ("settings", "units", "inputs", "warnings", "sha256", "to_json", "artifacts",
               "summary_rows", "with_inputs")
    missing = [m for m in members if not hasattr(result, m)]
    raise TypeError(f"{command} returned a {type(result).__name__}, not a Result: lacks "
                    + ", ".join(missing))
