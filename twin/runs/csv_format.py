"""Recorded runs as CSV: `# key: value` metadata lines, one header row, one row per sample.

Line numbers are counted as an editor shows them (1-based, every physical line counts,
metadata and blank lines included), so an error message points at the right place.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Callable, Iterator, Mapping

import numpy as np

from twin.errors import InputError
from twin.io.atomic import atomic_target
from twin.paths import read_input_text
from twin.runs.schema import ALL_COLUMNS, MAX_SAMPLES
from twin.runs.table import RawTable, is_number, parse_cell

LINE = "line"
"""What an error calls a place in a CSV file (`RawTable.row_unit`): its line, numbered as an
editor numbers them, not a data row (`bad.csv, line 4, column 'T1_C'`)."""


def read_csv_table(path: str | os.PathLike[str],
                   keep: Callable[[str], bool] | None = None, *,
                   option: str | None = None, max_rows: int | None = MAX_SAMPLES) -> RawTable:
    """Read a CSV recorded run into a `RawTable` (no validation beyond parsing).

    `keep(name)` says which columns to read (default: the recorded-run schema); the
    others are listed in `RawTable.ignored_columns`.  `option` is the command-line option
    that named the file (a file that cannot be read names it); `max_rows` the most data
    rows taken (None: any number; a speed profile's steps are no samples).
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
    data_lines: list[str] = []
    data_numbers: list[int] = []
    for number, line in enumerate(lines, start=1):
        stripped = line.strip()
        if not stripped or is_blank_record(stripped):
            continue
        if stripped.startswith("#"):
            if header is None and ":" in stripped:
                key, _, value = stripped[1:].partition(":")
                if key.strip():
                    metadata[key.strip()] = value.strip()
            continue
        if header is None and is_separator_hint(line, file, number):
            continue
        if header is None:
            header = without_trailing_blanks(
                [name.strip() for name in next(csv_records([line], file, [number]))])
            header_line = number
            continue
        data_lines.append(line)
        data_numbers.append(number)

    if header is None:
        raise InputError("empty file: no header row and no data", file=file)
    check_header(header, file, header_line)
    if not data_lines:
        raise InputError("no data rows after the header", file=file, row=header_line,
                         row_unit=LINE)
    if max_rows is not None and len(data_lines) > max_rows:
        raise InputError(f"{len(data_lines)} data rows; a run may hold at most {max_rows} "
                         "samples (resample it)", file=file, row=data_numbers[max_rows],
                         row_unit=LINE)

    known = [(i, name) for i, name in enumerate(header) if keep(name)]
    ignored = [name for name in header if not keep(name)]
    values = np.full((len(data_lines), len(known)), np.nan)
    for k, fields in enumerate(csv_records(data_lines, file, data_numbers)):
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
                row[j] = parse_cell(fields[i], file, line, name, LINE)
            except InputError as exc:
                if k == 0 and not any(is_number(f) for f in fields):
                    raise InputError(f"{exc.reason}; no cell of line {line} is a number: a "
                                     "units row? remove it (the names carry the units: "
                                     "time_s, T1_C)", file=file, row=line, column=name,
                                     row_unit=LINE) from None
                raise
    columns = {name: values[:, j].copy() for j, (_, name) in enumerate(known)}
    return RawTable(file=file, metadata=metadata, columns=columns,
                    rows=np.asarray(data_numbers, dtype=np.int64), header_row=header_line,
                    ignored_columns=ignored, row_unit=LINE)


def is_separator_hint(line: str, file: str, number: int) -> bool:
    """True for the `sep=,` line above the header that Excel reads as the separator to use
    (some exports write it): read past.  Another separator there is an `InputError`, in the
    words of `check_comma_separated`.  The hint was taken for the header ("line 2: expected
    1 fields as in the header, found 12").  `line` as read: only its spaces are stripped,
    so that a tab named there (`sep=\t`, a tab-separated export) is told, not read as the
    header "sep=" (a missing required column)."""
    line = line.strip(" ")
    if len(line) != 5 or line[:4].lower() != "sep=":
        return False
    if line[4] != ",":
        raise InputError(f"the first line says the file is separated by {line[4]!r}; write "
                         "it comma-separated, with decimal points", file=file, row=number,
                         row_unit=LINE)
    return True


def is_blank_record(line: str) -> bool:
    """True for a line of separators and blanks only (",,,,"): the rows a spreadsheet writes
    below the data where its used range runs on, read past as blank lines are; they hold
    no value to lose."""
    return not line.replace(",", "").strip()


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


def check_header(header: list[str], file: str, line: int) -> None:
    """InputError unless `header` (row `line`) is comma-separated and names each column once,
    none empty: a name given twice would leave which column is read to the reader."""
    check_comma_separated(header, file, line)
    for position, name in enumerate(header, start=1):
        if not name:
            raise InputError(f"header field {position} is empty", file=file, row=line,
                             row_unit=LINE)
        if header.count(name) > 1:
            raise InputError("column appears twice in the header", file=file, row=line,
                             column=name, row_unit=LINE)


def check_comma_separated(header: list[str], file: str, line: int) -> None:
    """Refuse a header that is one column holding `;` or tabs: a logger's export with
    another separator (often with decimal commas), which would otherwise read as one
    column and fail as a missing `time_s`."""
    if len(header) == 1:
        for separator in (";", "\t"):
            if separator in header[0]:
                raise InputError(f"the header is one column holding {separator!r}: the file is "
                                 f"separated by {separator!r}; write it comma-separated, with "
                                 "decimal points", file=file, row=line, row_unit=LINE)


def csv_records(lines: list[str], file: str, numbers: list[int]) -> Iterator[list[str]]:
    """CSV records of `lines` (`numbers`: their lines in `file`), one per line: a quoted
    cell may not span lines (the csv module would join `"1` and `2"` into 12), and csv's
    own errors name their line."""
    reader = csv.reader(lines)
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
