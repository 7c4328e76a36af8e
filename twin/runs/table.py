"""A raw run table as read from a file, before validation and repair.

Readers (one per format, like meshio's registry) turn a file into a `RawTable`: float
columns keyed by name, the metadata, and for every row where it sits in the file, so that
every later error or finding can name the line a user sees in an editor.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from twin.errors import InputError
from twin.runs.schema import TIME


@dataclass
class RawTable:
    """Columns of one recorded run exactly as stored in its file.

    `rows[i]` is the 1-based line number of sample i in a CSV file (as an editor shows
    it), or the 1-based data-row number in a Parquet file; `row_unit` says which ("line"
    or "row") where a message names one.  Missing values are NaN.
    """

    file: str
    metadata: dict[str, str]
    columns: dict[str, np.ndarray]
    rows: np.ndarray
    header_row: int | None = None
    ignored_columns: list[str] = field(default_factory=list)
    row_unit: str = "line"
    dialect: str = ""
    """How a CSV file was read where not as the plain one (comma-separated, decimal
    points): "semicolon-separated, with decimal commas", for the command to tell once."""

    @property
    def n_samples(self) -> int:
        return int(self.rows.size)

    def error(self, message: str, row: int | None = None,
              column: str | None = None) -> InputError:
        """InputError in this table's file at `row` (one of `rows`, or `header_row`), called
        a line or a row as the file has them (`row_unit`)."""
        return InputError(message, file=self.file, row=None if row is None else int(row),
                          column=column, row_unit=self.row_unit)


MISSING_TOKENS = frozenset({"", "nan", "na", "n/a", "#n/a", "null", "none"})
"""Cell texts (case-insensitive, after stripping blanks) that mean "no value" (`#N/A`: a
spreadsheet's "not available", what its NA() and lookups write for a missing reading)."""

MAX_NUMBER_CHARS = 64
"""No number a logger writes needs more characters; a longer cell is refused unread."""

# A plain decimal number as loggers write it.  Python's float() also takes `9_000`
# (a source-code digit separator) and `infinity`; neither is a measurement.
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


def is_number(cell: str, decimal_comma: bool = False) -> bool:
    """Whether `cell` is a plain decimal number as `parse_cell` reads one (with a decimal
    comma: `number_text`)."""
    return _NUMBER.fullmatch(number_text(cell, decimal_comma)) is not None


def number_text(cell: str, decimal_comma: bool = False) -> str:
    """`cell` stripped, as `float` is to read it: with `decimal_comma` (a `;` or tab
    separated file, `twin.runs.csv_format`), a comma that is the cell's one decimal mark
    ("22,5") reads as a point; a cell holding a point too ("1.234,5") stays as it is."""
    text = cell.strip()
    if decimal_comma and "," in text and "." not in text and text.count(",") == 1:
        return text.replace(",", ".")
    return text


_CLOCK = re.compile(r"(?:\d{1,4}[-/.]\d{1,2}[-/.]\d{1,4}[ T]?)?"  # a date,
                    r"(?:\d{1,2}:\d{2}(?::\d{2}(?:[.,]\d*)?)?)?")  # a clock time
"""A date, a clock time or both, as a logger or a spreadsheet writes its time column."""


_GROUPED = re.compile(r"[+-]?\d{1,3}(?:[.,]\d{3})+(?:[.,]\d*)?")
"""A number with thousands separators, as a spreadsheet formats it ("9,000", "1,234.5",
and in German "1.234,5", "1.234.567")."""


def is_grouped(cell: str) -> bool:
    """Whether `cell` looks like a number with thousands separators (`_GROUPED`); a reader
    reads none ("9,000" rpm is 9000, not 9)."""
    return _GROUPED.fullmatch(cell.strip()) is not None


def _hint(text: str, column: str) -> str:
    """What a cell that is no number most likely is, where a spreadsheet or a logger wrote
    it."""
    if column == TIME and text and _CLOCK.fullmatch(text.strip()):
        return (" (a date or clock time? time_s holds seconds from the run's start: "
                "convert the column)")
    if is_grouped(text):  # "9,000" or "1,234.5": 9000 rpm, not 9
        return (" (a thousands separator, or a decimal comma? write plain numbers with a "
                "decimal point: 9000, 25.4)")
    if is_number(text.replace(",", ".", 1)):
        return " (a decimal comma? write decimal points)"
    if text.startswith("#") and text.endswith(("!", "?")):
        return (" (a spreadsheet's error value: correct the formula, or leave the cell "
                "empty for a missing reading)")
    return ""


def parse_cell(cell: str, file: str, row: int, column: str, row_unit: str, *,
               decimal_comma: bool = False) -> float:
    """One cell of a run table as a float (NaN for a missing value), or `InputError` at
    `row` (a "line" or a "row", as `RawTable.row_unit`); `decimal_comma` as `number_text`."""
    text = number_text(cell, decimal_comma) if decimal_comma else cell.strip()
    if len(text) > MAX_NUMBER_CHARS:
        raise InputError(f"a cell of {len(text)} characters is not a number", file=file,
                         row=row, column=column, row_unit=row_unit)
    if text.lower() in MISSING_TOKENS:
        return math.nan
    if _NUMBER.fullmatch(text) is None:
        raise InputError(f"cannot read {cell!r} as a number{_hint(text, column)}", file=file,
                         row=row, column=column, row_unit=row_unit)
    value = float(text)
    if math.isinf(value):
        raise InputError(f"{cell!r} is not a finite number", file=file, row=row, column=column,
                         row_unit=row_unit)
    return value


def check_distinct_tables(tables: Sequence[RawTable], why: str) -> None:
    """Refuse a file given twice, or a copy of one under another name or with other line
    ends (the same columns and values): `why` says what the command would get wrong."""
    for k, table in enumerate(tables):
        for other in tables[:k]:
            if table.columns.keys() == other.columns.keys() and all(
                    np.array_equal(table.columns[name], other.columns[name], equal_nan=True)
                    for name in table.columns):
                raise InputError(f"holds the same data as {other.file}; give each file once "
                                 f"({why})", file=table.file)
