"""Recorded runs as Parquet: the same columns as the CSV; metadata in the schema metadata.

Rows are numbered 1-based over the data (Parquet has no lines a user would edit).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

import numpy as np

from twin.errors import InputError
from twin.io.atomic import atomic_target
from twin.paths import check_input_file
from twin.runs.schema import ALL_COLUMNS, MAX_SAMPLES, TIME
from twin.runs.table import RawTable, parse_cell

if TYPE_CHECKING:
    import pyarrow as pa

ROW = "row"
"""What an error calls a place in a Parquet file (`RawTable.row_unit`): its data row,
1-based (`bad.parquet, row 3, column 'T1_C'`)."""


def _is_tool_metadata(key: str) -> bool:
    # Written by pandas/pyarrow themselves, not by the user.
    return key == "pandas" or key.startswith("ARROW:")


def _column_values(column: pa.ChunkedArray, file: str, name: str) -> np.ndarray:
    """A Parquet column as float64; text cells are read as the CSV reader reads them."""
    import pyarrow as pa

    kind = column.type
    if pa.types.is_dictionary(kind):
        column = column.cast(kind.value_type)
        kind = column.type
    if pa.types.is_null(kind):
        return np.full(len(column), np.nan)
    if pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_decimal(kind):
        # unsafe: a uint64 beyond 2**53 rounds to the nearest float instead of raising
        values = column.cast(pa.float64(), safe=False).to_numpy(zero_copy_only=False)
        values = np.asarray(values, dtype=float)
        bad = np.flatnonzero(np.isinf(values))
        if bad.size:
            raise InputError("not a finite number", file=file, row=int(bad[0]) + 1,
                             column=name, row_unit=ROW)
        return values
    if pa.types.is_string(kind) or pa.types.is_large_string(kind):
        texts = column.to_pylist()
        return np.array([math.nan if text is None else parse_cell(text, file, i, name, ROW)
                         for i, text in enumerate(texts, start=1)], dtype=float)
    hint = ""
    if name == TIME and pa.types.is_temporal(kind):
        # a logger's time stamps, as a CSV file's '2026-11-27 10:00:02' is told
        hint = ": time_s holds seconds from the run's start, convert the column"
    raise InputError(f"column type {kind} is not numeric{hint}", file=file, column=name)


def read_parquet_table(path: str | os.PathLike[str],
                       keep: Callable[[str], bool] | None = None) -> RawTable:
    """Read a Parquet recorded run into a `RawTable`; `keep` as in `read_csv_table`."""
    keep = keep or ALL_COLUMNS.__contains__
    import pyarrow as pa
    import pyarrow.parquet as pq

    file = str(path)
    check_input_file(path)
    try:
        parquet = pq.ParquetFile(path)
        # counted from the footer, before the columns are decompressed into memory
        if parquet.metadata.num_rows > MAX_SAMPLES:
            raise InputError(f"{parquet.metadata.num_rows} data rows; a run may hold at most "
                             f"{MAX_SAMPLES} samples (resample it)", file=file,
                             row=MAX_SAMPLES + 1, row_unit=ROW)
        table = parquet.read()
    except (OSError, pa.ArrowException) as exc:
        raise InputError(f"not a readable Parquet file: {exc}", file=file) from None
    names = table.column_names
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise InputError("column appears twice", file=file, column=twice[0])
    metadata = {}
    for key, value in (table.schema.metadata or {}).items():
        name = key.decode("utf-8", "replace")
        if not _is_tool_metadata(name):
            metadata[name] = value.decode("utf-8", "replace")
    if table.num_rows == 0:
        raise InputError("no data rows", file=file)

    columns: dict[str, np.ndarray] = {}
    for name in table.column_names:
        if not keep(name):
            continue
        columns[name] = _column_values(table.column(name), file, name)
    ignored = [name for name in table.column_names if not keep(name)]
    return RawTable(file=file, metadata=metadata, columns=columns,
                    rows=np.arange(1, table.num_rows + 1, dtype=np.int64),
                    ignored_columns=ignored, row_unit=ROW)


def write_parquet_table(
    path: str | os.PathLike[str],
    columns: Mapping[str, np.ndarray],
    metadata: Mapping[str, object] | None = None,
) -> None:
    """Write columns and metadata as a Parquet recorded run, atomically."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.table({name: np.asarray(values, dtype=float) for name, values in columns.items()})
    table = table.replace_schema_metadata({str(k): str(v) for k, v in (metadata or {}).items()})
    with atomic_target(path) as tmp:
        pq.write_table(table, tmp)
