"""A report section: title, text, tables and figures contributed by one study."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass
class Table:
    """A table: ``columns`` (header strings) and ``rows`` (lists of cells).

    Cells may be numbers (formatted with ``fmt``), strings or None (shown as a dash).
    """

    title: str
    columns: list[str]
    rows: list[list[Any]]
    note: str = ""
    fmt: str = ".4g"


@dataclass
class Figure:
    """A matplotlib figure with its caption; rendered as an embedded PNG."""

    figure: Any  # matplotlib.figure.Figure (None once rasterised into ``png``)
    caption: str
    name: str = "figure"
    png: bytes | None = None


@dataclass
class Section:
    """One study's part of the report.

    ``key`` is the study name (anchor in the table of contents); ``paragraphs`` are
    plain text (HTML-escaped when rendered); ``results`` is the JSON-ready data that
    goes into results.json under the study's key.
    """

    key: str
    title: str
    paragraphs: list[str] = field(default_factory=list)
    tables: list[Table] = field(default_factory=list)
    figures: list[Figure] = field(default_factory=list)
    results: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)
