"""Speed profile CSV of the emulator: `time_s, speed_rpm[, ambient_C]`.

A speed (and ambient, if given) holds until the next row; the first row is at 0 s (the
run's start).  `#` lines are comments.  Rows are numbered as lines in an editor.

Why the first row must be at 0 s: a profile starting later (`60,9000`) was read as 9000 rpm
from the start, the first row's value held back to 0 s without a word, where its writer may
as well have meant a spindle standing until then.  Asked to say which, the error names the
row.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from twin.plant.timetable import StepTable
from twin.runs.csv_format import read_csv_table
from twin.runs.schema import AMBIENT, SPEED, TIME
from twin.runs.validate import (
    check_operating_temperature,
    check_speed_sign,
    checked_time,
    complete_column,
    required_column,
)

PROFILE_COLUMNS = (TIME, SPEED, AMBIENT)
"""The columns a speed profile sets; any other is read over (and named by the command)."""


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
    row_unit: str = "line"
    """What an error calls a place of `rows` (the CSV reader's word, `RawTable.row_unit`)."""


def read_speed_profile(path: str | os.PathLike[str]) -> SpeedProfile:
    """Read a speed profile; errors name the file, line and column.

    Read and checked by the recorded-run reader and checks (`twin.runs`), so a problem
    both files can have (an empty file, a missing column, a cell that is no number, time
    out of order, a negative speed, an ambient outside the modelled range) is told in the
    same words; unlike a run, a profile may have no gap (no repair fills a step in) and
    no time given twice (a step lasts a while).
    """
    table = read_csv_table(path, PROFILE_COLUMNS.__contains__, option="--profile",
                           max_rows=None)
    required_column(table, TIME)
    required_column(table, SPEED)
    time = complete_column(table, TIME, "time")
    if time[0] != 0:
        raise table.error(f"the first row must be at 0 s, the run's start (got {time[0]:g} s): "
                          "add a row at 0 s with the speed until then (0 rpm: standing)",
                          table.rows[0], TIME)
    checked_time(table, repeats=False)
    speed = complete_column(table, SPEED)
    check_speed_sign(table)
    ambient = None
    if AMBIENT in table.columns:
        values = complete_column(table, AMBIENT)
        check_operating_temperature(table.file, table.rows, AMBIENT, values,
                                    row_unit=table.row_unit)
        ambient = StepTable(time, values)
    return SpeedProfile(StepTable(time, speed), ambient,
                        tuple(int(row) for row in table.rows), tuple(table.ignored_columns),
                        table.row_unit)


def steps_after(profile: SpeedProfile, duration_s: float) -> list[tuple[int | None, float]]:
    """(file line, time) of each step that starts after a run of `duration_s` ends, which
    the emulator never reaches (a line of None for a profile not read from a file).

    Told, not refused (a scenario's fault after the end is refused): a fault placed after
    the end is a mistake in a file written for that run, while a profile longer than the
    run is a legitimate reuse (a shift's profile emulated for its first minutes).  A step
    at the end itself is reached (its last sample), as a fault at the end is."""
    times = profile.speed_rpm.time_s
    return [(profile.rows[k] if profile.rows else None, float(t))
            for k, t in enumerate(times) if t > duration_s]
