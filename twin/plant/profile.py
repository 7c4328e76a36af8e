"""Speed profile CSV of the emulator: `time_s, speed_rpm[, ambient_C]`.

A speed (and ambient, if given) holds until the next row; the first row is at 0 s (the
run's start).  `#` lines are comments.  Rows are numbered as lines in an editor.

Why the first row must be at 0 s: a profile starting later (`60,9000`) was read as 9000 rpm
from the start, the first row's value held back to 0 s without a word, where its writer may
as well have meant a spindle standing until then.  Asked to say which, the error names the
row.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from twin.contract import OPERATING_TEMPERATURE_C
from twin.errors import InputError
from twin.paths import read_input_text
from twin.plant.timetable import StepTable
from twin.runs.csv_format import check_header, csv_records, without_trailing_blanks
from twin.runs.table import parse_cell


@dataclass(frozen=True)
class SpeedProfile:
    speed_rpm: StepTable
    ambient_C: StepTable | None = None
    rows: tuple[int, ...] = ()
    """The file line of each step (so a check made later, the spindle's speed limit, can
    name it); empty for a profile not read from a file."""
    ignored: tuple[str, ...] = ()
    """Header columns the profile does not read (a recorded run's T1_C.., a coolant_C or a
    misspelt ambient), for the command to tell."""

    def row_of(self, step: int) -> int | None:
        """The file line of step `step`, or None."""
        return self.rows[step] if step < len(self.rows) else None


def read_speed_profile(path: str | os.PathLike[str]) -> SpeedProfile:
    """Read a speed profile; errors name the file, line and column."""
    file = str(path)
    lines = read_input_text(path, column="--profile").split("\n")
    header: list[str] | None = None
    header_line = 0
    rows: list[tuple[int, list[str]]] = []
    for number, line in enumerate(lines, start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        fields = [f.strip() for f in next(csv_records([line], file, [number]))]
        if header is None:
            fields = without_trailing_blanks(fields)
            check_header(fields, file, number)
            header, header_line = fields, number
        else:
            rows.append((number, without_trailing_blanks(fields, len(header))))
    if header is None:
        raise InputError("empty speed profile", file=file)
    for name in ("time_s", "speed_rpm"):
        if name not in header:
            raise InputError("missing required column", file=file, row=header_line, column=name)
    wanted = ["time_s", "speed_rpm"] + (["ambient_C"] if "ambient_C" in header else [])
    if not rows:
        raise InputError("no rows after the header", file=file, row=header_line)
    values = np.empty((len(rows), len(wanted)))
    for k, (number, fields) in enumerate(rows):
        if len(fields) != len(header):
            raise InputError(f"expected {len(header)} fields, found {len(fields)}", file=file,
                             row=number)
        for j, name in enumerate(wanted):
            cell = fields[header.index(name)]
            value = parse_cell(cell, file, number, name)
            if not math.isfinite(value):
                raise InputError(f"{cell!r} is not a finite number", file=file, row=number,
                                 column=name)
            values[k, j] = value
        time, speed = values[k, 0], values[k, 1]
        if k == 0 and time != 0:
            raise InputError(f"the first row must be at 0 s, the run's start (got {time:g} s): "
                             "add a row at 0 s with the speed until then (0 rpm: standing)",
                             file=file, row=number, column="time_s")
        if time < 0:
            raise InputError("time must be ≥ 0", file=file, row=number, column="time_s")
        if k and time <= values[k - 1, 0]:
            raise InputError("time must increase from row to row", file=file, row=number,
                             column="time_s")
        if speed < 0:
            raise InputError(f"negative speed {speed:g} rpm", file=file, row=number,
                             column="speed_rpm")
        low, high = OPERATING_TEMPERATURE_C
        if len(wanted) == 3 and not low <= values[k, 2] <= high:
            raise InputError(f"ambient {values[k, 2]:g} °C is outside the {low:g}..{high:g} °C "
                             "the twin models", file=file, row=number, column="ambient_C")
    ambient = StepTable(values[:, 0], values[:, 2]) if len(wanted) == 3 else None
    return SpeedProfile(StepTable(values[:, 0], values[:, 1]), ambient,
                        tuple(number for number, _ in rows),
                        tuple(name for name in header if name not in wanted))
