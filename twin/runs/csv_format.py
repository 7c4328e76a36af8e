"""Recorded runs as CSV: `# key: value` metadata lines, one header row, one row per sample.

Line numbers are counted as an editor shows them (1-based, every physical line counts,
metadata and blank lines included), so an error message points at the right place.

Dialects.  The separator is decided once, from the header: a header that reads as more
than one comma-separated column is comma-separated (every file that read before reads
as it did); one that reads as a single column holding `;` or tabs is separated by them
(Excel's export in German and most European locales, a tab-separated logger).  An Excel
hint line above the header (`sep=,`, `sep=;`, `sep=` and a tab) decides instead: the way
to read a header holding both `;` and tabs.  In a `;` or tab file a number's decimal
mark may be a comma ("22,5") or a point.  Thousands separators are never read: a cell
with both marks ("1.234,5", "9,000.5") or one mark twice ("1.234.567") is refused.  A
cell that reads either way, 1-3 digits (not a lone 0), one mark, exactly 3 digits
("9.000": 9000 rpm formatted with a separator, or 9.0), is read in a temperature
column (`*_C`: no temperature is grouped) and elsewhere only where the file's
other numbers show the mark to be the decimal one (they use it and never the other:
"9.000" beside "22.5" is 9.0, "9,000" beside "22,5" too); otherwise it is refused,
naming the cell (Excel writes 9000 rpm as "9000" unless the column is formatted with
separators).  Rows of separators, trailing separators, the header written again and a
units row are told for each separator as for ','; a `;` file's metadata lines may end
in the `;` padding a spreadsheet writes.  `RawTable.dialect` says how a file other than
a comma one was read; every file written is comma-separated, with decimal points.
"""

from __future__ import annotations

import csv
import math
import os
import re
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field

import numpy as np

from twin.errors import InputError
from twin.io.atomic import atomic_target
from twin.paths import read_input_text
from twin.runs.schema import ALL_COLUMNS, MAX_SAMPLES
from twin.runs.table import RawTable, is_grouped, is_number, parse_cell

LINE = "line"
"""What an error calls a place in a CSV file (`RawTable.row_unit`): its line, numbered as an
editor numbers them, not a data row (`bad.csv, line 4, column 'T1_C'`)."""

SEPARATORS = {",": "comma", ";": "semicolon", "\t": "tab"}
"""The separators a CSV file may have, by the name a message gives them."""


def read_csv_table(path: str | os.PathLike[str],
                   keep: Callable[[str], bool] | None = None, *,
                   option: str | None = None, max_rows: int | None = MAX_SAMPLES) -> RawTable:
    """Read a CSV recorded run into a `RawTable` (no validation beyond parsing).

    `keep(name)` says which columns to read (default: the recorded-run schema); the
    others are listed in `RawTable.ignored_columns`.  `option` is the command-line option
    that named the file (a file that cannot be read names it); `max_rows` the most data
    rows taken (None: any number; a speed profile's steps are no samples).  The separator
    and decimal mark as the module says.
    """
    file = str(path)
    keep = keep or ALL_COLUMNS.__contains__
    text = read_input_text(path, column=option)

    # Split on '\n' only: editors number lines that way (str.splitlines would also
    # break on form feeds and Unicode separators).
    lines = [ln.rstrip("\r") for ln in text.split("\n")]
    metadata: dict[str, str] = {}
    header: list[str] | None = None
    header_line = 0
    hint: tuple[str, int] | None = None  # a `sep=` line's separator and line
    separator = ","
    data_lines: list[str] = []
    data_numbers: list[int] = []
    for number, line in enumerate(lines, start=1):
        stripped = line.strip()
        if not stripped or is_blank_record(
                stripped, "".join(SEPARATORS) if header is None else separator):
            continue
        if stripped.startswith("#"):
            if header is None and ":" in stripped:
                key, _, value = stripped[1:].partition(":")
                if key.strip():
                    metadata[key.strip()] = value.strip()
            continue
        if header is None:
            given = separator_hint(line, file, number)
            if given is not None:
                hint = (given, number)
                continue
            separator = header_separator(line, hint, file, number)
            header = without_trailing_blanks(
                [name.strip() for name in next(csv_records([line], file, [number], separator))])
            header_line = number
            continue
        data_lines.append(line)
        data_numbers.append(number)

    if header is None:
        raise InputError("empty file: no header row and no data", file=file)
    check_header(header, file, header_line, separator, hint)
    if not data_lines:
        raise InputError("no data rows after the header", file=file, row=header_line,
                         row_unit=LINE)
    if max_rows is not None and len(data_lines) > max_rows:
        raise InputError(f"{len(data_lines)} data rows; a run may hold at most {max_rows} "
                         "samples (resample it)", file=file, row=data_numbers[max_rows],
                         row_unit=LINE)
    if separator != ",":
        # a spreadsheet pads the metadata lines of a `;` file as it does its rows
        metadata = {key: value.rstrip(separator + " ") for key, value in metadata.items()}

    known = [(i, name) for i, name in enumerate(header) if keep(name)]
    ignored = [name for name in header if not keep(name)]
    values = np.full((len(data_lines), len(known)), np.nan)
    marks = DecimalMarks(file) if separator != "," else None
    for k, fields in enumerate(csv_records(data_lines, file, data_numbers, separator)):
        line = data_numbers[k]
        fields = without_trailing_blanks(fields, len(header))
        if len(fields) != len(header):
            raise InputError(f"expected {len(header)} fields as in the header, found "
                             f"{len(fields)}", file=file, row=line, row_unit=LINE)
        if [f.strip() for f in fields] == header:
            # two logs joined one after the other: "cannot read 'time_s' as a number"
            raise InputError(f"the header again (line {header_line} holds it): files joined "
                             "one after the other? keep the first header only", file=file,
                             row=line, row_unit=LINE)
        row = values[k]
        for j, (i, name) in enumerate(known):
            try:
                row[j] = (parse_cell(fields[i], file, line, name, LINE) if marks is None
                          else marks.read(fields[i], line, name))
            except InputError as exc:
                if k == 0 and not any(is_number(f, marks is not None) for f in fields):
                    raise InputError(f"{exc.reason}; no cell of line {line} is a number: a "
                                     "units row? remove it (the names carry the units: "
                                     "time_s, T1_C)", file=file, row=line, column=name,
                                     row_unit=LINE) from None
                raise
    dialect = ""
    if marks is not None:
        marks.check_undecided()
        dialect = f"{SEPARATORS[separator]}-separated" + (
            ", with decimal commas" if marks.read_commas() else "")
    columns = {name: values[:, j].copy() for j, (_, name) in enumerate(known)}
    return RawTable(file=file, metadata=metadata, columns=columns,
                    rows=np.asarray(data_numbers, dtype=np.int64), header_row=header_line,
                    ignored_columns=ignored, row_unit=LINE, dialect=dialect)


def separator_hint(line: str, file: str, number: int) -> str | None:
    """The separator named by a `sep=,` line above the header, which Excel reads as the
    separator to use (some exports write it), or None for another line.  A separator
    other than `,`, `;` or a tab is an `InputError`.  Before, the hint was taken for the
    header ("line 2: expected 1 fields as in the header, found 12").  `line` as read:
    only its spaces are stripped, so that a tab named there (`sep=\t`) is read, not
    taken for the header "sep=" (a missing required column)."""
    line = line.strip(" ")
    if len(line) != 5 or line[:4].lower() != "sep=":
        return None
    if line[4] not in SEPARATORS:
        raise InputError(f"this 'sep=' line says the file is separated by {line[4]!r}; "
                         "separate it by commas, semicolons or tabs", file=file, row=number,
                         row_unit=LINE)
    return line[4]


def header_separator(line: str, hint: tuple[str, int] | None, file: str, number: int) -> str:
    """The separator of a file whose header is `line` (line `number`): the one a `sep=`
    line named (`hint`: separator and line), else a comma unless the header read so is
    one column holding `;` or tabs (see the module); both is an `InputError`."""
    if hint is not None:
        return hint[0]
    header = without_trailing_blanks(
        [name.strip() for name in next(csv_records([line], file, [number]))])
    if len(header) != 1:
        return ","
    held = [s for s in (";", "\t") if s in header[0]]
    if len(held) > 1:
        raise InputError("the header holds both ';' and tabs: which separates the columns? "
                         "say it in a line 'sep=;' (or 'sep=' and a tab) above the header",
                         file=file, row=number, row_unit=LINE)
    return held[0] if held else ","


def is_blank_record(line: str, separators: str = ",") -> bool:
    """True for a line of `separators` and blanks only (",,,,", ";;;;" in a `;` file): the
    rows a spreadsheet writes below the data where its used range runs on, read past as
    blank lines are; they hold no value to lose.  Above the header, where the separator
    is still unknown, any of `SEPARATORS`."""
    for separator in separators:
        line = line.replace(separator, "")
    return not line.strip()


def without_trailing_blanks(fields: list[str], width: int | None = None) -> list[str]:
    """`fields` without the blank fields after the first `width` (default: after the last
    non-blank one): the trailing separators a spreadsheet writes to fill its used range
    ("T5_C,coolant_C,,," and "24.1,23.0,,,").  Blanks inside the row stay."""
    if width is None:
        width = len(fields)
        while width and not fields[width - 1].strip():
            width -= 1
    if len(fields) > width and not any(f.strip() for f in fields[width:]):
        return fields[:width]
    return fields


def check_header(header: list[str], file: str, line: int, separator: str = ",",
                 hint: tuple[str, int] | None = None) -> None:
    """InputError unless `header` (row `line`) is separated as `separator` says and names
    each column once, none empty: a name given twice would leave which column is read to
    the reader."""
    check_separated(header, file, line, separator, hint)
    for position, name in enumerate(header, start=1):
        if not name:
            raise InputError(f"header field {position} is empty", file=file, row=line,
                             row_unit=LINE)
        if header.count(name) > 1:
            raise InputError("column appears twice in the header", file=file, row=line,
                             column=name, row_unit=LINE)


def check_separated(header: list[str], file: str, line: int, separator: str,
                    hint: tuple[str, int] | None) -> None:
    """Refuse a header that is one column holding another separator than the `sep=` line
    (`hint`: separator and line) named: read so, it would fail as a missing `time_s`."""
    if len(header) != 1 or hint is None:
        return
    for other in SEPARATORS:
        if other != separator and other in header[0]:
            raise InputError(f"the header is one column holding {other!r}: line {hint[1]} "
                             f"says the file is separated by {separator!r}; correct that "
                             "line or remove it", file=file, row=line, row_unit=LINE)


_AMBIGUOUS = re.compile(r"[+-]?[1-9][0-9]{0,2}[.,][0-9]{3}")
"""A number whose one mark reads as a thousands separator as well as a decimal one."""


_MARK_NAMES = {",": "comma", ".": "point"}


@dataclass
class DecimalMarks:
    """The decimal marks of a `;` or tab file's number cells, noted as they are read: the
    first cell that shows each mark to be a decimal one (`shown`), and the first that one
    mark leaves ambiguous (`undecided`), each as (line, column, cell).  See the module."""

    file: str
    shown: dict[str, tuple[int, str, str]] = field(default_factory=dict)
    undecided: dict[str, tuple[int, str, str]] = field(default_factory=dict)

    def read(self, cell: str, line: int, column: str) -> float:
        """`cell` as a number (`parse_cell`, a comma read as a decimal mark), its mark
        noted; InputError for a cell with thousands separators."""
        try:
            value = parse_cell(cell, self.file, line, column, LINE, decimal_comma=True)
        except InputError:
            if is_grouped(cell):
                raise InputError(f"cannot read {cell.strip()!r} as a number (thousands "
                                 "separators? write numbers without them: 9000, 22,5)",
                                 file=self.file, row=line, column=column,
                                 row_unit=LINE) from None
            raise
        # a number read holds one mark at most
        mark = "," if "," in cell else "." if "." in cell else None
        if mark is not None and not (mark in self.shown and mark in self.undecided):
            text = cell.strip()
            # a temperature is never grouped: '22,125' in a *_C column is 22.125 °C (a
            # logger writing three decimals had every cell refused, the file unreadable)
            ambiguous = _AMBIGUOUS.fullmatch(text) and not column.endswith("_C")
            found = self.undecided if ambiguous else self.shown
            if mark not in found:
                found[mark] = (line, column, text)
                self.check_undecided(final=False)  # told where it is decided, in file order
        return value

    def read_commas(self) -> bool:
        """Whether a cell was read with a decimal comma."""
        return "," in self.shown or "," in self.undecided

    def check_undecided(self, final: bool = True) -> None:
        """InputError at the first cell one mark left ambiguous that the file's other
        numbers do not decide (their marks: that one and not the other): once read
        (`final`), or as soon as another mark is shown a decimal one."""
        refused = [place for mark, place in self.undecided.items()
                   if set(self.shown) - {mark} or (final and mark not in self.shown)]
        if not refused:
            return
        line, column, text = min(refused)
        mark = "," if "," in text else "."
        lead, _, fraction = text.partition(mark)
        writes = "." if set(self.shown) == {"."} else ","
        shown = " and ".join(f"decimal {_MARK_NAMES[m]}s (line {at}, column {name!r}: "
                             f"{cell!r})" for m, (at, name, cell) in sorted(self.shown.items()))
        evidence = (f"the file's other numbers have {shown}" if shown else
                    "no other number in the file has a decimal mark to tell")
        decimal = f"{lead}{writes}{fraction.rstrip('0') or '0'}"
        if decimal == text:  # the refused cell itself: a fourth decimal decides
            decimal = f"{lead}{writes}{fraction}0"
        raise InputError(f"cannot read {text!r} as a number: {lead}{fraction} with a "
                         f"thousands separator, or {float(text.replace(',', '.')):g} with a "
                         f"decimal {_MARK_NAMES[mark]}? {evidence}; write "
                         f"{lead}{fraction} or {decimal}",
                         file=self.file, row=line, column=column, row_unit=LINE)


def csv_records(lines: list[str], file: str, numbers: list[int],
                separator: str = ",") -> Iterator[list[str]]:
    """CSV records of `lines` (`numbers`: their lines in `file`) separated by `separator`,
    one per line: a quoted cell may not span lines (the csv module would join `"1` and
    `2"` into 12), and csv's own errors name their line."""
    reader = csv.reader(lines, delimiter=separator)
    k = 0
    while True:
        try:
            fields = next(reader)
        except StopIteration:
            return
        except csv.Error as exc:
            line = numbers[min(reader.line_num, len(numbers)) - 1]
            raise InputError(f"not a readable CSV line ({exc})", file=file, row=line,
                             row_unit=LINE) from None
        if reader.line_num != k + 1:
            raise InputError("a quoted cell runs over several lines", file=file,
                             row=numbers[k], row_unit=LINE)
        k += 1
        yield fields


def _format(value: float, fmt: str) -> str:
    return "nan" if math.isnan(value) else fmt % value


def write_csv_table(
    path: str | os.PathLike[str],
    columns: Mapping[str, np.ndarray],
    metadata: Mapping[str, object] | None = None,
    formats: Mapping[str, str] | None = None,
) -> None:
    """Write columns (equal-length 1-D arrays) as a recorded-run CSV, atomically.

    Metadata become leading `# key: value` lines; NaN is written as `nan`.  `formats`
    maps a column to a printf format (default `%.4f`, time `%.3f`, speed `%.1f`).
    """
    formats = {"time_s": "%.3f", "speed_rpm": "%.1f", **(formats or {})}
    names = list(columns)
    arrays = [np.asarray(columns[name], dtype=float) for name in names]
    if len({a.shape for a in arrays}) > 1 or any(a.ndim != 1 for a in arrays):
        raise ValueError("columns must be 1-D arrays of equal length")
    # the file is closed before atomic_target moves it into place
    with atomic_target(path) as tmp, open(tmp, "w", newline="") as out:
        for key, value in (metadata or {}).items():
            out.write(f"# {key}: {value}\n")
        out.write(",".join(names) + "\n")
        fmts = [formats.get(name, "%.4f") for name in names]
        for row in zip(*arrays, strict=True):
            out.write(",".join(_format(v, f) for v, f in zip(row, fmts, strict=True)) + "\n")
