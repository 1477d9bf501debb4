"""Record schemas: columns with units, required/optional, aliases, validation rules.

A :class:`Column` is either *fixed* (one canonical name such as ``temp_set_c``) or
*unit-flexible* (a base such as ``rate`` whose unit comes from the suffix: ``rate_dph``,
``rate_rps`` ...; ``dimensions`` lists the dimensions the suffix may have). Names are
matched case-insensitively, so the spellings printed in the specs (``temp_meas_C``,
``output_mV``, ``V_A_V``) load unchanged; other spellings are listed as ``aliases``.
A bare flexible name (``ax``) takes its unit from ``--unit``, else from the sidecar
or header key ``units`` (precedence: option > suffix > sidecar).
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Column:
    """One column of a record schema.

    Parameters
    ----------
    name : str
        Canonical name (fixed column) or base name (flexible column, ``dimensions`` set).
    kind : {"float", "int", "str", "bool", "datetime"}
        Value type after validation.
    required : bool
        Must be present (see also :attr:`Schema.one_of`).
    dimensions : tuple of str
        For a unit-flexible column: the allowed dimensions of its suffix
        (see :mod:`inertialab.units`). Empty for a fixed column.
    aliases : tuple of str
        Other accepted spellings (case-insensitive) of a fixed column.
    finite : bool
        NaN/inf are errors (numeric columns). Empty cells count as NaN.
    description : str
        Meaning and unit, for the docs.
    """

    name: str
    kind: str = "float"
    required: bool = False
    dimensions: tuple[str, ...] = ()
    aliases: tuple[str, ...] = ()
    finite: bool = True
    description: str = ""

    @property
    def flexible(self) -> bool:
        return bool(self.dimensions)


@dataclass(frozen=True)
class Schema:
    """A record kind.

    Attributes
    ----------
    kind : str
        Name used by :func:`inertialab.io.read_record`.
    columns : tuple of Column
    one_of : tuple of tuple of str
        Groups of column names/bases of which at least one must be present.
    time_column : str or None
        A time column checked for order.
    time_order : {"strict", "sort", None}
        ``"strict"``: decreasing or repeated time is an InputError naming the rows
        (continuous logs); ``"sort"``: rows are sorted with a warning (per-test tables).
    sort_by : tuple of str
        Columns a per-test table is sorted by when ``time_order == "sort"``
        (first present wins).
    min_rows : int
        Fewer data rows is an InputError.
    required_meta : tuple of str
        Sidecar keys that must be present.
    source : str
        Spec section that defines the record.
    keep_unknown : bool
        Keep columns the schema does not know (True: they pass through untouched).
    """

    kind: str
    columns: tuple[Column, ...]
    one_of: tuple[tuple[str, ...], ...] = ()
    time_column: str | None = None
    time_order: str | None = None
    sort_by: tuple[str, ...] = ()
    min_rows: int = 1
    required_meta: tuple[str, ...] = ()
    source: str = ""
    keep_unknown: bool = True
    description: str = ""
    extra: dict = field(default_factory=dict)

    def column(self, name: str) -> Column | None:
        for c in self.columns:
            if c.name == name:
                return c
        return None
