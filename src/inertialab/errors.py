"""Exceptions and warnings of inertialab.

Every user-facing error is an :class:`InputError` (a ``ValueError``) whose message is
one line naming the file, the column and the row where that is known. The CLI turns
it into exit status 2 with that one line on stderr.
"""

from __future__ import annotations


class InputError(ValueError):
    """Bad input: a file, column, row, option or model file that cannot be used.

    Examples
    --------
    >>> str(InputError("must be positive", path="g.csv", column="rate_dph", row=[3]))
    "g.csv: column 'rate_dph', rows 3: must be positive"

    Parameters
    ----------
    message : str
        What is wrong and, where possible, what to change.
    path, column, row : optional
        Where it is wrong. They are prefixed to the message as
        ``"<path>: column '<column>', row <row>: <message>"``; ``row`` is the
        1-based data row (the header is row 0), as a spreadsheet user counts.
    """

    def __init__(self, message: str, *, path=None, column=None, row=None):
        self.path = None if path is None else str(path)
        self.column = column
        self.row = row
        where = []
        if self.path is not None:
            where.append(self.path)
        loc = []
        if column is not None:
            loc.append(f"column '{column}'")
        if row is not None:
            loc.append(f"row {row}" if not isinstance(row, (list, tuple)) else
                       "rows " + ", ".join(str(r) for r in row))
        if loc:
            where.append(", ".join(loc))
        prefix = ": ".join(where)
        text = " ".join(str(message).split())  # always one line
        super().__init__(f"{prefix}: {text}" if prefix else text)

    def naming(self, path) -> InputError:
        """This error with ``path`` in front (``"<path>: <message>"``) when it names no
        file yet; unchanged when it does. The reading front door and the command line
        call it once where an error leaves them, so every message names its file
        without each raise site repeating it."""
        if self.path is None and path is not None:
            self.path = str(path)
            self.args = (f"{self.path}: {self.args[0]}", *self.args[1:])
        return self


class OutputError(InputError):
    """An output cannot be written where it was asked for (exit 2, one line)."""


class ImplausibleCalibrationError(InputError):
    """A fit whose parameters are not identifiable or not physically plausible."""


class SchemaError(ValueError):
    """A model payload does not match its type's schema (``where`` is the key path,
    e.g. ``.coef[2]``)."""

    def __init__(self, where: str, message: str):
        self.where = where
        super().__init__(f"payload{where}: {message}")


class NotFittedError(RuntimeError, AttributeError):
    """An estimator's ``predict``/``forecast``/``to_dict`` was called before ``fit``.

    The one such error of every estimator; like scikit-learn's
    ``NotFittedError`` it is both a ``RuntimeError`` and an ``AttributeError``.
    """


class MissingReferenceError(InputError):
    """An objective or method needs reference directions/values the records lack.

    Examples
    --------
    >>> err = MissingReferenceError("needs the table's reference angles", path="r.csv",
    ...                             column="angle_deg")
    >>> str(err)
    "r.csv: column 'angle_deg': needs the table's reference angles"
    >>> isinstance(err, InputError), isinstance(err, ValueError)
    (True, True)
    """


class UnderdeterminedError(InputError):
    """Fewer independent observations than unknowns, or a degenerate design.

    Examples
    --------
    >>> str(UnderdeterminedError("3 positions for 12 unknowns", path="six.csv"))
    'six.csv: 3 positions for 12 unknowns'
    >>> issubclass(UnderdeterminedError, InputError)
    True
    """


class NonIdentifiableWarning(UserWarning):
    """Some parameters are not identifiable from the data (rank deficiency).

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warnings.warn("g-sensitivity not identifiable", NonIdentifiableWarning)
    >>> caught[0].category.__name__, issubclass(NonIdentifiableWarning, UserWarning)
    ('NonIdentifiableWarning', True)
    """


class ShrinkageWarning(UserWarning):
    """A shrinkage estimator leaned heavily on its prior.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warnings.warn("posterior weight on the prior 0.97", ShrinkageWarning)
    >>> str(caught[0].message), issubclass(ShrinkageWarning, UserWarning)
    ('posterior weight on the prior 0.97', True)
    """


class ExtrapolationWarning(UserWarning):
    """A model was applied outside the range it was trained on.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error", ExtrapolationWarning)
    ...     try:
    ...         warnings.warn("85 degC above the 70 degC trained", ExtrapolationWarning)
    ...     except ExtrapolationWarning as w:
    ...         print(w)
    85 degC above the 70 degC trained
    """


class ConvergenceWarning(UserWarning):
    """An iterative method stopped before its convergence criterion held."""


class DataQualityWarning(UserWarning):
    """The data are usable but something about them deserves the user's attention."""
