"""`RecordedRun`: a validated, repaired recorded run, and sampling it at given times."""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from twin.errors import InputError
from twin.io.atomic import write_json
from twin.paths import regular_file_info
from twin.runs.csv_format import read_csv_table, write_csv_table
from twin.runs.parquet_format import read_parquet_table, write_parquet_table
from twin.runs.quality import QualityConfig, drop_repeated_rows, finding, repair
from twin.runs.schema import AMBIENT, COOLANT, DISPLACEMENTS, SPEED, TEMPERATURES, TIME
from twin.runs.table import RawTable
from twin.runs.validate import (
    check_operating_temperatures,
    check_speed_limit,
    check_structure,
    check_values,
)

CSV_DIALECT = "csv_dialect"
"""quality.json kind of the note that a CSV file was read as other than comma-separated
with decimal points (`RawTable.dialect`): told once, for the whole file."""

# one reader and one writer per format, chosen by file suffix (meshio's registry)
_READERS = {".csv": read_csv_table, ".parquet": read_parquet_table, ".pq": read_parquet_table}
_WRITERS = {".csv": write_csv_table, ".parquet": write_parquet_table, ".pq": write_parquet_table}


@dataclass(frozen=True, kw_only=True)
class Samples:
    """Measured values at a set of times (run time, s from the first sample).

    `T_C` is (n, 5) for T1..T5; `disp_um` is (n, 3) for x, y, z (NaN where a component
    was not recorded) or None.  `valid[column]` is False where a value must not be used
    (long gap, long dropout, stuck sensor); columns are named as in the file.
    """

    time_s: np.ndarray
    speed_rpm: np.ndarray
    ambient_C: np.ndarray
    T_C: np.ndarray
    coolant_C: np.ndarray | None = None
    disp_um: np.ndarray | None = None
    valid: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def valid_T(self) -> np.ndarray:
        """(n, 5) validity of T1..T5."""
        return np.stack([self.valid[n] for n in TEMPERATURES], axis=1)

    @property
    def T_valid_C(self) -> np.ndarray:
        """(n, 5) T1..T5 as the twin reads them: NaN where the data-quality check marks a
        sample invalid (a long dropout's or gap's fill, a stuck or dead sensor), °C."""
        return np.where(self.valid_T, self.T_C, np.nan)

    def column(self, name: str) -> np.ndarray:
        """A column by its file name (`T3_C`, `disp_z_um`, ...)."""
        if name in TEMPERATURES:
            return self.T_C[:, TEMPERATURES.index(name)]
        if name in DISPLACEMENTS:
            if self.disp_um is None:
                raise KeyError(name)
            return self.disp_um[:, DISPLACEMENTS.index(name)]
        value = {TIME: self.time_s, SPEED: self.speed_rpm, AMBIENT: self.ambient_C,
                 COOLANT: self.coolant_C}.get(name)
        if value is None:
            raise KeyError(name)
        return value


@dataclass(frozen=True, kw_only=True)
class RecordedRun(Samples):
    """A recorded run after validation and repair; the source file is never modified.

    `metadata` holds the `# key: value` lines (strings); `quality` the data-quality
    findings (see `twin.runs.quality`); `gaps_s` the long time gaps (excluded from the
    metrics); `rows[i]` the file line (CSV) or data row (Parquet) of sample i.
    """

    name: str
    path: str
    metadata: dict[str, str]
    rows: np.ndarray
    quality: list[dict]
    gaps_s: list[tuple[float, float]]
    max_gap_s: float

    @property
    def duration_s(self) -> float:
        return float(self.time_s[-1])

    @property
    def columns(self) -> list[str]:
        """Columns present in the run (after dropping empty optional ones)."""
        return list(self.valid)

    def at(self, times_s: np.ndarray) -> Samples:
        """Values linearly interpolated at `times_s` (e.g. every 4 s solver step).

        A value is valid when both bracketing samples are valid and at most `max_gap_s`
        apart; times outside the run are clamped to its ends and marked invalid.
        """
        t = np.atleast_1d(np.asarray(times_s, dtype=float))
        left = np.clip(np.searchsorted(self.time_s, t, side="right") - 1, 0, self.time_s.size - 1)
        right = np.minimum(left + 1, self.time_s.size - 1)
        exact = self.time_s[left] == t
        inside = (t >= self.time_s[0]) & (t <= self.time_s[-1])
        close = exact | (self.time_s[right] - self.time_s[left] <= self.max_gap_s)

        def interp(x: np.ndarray) -> np.ndarray:
            return np.interp(t, self.time_s, x)

        def ok(name: str) -> np.ndarray:
            m = self.valid[name]
            return inside & close & m[left] & (exact | m[right])

        return self._build(t, interp, ok)

    def before(self, times_s: np.ndarray) -> Samples:
        """The last sample at or before each time (causal: what was measured by then).

        The twin's forecast for window k uses `before(60 k)`.  Invalid where no sample
        precedes the time, or the last one is older than `max_gap_s`.
        """
        t = np.atleast_1d(np.asarray(times_s, dtype=float))
        idx = np.searchsorted(self.time_s, t, side="right") - 1
        some = idx >= 0
        idx = np.maximum(idx, 0)
        recent = some & (t - self.time_s[idx] <= self.max_gap_s)

        def pick(x: np.ndarray) -> np.ndarray:
            return x[idx]

        def ok(name: str) -> np.ndarray:
            return recent & self.valid[name][idx]

        return self._build(self.time_s[idx], pick, ok)

    def _build(self, t: np.ndarray, get: Callable[[np.ndarray], np.ndarray],
               ok: Callable[[str], np.ndarray]) -> Samples:
        disp = None
        if self.disp_um is not None:
            disp = np.stack([get(self.disp_um[:, j]) for j in range(3)], axis=1)
        return Samples(
            time_s=t, speed_rpm=get(self.speed_rpm), ambient_C=get(self.ambient_C),
            T_C=np.stack([get(self.T_C[:, j]) for j in range(5)], axis=1),
            coolant_C=None if self.coolant_C is None else get(self.coolant_C),
            disp_um=disp, valid={name: ok(name) for name in self.valid})


def read_table(path: str | os.PathLike[str],
               keep: Callable[[str], bool] | None = None) -> RawTable:
    """Read a CSV or Parquet table (by file suffix) without validation.

    `keep(name)` selects the columns to read (default: the recorded-run schema).
    """
    file = Path(path)
    reader = _READERS.get(file.suffix.lower())
    if reader is None and file.is_dir():  # said as it is, not as a format named ''
        raise InputError("is a folder, not a run file (CSV or Parquet)", file=str(path))
    if reader is None:
        # nothing there (a mistyped folder), a fifo, a symlink loop: said as it is
        regular_file_info(path, use="read file")
        raise InputError(f"unknown run format {file.suffix!r}; expected .csv or .parquet",
                         file=str(path))
    return reader(path, keep)


def read_run(path: str | os.PathLike[str], config: QualityConfig | None = None,
             max_speed_rpm: float = math.inf) -> RecordedRun:
    """Read, validate and repair a recorded run (CSV or Parquet, by file suffix).

    Hard errors raise `InputError` with the file, the line (of a CSV file, as an editor
    numbers them) or row (a Parquet file's data row) and the column: besides the format,
    a run longer than `MAX_DURATION_S`, a speed above `max_speed_rpm` (the spindle's
    limit: pass the spec's) or an ambient or coolant outside `OPERATING_TEMPERATURE_C` is
    refused here, before any replay.  Repairs are listed in
    `RecordedRun.quality`.
    """
    return run_from_table(read_table(path), config, max_speed_rpm)


def run_from_table(table: RawTable, config: QualityConfig | None = None,
                   max_speed_rpm: float = math.inf) -> RecordedRun:
    """Validate and repair a raw table into a `RecordedRun` (see `read_run`)."""
    config = config or QualityConfig()
    table, repeats = drop_repeated_rows(table)
    check_structure(table)
    check_values(table)
    # The speed limit holds for the speeds as written: the repair replaces a one-sample
    # speed glitch, but one beyond the spindle's limit is a corrupt value to be told.
    check_speed_limit(table.file, table.rows, table.columns[SPEED], max_speed_rpm,
                      row_unit=table.row_unit)
    fixed = repair(table, config)
    check_operating_temperatures(table.file, fixed.rows, fixed.columns,
                                 row_unit=table.row_unit)
    quality = [finding("", CSV_DIALECT, f"read as {table.dialect}", count=table.n_samples,
                       detail="the twin writes its files comma-separated, with decimal points")
               ] if table.dialect else []
    quality += [finding(n, "ignored_column", "column ignored (not in the run schema)",
                        detail="unknown column name") for n in table.ignored_columns]
    quality += repeats + fixed.findings
    c = fixed.columns
    disp = None
    if any(n in c for n in DISPLACEMENTS):
        nan = np.full(fixed.time_s.size, np.nan)
        disp = np.stack([c.get(n, nan) for n in DISPLACEMENTS], axis=1)
    valid = dict(fixed.valid)
    if disp is not None:
        for n in DISPLACEMENTS:
            valid.setdefault(n, np.zeros(fixed.time_s.size, dtype=bool))
    file = Path(table.file)
    return RecordedRun(
        name=table.metadata.get("name") or file.stem, path=table.file,
        metadata=dict(table.metadata), rows=fixed.rows, time_s=fixed.time_s,
        speed_rpm=c[SPEED], ambient_C=c[AMBIENT],
        T_C=np.stack([c[n] for n in TEMPERATURES], axis=1), coolant_C=c.get(COOLANT),
        disp_um=disp, valid=valid, quality=quality, gaps_s=fixed.gaps_s,
        max_gap_s=config.max_gap_s)


def check_replayable(columns: Mapping[str, np.ndarray], file: str,
                     max_speed_rpm: float = math.inf) -> None:
    """InputError if `read_run` would refuse a run of these columns (checked before such a
    run is written: whatever `twin synth` writes, replay reads)."""
    n = len(next(iter(columns.values())))
    table = RawTable(file=file, metadata={}, rows=np.arange(1, n + 1),
                     columns={k: np.asarray(v, dtype=float) for k, v in columns.items()},
                     row_unit="row")
    run_from_table(table, max_speed_rpm=max_speed_rpm)


def write_run(path: str | os.PathLike[str], columns: Mapping[str, np.ndarray],
              metadata: Mapping[str, object] | None = None) -> None:
    """Write a recorded run (CSV or Parquet by suffix), atomically.

    `columns` maps schema column names to 1-D arrays; the required ones must be present.
    """
    missing = [n for n in (TIME, SPEED, AMBIENT, *TEMPERATURES) if n not in columns]
    if missing:
        raise ValueError(f"missing required columns: {', '.join(missing)}")
    suffix = Path(path).suffix.lower()
    writer = _WRITERS.get(suffix)
    if writer is None:
        raise ValueError(f"unknown run format {suffix!r}; expected .csv or .parquet")
    writer(path, columns, metadata)


def write_quality(run: RecordedRun, path: str | os.PathLike[str]) -> None:
    """Write `quality.json` (the run's data-quality findings), atomically."""
    doc = {"run": run.name, "file": run.path, "n_samples": int(run.time_s.size),
           "duration_s": run.duration_s, "findings": run.quality}
    write_json(path, doc)
