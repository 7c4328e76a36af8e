"""Hard errors of a recorded run: problems no repair can honestly fix.

Each raises `InputError` naming the file, the line (a CSV file's, as an editor numbers
them) or row (a Parquet file's data row; `RawTable.row_unit`) and the column.  Anything a
repair can fix (duplicates, dropouts, spikes, stuck or noisy sensors) is left to
`twin.runs.quality`.  The column and time checks (`required_column`,
`column_with_values`, `complete_column`, `checked_time`) serve the drift data
(`twin.drift.data`) and the emulator's speed profile (`twin.plant.profile`) too, as do the
speed and temperature checks (`check_speed_sign`, `check_speed_limit`,
`check_operating_temperature`), so a file refused by several commands is refused in the
same words.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from twin.contract import OPERATING_TEMPERATURE_C, WINDOW_S
from twin.errors import InputError
from twin.runs.schema import (
    AMBIENT,
    CELSIUS_COLUMNS,
    COOLANT,
    MAX_DURATION_S,
    MAX_SAMPLE_INTERVAL_S,
    REQUIRED,
    SPEED,
    TEMPERATURES,
    TIME,
)
from twin.runs.table import RawTable

KELVIN_MEDIAN_C = 200.0
"""A °C column whose median exceeds this is Kelvin: no spindle part runs at 200 °C."""
FAHRENHEIT_AIR_RANGE_C = (OPERATING_TEMPERATURE_C[1], 130.0)
"""Ambient air or coolant with a median above the first (the plausible range's top) and up
to the second is Fahrenheit: 45–130 °F is 7–54 °C, any room or coolant logged in °F."""


HEADER_NAMES_TOLD = 12
"""At most this many of a file's column names are listed beside a missing column."""


def required_column(table: RawTable, name: str) -> np.ndarray:
    """The column `name`, or InputError at the header if the file lacks it, saying what
    the header has instead: a logger's `TIME_S` or `timestamp` was told only as a missing
    `time_s`."""
    if name not in table.columns:
        raise table.error(f"missing required column {header_hint(table, name)}",
                          table.header_row, name)
    return table.columns[name]


def header_hint(table: RawTable, name: str = "") -> str:
    """'(the header has …)': the file's column names, or the one spelt like `name` but for
    its case."""
    header = [*table.columns, *table.ignored_columns]
    near = [h for h in header if h.strip().lower() == name.lower()]
    if near:
        return f"(the header has {near[0]!r}; column names are case-sensitive)"
    told = ", ".join(header[:HEADER_NAMES_TOLD])
    return f"(the header has {told}{', …' if len(header) > HEADER_NAMES_TOLD else ''})"


def column_with_values(table: RawTable, name: str) -> np.ndarray:
    """The column `name` (`required_column`), or InputError if no row holds a value."""
    values = required_column(table, name)
    if np.isnan(values).all():
        raise table.error("column has no values", table.rows[0], name)
    return values


def complete_column(table: RawTable, name: str, what: str = "value") -> np.ndarray:
    """The column `name` (`required_column`), or InputError at the first row without a
    value (`what` is missing): for the columns no repair may fill in."""
    values = required_column(table, name)
    missing = np.flatnonzero(np.isnan(values))
    if missing.size:
        raise table.error(f"{what} is missing", table.rows[missing[0]], name)
    return values


def checked_time(table: RawTable, *, repeats: bool = True) -> np.ndarray:
    """The time column, every row holding one, in time order; a time repeating the one
    before is refused unless `repeats` (a run merges such samples, drift features and a
    speed profile's steps do not)."""
    time = complete_column(table, TIME, "time")
    step = np.diff(time)
    wrong = np.flatnonzero(step < 0 if repeats else step <= 0)
    if wrong.size:
        i = int(wrong[0])
        where = f"{table.row_unit} {table.rows[i]}"
        # to 15 digits: a logger's Unix time (1.7e9 s) read the same at both rows as %g
        what = (f"time goes back from {time[i]:.15g} s ({where}) to {time[i + 1]:.15g} s; "
                "samples must be in time order" if step[i] < 0 else
                f"time {time[i]:.15g} s repeats that of {where}; each sample needs a later "
                "time than the one before")
        raise table.error(what, table.rows[i + 1], TIME)
    return time


def check_structure(table: RawTable) -> None:
    """Required columns present, each with values (but for dead thermocouples, while one
    is left), time readable and non-decreasing."""
    for name in REQUIRED:
        required_column(table, name)
    for name in REQUIRED:
        # a thermocouple with no value in the whole run is a dead channel, which the
        # repair excludes; the run is refused only when no temperature sensor is left
        if name not in TEMPERATURES:
            column_with_values(table, name)
    if all(np.isnan(table.columns[name]).all() for name in TEMPERATURES):
        raise table.error("no temperature sensor has a value (T1_C..T5_C all empty)",
                          table.rows[0], TEMPERATURES[0])
    checked_time(table)


def check_values(table: RawTable) -> None:
    """Sample rate, duration, speed sign and temperature units."""
    time = table.columns[TIME]
    unique_time = np.unique(time)
    duration = float(unique_time[-1] - unique_time[0])
    if duration < 2 * WINDOW_S:
        raise table.error(
            f"the run lasts {duration:g} s; the twin needs at least two {WINDOW_S:g} s "
            f"windows ({2 * WINDOW_S:g} s)", table.rows[-1], TIME)
    if duration > MAX_DURATION_S:
        i = int(np.flatnonzero(time - time[0] > MAX_DURATION_S)[0])
        raise table.error(
            f"time {time[i]:.15g} s lies more than {MAX_DURATION_S:g} s after the first sample; "
            f"a run may last at most {MAX_DURATION_S / 3600:g} h", table.rows[i], TIME)
    interval = float(np.median(np.diff(unique_time)))
    if interval > MAX_SAMPLE_INTERVAL_S:
        raise table.error(
            f"median sample interval {interval:g} s is longer than {MAX_SAMPLE_INTERVAL_S:g} s "
            "(at least one sample per 10 s is needed)", column=TIME)

    check_speed_sign(table)
    for name in CELSIUS_COLUMNS:
        if name in table.columns:
            _check_celsius(table, name)


def check_speed_sign(table: RawTable) -> None:
    """InputError at the first negative speed (0 is a stop; there is no reverse)."""
    speed = table.columns[SPEED]
    negative = np.flatnonzero(speed < 0)
    if negative.size:
        i = int(negative[0])
        raise table.error(f"negative speed {speed[i]:g} rpm", table.rows[i], SPEED)


def _check_celsius(table: RawTable, name: str) -> None:
    values = table.columns[name]
    finite = values[~np.isnan(values)]
    if finite.size == 0:
        return
    below = np.flatnonzero(values < -273.15)
    if below.size:
        i = int(below[0])
        raise table.error(f"{values[i]:g} °C is below absolute zero", table.rows[i], name)
    median = float(np.median(finite))
    first = int(np.flatnonzero(~np.isnan(values))[0])
    row = table.rows[first]
    if median > KELVIN_MEDIAN_C:
        raise table.error(
            f"values look like Kelvin (median {median:.2f}); the column must be in °C "
            f"(subtract 273.15)", row, name)
    lo, hi = FAHRENHEIT_AIR_RANGE_C
    if name in (AMBIENT, COOLANT) and lo < median <= hi:
        # the first row past the °C range: where a logger switched units mid-run
        above = int(np.flatnonzero(values > lo)[0])
        raise table.error(
            f"values look like Fahrenheit (median {median:.1f}, an implausible air/coolant "
            "temperature in °C); the column must be in °C", table.rows[above], name)
    if name in TEMPERATURES:
        # A run starts near ambient; a sensor reading 1.8·ambient + 32 at the start,
        # far above the ambient, is logging Fahrenheit.
        ambient = table.columns[AMBIENT]
        a0 = np.nanmedian(ambient[:5]) if np.isfinite(ambient[:5]).any() else np.nan
        t0 = float(np.median(finite[:5]))
        if np.isfinite(a0) and t0 > a0 + 25.0 and abs(t0 - (1.8 * a0 + 32.0)) < 2.0:
            raise table.error(
                f"values look like Fahrenheit (starts at {t0:.1f} with ambient {a0:.1f} °C "
                f"= {1.8 * a0 + 32:.1f} °F); the column must be in °C", row, name)


def check_operating_temperatures(file: str, rows: np.ndarray, columns: dict[str, np.ndarray],
                                 *, row_unit: str) -> None:
    """Ambient and coolant within the twin's envelope (`check_operating_temperature`).

    Checked on the repaired values (a spike the repair removes is no error) so that a
    replay never meets a value it cannot simulate; the error names the file's line or row
    (`row_unit`, as `RawTable.row_unit`).  The speed's limit is checked on the speeds as
    written (`check_speed_limit`): its repairs only put a neighbour's speed in a sample.
    """
    for name in (AMBIENT, COOLANT):
        if name in columns:
            check_operating_temperature(file, rows, name, columns[name], row_unit=row_unit)


def check_speed_limit(file: str | None, rows: Sequence[int] | np.ndarray | None,
                      speed: np.ndarray, max_speed_rpm: float, *, row_unit: str) -> None:
    """InputError at the first speed above the spindle's limit (`rows`: the file line or
    row of each value, as `row_unit` calls it; None if not read from a file)."""
    over = np.flatnonzero(np.asarray(speed) > max_speed_rpm)
    if over.size:
        i = int(over[0])
        raise InputError(f"speed {speed[i]:g} rpm exceeds the spindle's limit "
                         f"{max_speed_rpm:g} rpm", file=file,
                         row=None if rows is None else int(rows[i]), column=SPEED,
                         row_unit=row_unit)


def check_operating_temperature(file: str, rows: np.ndarray, name: str,
                                values: np.ndarray, *, row_unit: str) -> None:
    """InputError at the first air or coolant temperature of column `name` outside the
    range the twin models (`twin.contract.OPERATING_TEMPERATURE_C`); `rows` and
    `row_unit` as for `check_speed_limit`."""
    lo, hi = OPERATING_TEMPERATURE_C
    outside = np.flatnonzero((values < lo) | (values > hi))
    if outside.size:
        i = int(outside[0])
        raise InputError(f"{values[i]:g} °C is outside the {lo:g}..{hi:g} °C the twin "
                         "models", file=file, row=int(rows[i]), column=name,
                         row_unit=row_unit)
