"""Recorded runs as CSV: `# key: value` metadata lines, one header row, one row per sample.

Line numbers are counted as an editor shows them (1-based, every physical line counts,
metadata and blank lines included), so an error message points at the right place.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from twin.atomic import atomic_target
from twin.errors import InputError
from twin.runs.schema import ALL_COLUMNS
from twin.runs.table import RawTable

_MISSING = {"", "nan", "na", "n/a", "null", "none"}


def _parse_number(cell: str, file: str, line: int, column: str) -> float:
    text = cell.strip()
    if text.lower() in _MISSING:
        return math.nan
    try:
        value = float(text)
    except ValueError:
        raise InputError(f"cannot read {cell!r} as a number", file=file, row=line,
                         column=column) from None
    if math.isinf(value):
        raise InputError(f"{cell!r} is not a finite number", file=file, row=line, column=column)
    return value


def read_csv_table(path: str | os.PathLike[str]) -> RawTable:
    """Read a CSV recorded run into a `RawTable` (no validation beyond parsing)."""
    file = str(path)
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read file: {exc.strerror or exc}", file=file) from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError("not UTF-8 text", file=file, row=line) from None

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
        if not stripped:
            continue
        if stripped.startswith("#"):
            if header is None and ":" in stripped:
                key, _, value = stripped[1:].partition(":")
                if key.strip():
                    metadata[key.strip()] = value.strip()
            continue
        if header is None:
            header = [name.strip() for name in next(csv.reader([line]))]
            header_line = number
            continue
        data_lines.append(line)
        data_numbers.append(number)

    if header is None:
        raise InputError("empty file: no header row and no data", file=file)
    for position, name in enumerate(header, start=1):
        if not name:
            raise InputError(f"header field {position} is empty", file=file, row=header_line)
        if header.count(name) > 1:
            raise InputError("column appears twice in the header", file=file, row=header_line,
                             column=name)
    if not data_lines:
        raise InputError("no data rows after the header", file=file, row=header_line)

    known = [(i, name) for i, name in enumerate(header) if name in ALL_COLUMNS]
    ignored = [name for name in header if name not in ALL_COLUMNS]
    values = np.full((len(data_lines), len(known)), np.nan)
    reader = csv.reader(data_lines)
    for k, fields in enumerate(reader):
        line = data_numbers[min(reader.line_num, len(data_numbers)) - 1]
        if len(fields) != len(header):
            raise InputError(f"expected {len(header)} fields as in the header, found "
                             f"{len(fields)}", file=file, row=line)
        row = values[k]
        for j, (i, name) in enumerate(known):
            row[j] = _parse_number(fields[i], file, line, name)
    n = k + 1
    columns = {name: values[:n, j].copy() for j, (_, name) in enumerate(known)}
    return RawTable(file=file, metadata=metadata, columns=columns,
                    rows=np.asarray(data_numbers[:n], dtype=np.int64), header_row=header_line,
                    ignored_columns=ignored)


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
