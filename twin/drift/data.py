"""Drift data: time, speed, temperature and displacement columns of one or more files.

DESIGN.md, "Data-driven drift models": CSV or Parquet (`# key: value` lines allowed) with
`time_s`, optional `speed_rpm`, any number of temperature columns `*_C` and displacement
columns `*_um`.  The files are read and their columns and time checked with the
recorded-run readers and checks (`twin.runs`), so a file both refuse is refused in the
same words, at the same line and column.  Every file is its own continuous
series (a *segment*): features restart at its first row.

Rows repeating an earlier row exactly are dropped, as a run's are (`twin.runs.quality`);
gaps (NaN) in temperatures and speed are bridged causally — the last reading holds — and
reported; a sensor that starts with a gap takes its first reading for the rows before it
(the one place a value is taken from later rows, reported as such).  Targets keep their
NaN: those rows are left out of fitting and metrics.  A finding (`findings`) names its
place as the error messages do (`where`: `data.csv, lines 12–40, column 'T3_C'`, a
Parquet file's rows), and the words it is told in count samples, not a file's rows or
lines.
"""

from __future__ import annotations

import hashlib
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from twin.errors import InputError, place
from twin.runs import read_table
from twin.runs.quality import drop_repeated_rows, true_runs
from twin.runs.schema import SPEED, TIME
from twin.runs.table import RawTable, check_distinct_tables
from twin.runs.validate import checked_time, column_with_values, header_hint, required_column

TEMPERATURE_SUFFIX = "_C"
DISPLACEMENT_SUFFIX = "_um"


def is_drift_column(name: str) -> bool:
    """Columns a drift model reads: time, speed, temperatures (`*_C`), drifts (`*_um`)."""
    return name in (TIME, SPEED) or name.endswith((TEMPERATURE_SUFFIX, DISPLACEMENT_SUFFIX))


def read_drift_table(path: str | os.PathLike[str]) -> RawTable:
    """Read one drift-data file (CSV or Parquet) without further checks."""
    return read_table(path, keep=is_drift_column)


def temperature_columns(table: RawTable) -> list[str]:
    return [n for n in table.columns if n.endswith(TEMPERATURE_SUFFIX)]


def displacement_columns(table: RawTable) -> list[str]:
    return [n for n in table.columns if n.endswith(DISPLACEMENT_SUFFIX)]


def sensor_order(names: Sequence[str]) -> list[str]:
    """`names` in the one order a model takes its sensors in: by name, numbers by value
    (t2_C before t10_C), so the bundled data's t1_C … t16_C keep theirs.

    The features (and so a network's start, the validation, every prediction) followed
    the file's column order: the same data with the columns permuted gave another model.
    """
    def key(name: str) -> tuple:
        parts = re.split(r"(\d+)", name)
        return (tuple((0, int(p), p) if p.isdigit() else (1, 0, p) for p in parts), name)

    return sorted(names, key=key)


def array_digest(arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 of named arrays: names sorted, each name, shape and little-endian float64
    bytes (the drift model file's tensor checksum, and what identifies fitting data)."""
    h = hashlib.sha256()
    for name in sorted(arrays):
        h.update(name.encode())
        h.update(str(arrays[name].shape).encode())
        h.update(np.ascontiguousarray(arrays[name], dtype="<f8").tobytes())
    return h.hexdigest()


@dataclass(frozen=True)
class DriftData:
    """Checked, gap-bridged drift data of one or more files, rows concatenated.

    `T_C` (n, m) holds the temperature columns `sensors` (in `sensor_order`, whatever
    order the files hold them in); `targets_um` (n, p) the
    displacement columns `targets` (NaN where not measured, or None when the files hold
    none of them).  `segment_starts` are the first row of every file; `rows` the row of
    every sample in its file (1-based line of a CSV file).  `left_out` maps a temperature
    column not taken as a sensor (`usable_temperatures`) to the reason; `not_read` a file to
    its columns that are none of the above (a speed named `speed`), for the user to hear;
    `dialects` a file read as other than comma-separated with decimal points to how it was
    (`RawTable.dialect`).
    """

    files: list[str]
    time_s: np.ndarray
    speed_rpm: np.ndarray | None
    sensors: list[str]
    T_C: np.ndarray
    targets: list[str]
    targets_um: np.ndarray | None
    segment_starts: np.ndarray
    rows: np.ndarray
    findings: list[dict] = field(default_factory=list)
    left_out: dict[str, str] = field(default_factory=dict)
    not_read: dict[str, list[str]] = field(default_factory=dict)
    dialects: dict[str, str] = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        return int(self.time_s.size)

    def segment_ids(self) -> np.ndarray:
        """Index of the file every row comes from."""
        ids = np.zeros(self.n_samples, dtype=np.int64)
        ids[self.segment_starts[1:]] = 1
        return np.cumsum(ids)

    def segment_digests(self, sensors: Sequence[str], speed: bool) -> list[str]:
        """Per file, the digest of what a model of `sensors` (and the speed) reads of it as
        read (copies dropped, gaps bridged): time, temperatures, speed, targets.  The
        same data under another name or in the other format has the same digest."""
        columns = [self.sensors.index(s) for s in sensors]
        ids = self.segment_ids()
        out = []
        for k in range(len(self.files)):
            rows = ids == k
            arrays = {"time_s": self.time_s[rows], "T_C": self.T_C[rows][:, columns]}
            if speed and self.speed_rpm is not None:
                arrays["speed_rpm"] = self.speed_rpm[rows]
            if self.targets_um is not None:
                arrays["targets_um"] = self.targets_um[rows]
            out.append(array_digest(arrays))
        return out


def _has_values(table: RawTable, name: str) -> bool:
    return name in table.columns and not np.all(np.isnan(table.columns[name]))


def bridge_gaps(values: np.ndarray) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """Hold the last reading across NaN gaps (causal); leading NaN take the first reading.

    Returns the bridged copy and the gaps as (first index, last index) pairs.
    """
    x = np.asarray(values, dtype=float).copy()
    missing = np.isnan(x)
    if not missing.any():
        return x, []
    gaps = true_runs(missing)
    idx = np.where(missing, 0, np.arange(x.size))
    np.maximum.accumulate(idx, out=idx)
    first_valid = int(np.flatnonzero(~missing)[0])
    x = x[idx]
    x[:first_valid] = values[first_valid]
    return x, gaps


def _gap_findings(table: RawTable, name: str, gaps: list[tuple[int, int]],
                  repair: str | None = None) -> list[dict]:
    """A finding per gap (first, last index into the table's samples): its place in the
    file (`first_row`, `last_row` in `row_unit`s: a CSV file's lines, a Parquet file's
    data rows; `where` as the messages tell it), the samples it spans, the repair."""
    out = []
    for a, b in gaps:
        how = repair or ("leading gap: first reading used for the samples before it" if a == 0
                         else "gap bridged causally: last reading held")
        first, last = int(table.rows[a]), int(table.rows[b])
        out.append({"file": table.file, "column": name, "first_row": first,
                    "last_row": last, "row_unit": table.row_unit, "n_rows": b - a + 1,
                    "where": place(table.file, first, name, row_unit=table.row_unit,
                                   last_row=last),
                    "repair": how})
    return out


TIME_GAP_FACTOR = 10.0
"""A step between two rows this many times the file's median step is a gap in the log."""


def _time_gap_findings(table: RawTable, t: np.ndarray) -> list[dict]:
    """A finding per stretch of time without rows (a logger stopped for an hour): the lags
    hold the last reading across it, as they do a missing reading, and that was said of
    a missing reading alone (the run reader reports such a gap as `long_gap`)."""
    if t.size < 3:
        return []
    step = np.diff(t)
    gaps = np.flatnonzero(step > TIME_GAP_FACTOR * float(np.median(step)))
    return [finding for k in gaps for finding in _gap_findings(
        table, TIME, [(int(k), int(k) + 1)],
        f"{step[k]:g} s without rows: the lagged features hold the last reading across it")]


def _without_repeated_rows(table: RawTable) -> tuple[RawTable, list[dict]]:
    """The table without the rows that repeat an earlier one exactly (a logger re-sending
    its buffer), as the recorded-run reader drops them, and a finding per block dropped."""
    kept, _ = drop_repeated_rows(table)
    if kept is table:
        return table, []
    dropped = ~np.isin(table.rows, kept.rows)
    return kept, _gap_findings(table, TIME, true_runs(dropped),
                               f"exact copies of earlier {table.row_unit}s: dropped")


def _check_temperatures(table: RawTable) -> list[str]:
    names = temperature_columns(table)
    if not names:
        # a logger's 'T front bearing' or 'Temp1 [°C]' is not read: say what the file holds
        raise table.error(f"no temperature columns (names ending in _C) {header_hint(table)}",
                          table.header_row)
    return names


def _constant_value(tables: Sequence[RawTable], name: str) -> float | None:
    """The one value column `name` holds in every row of every table (gaps aside), or
    None if it changes (or holds none: refused where its values are read)."""
    values = np.concatenate([t.columns[name] for t in tables])
    values = values[~np.isnan(values)]
    return float(values[0]) if values.size and np.ptp(values) == 0 else None


def usable_temperatures(tables: Sequence[RawTable]) -> tuple[list[str], dict[str, str]]:
    """The temperature columns every table holds (in the first's order) and that change,
    and why each other one is left out: a sensor one file lacks cannot be a feature of a
    model fitted on all of them, whichever file is given first, and one that never
    changes tells nothing (its grade and correlation cluster are artefacts)."""
    held = [_check_temperatures(table) for table in tables]
    files = ", ".join(t.file for t in tables)
    common = [n for n in held[0] if all(n in names for names in held)]
    if not common:
        listing = "; ".join(f"{t.file}: {', '.join(names)}"
                            for t, names in zip(tables, held, strict=True))
        raise InputError(f"no temperature column is in every file ({listing})", file=files)
    left_out = {n: "not in " + ", ".join(t.file for t, names in zip(tables, held, strict=True)
                                         if n not in names) + " (a sensor is in every file)"
                for names in held for n in names if n not in common}
    if sum(t.n_samples for t in tables) < 2:
        # one sample shows no column change: refused for its length where the rows with a
        # drift are counted (it was 'every temperature column reads one value throughout')
        return common, left_out
    constant = {n: v for n in common if (v := _constant_value(tables, n)) is not None}
    if len(constant) == len(common):
        raise InputError(f"every temperature column ({', '.join(common)}) reads one value "
                         "throughout: no sensor tells how the machine warms (--sensors LIST "
                         "uses them anyway)", file=files)
    left_out.update({n: f"reads {v:g} in every sample (tells nothing)"
                     for n, v in constant.items()})
    return [n for n in common if n not in constant], left_out


def drift_data(
    tables: Sequence[RawTable],
    sensors: Sequence[str] | None = None,
    targets: Sequence[str] = (),
    require_targets: bool = True,
    require_speed: bool = False,
) -> DriftData:
    """Check the tables and assemble a `DriftData`.

    `sensors` None takes the temperature columns every file holds and that change (the
    others are `left_out`, whichever file comes first); either way in `sensor_order`; `targets`
    must be present in every file when `require_targets`.
    """
    if not tables:
        raise InputError("no data file given")
    check_distinct_tables(tables, "validation holds one file out per block and would "
                          "score it against a model fitted on its copy")
    left_out: dict[str, str] = {}
    if sensors is None:
        sensors, left_out = usable_temperatures(tables)
    sensors, targets = sensor_order(sensors), list(targets)
    # speed is optional: a column without any value (a logger that exports every channel
    # it has) is no speed, as a file without one
    use_speed = require_speed or all(_has_values(t, SPEED) for t in tables)
    times, speeds, temps, drifts, rows, starts, findings = [], [], [], [], [], [], []
    n = 0
    for table in tables:
        table, repeats = _without_repeated_rows(table)
        findings += repeats
        t = checked_time(table, repeats=False)
        findings += _time_gap_findings(table, t)
        _check_temperatures(table)
        wanted = [*sensors, *([SPEED] if use_speed else [])]
        if require_targets:
            wanted += targets
        for name in wanted:
            required_column(table, name)
        T = np.empty((t.size, len(sensors)))
        for j, name in enumerate(sensors):
            T[:, j], gaps = bridge_gaps(column_with_values(table, name))
            findings += _gap_findings(table, name, gaps)
        if use_speed:
            speed, gaps = bridge_gaps(column_with_values(table, SPEED))
            findings += _gap_findings(table, SPEED, gaps)
            speeds.append(speed)
        elif SPEED in table.columns and not _has_values(table, SPEED):
            findings += _gap_findings(table, SPEED, [(0, t.size - 1)],
                                      "no value at all: read as no speed column")
        if targets and all(name in table.columns for name in targets):
            # predict reads no target: a column left blank for the drift to come is none
            drifts.append(np.stack([column_with_values(table, name) if require_targets
                                    else table.columns[name] for name in targets], axis=1))
            if require_targets:  # a probe's dropout left rows out of fitting unsaid
                for j, name in enumerate(targets):
                    findings += _gap_findings(
                        table, name, true_runs(np.isnan(drifts[-1][:, j])),
                        "no drift measured: left out of fitting and of the metrics")
        else:
            drifts.append(np.full((t.size, len(targets)), np.nan))
        times.append(t)
        temps.append(T)
        rows.append(table.rows)
        starts.append(n)
        n += t.size
    targets_um = np.concatenate(drifts) if targets else None
    return DriftData(
        files=[t.file for t in tables], time_s=np.concatenate(times),
        speed_rpm=np.concatenate(speeds) if use_speed else None, sensors=sensors,
        T_C=np.concatenate(temps), targets=targets, targets_um=targets_um,
        segment_starts=np.asarray(starts, dtype=np.int64), rows=np.concatenate(rows),
        findings=findings, left_out=left_out,
        not_read={t.file: list(t.ignored_columns) for t in tables if t.ignored_columns},
        dialects={t.file: t.dialect for t in tables if t.dialect})


def read_drift_data(
    paths: Sequence[str | os.PathLike[str]],
    sensors: Sequence[str] | None = None,
    targets: Sequence[str] = (),
    require_targets: bool = True,
    require_speed: bool = False,
) -> DriftData:
    """Read and check drift-data files (see `drift_data`)."""
    return drift_data([read_drift_table(p) for p in paths], sensors, targets,
                      require_targets, require_speed)
