"""Recorded runs as Parquet: the same columns as the CSV; metadata in the schema metadata.

Rows are numbered 1-based over the data (Parquet has no lines a user would edit).
"""

from __future__ import annotations

import os
from collections.abc import Mapping

import numpy as np

from twin.atomic import atomic_target
from twin.errors import InputError
from twin.runs.schema import ALL_COLUMNS
from twin.runs.table import RawTable


def _is_tool_metadata(key: str) -> bool:
    # Written by pandas/pyarrow themselves, not by the user.
    return key == "pandas" or key.startswith("ARROW:")


def read_parquet_table(path: str | os.PathLike[str]) -> RawTable:
    """Read a Parquet recorded run into a `RawTable`."""
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    file = str(path)
    try:
        table = pq.read_table(path)
    except (OSError, pa.ArrowException) as exc:
        raise InputError(f"not a readable Parquet file: {exc}", file=file) from None
    metadata = {}
    for key, value in (table.schema.metadata or {}).items():
        name = key.decode("utf-8", "replace")
        if not _is_tool_metadata(name):
            metadata[name] = value.decode("utf-8", "replace")
    if table.num_rows == 0:
        raise InputError("no data rows", file=file)

    columns: dict[str, np.ndarray] = {}
    for name in table.column_names:
        if name not in ALL_COLUMNS:
            continue
        column = table.column(name)
        if pa.types.is_integer(column.type) or pa.types.is_floating(column.type):
            values = column.cast(pa.float64()).to_numpy(zero_copy_only=False)
        elif pa.types.is_string(column.type) or pa.types.is_large_string(column.type):
            try:
                values = pc.cast(column, pa.float64()).to_numpy(zero_copy_only=False)
            except pa.ArrowInvalid:
                texts = column.to_pylist()
                for i, text in enumerate(texts, start=1):
                    try:
                        float(text) if text is not None else None
                    except ValueError:
                        raise InputError(f"cannot read {text!r} as a number", file=file,
                                         row=i, column=name) from None
                raise
        else:
            raise InputError(f"column type {column.type} is not numeric", file=file,
                             column=name)
        values = np.asarray(values, dtype=float)
        bad = np.flatnonzero(np.isinf(values))
        if bad.size:
            raise InputError("not a finite number", file=file, row=int(bad[0]) + 1, column=name)
        columns[name] = values
    ignored = [name for name in table.column_names if name not in ALL_COLUMNS]
    return RawTable(file=file, metadata=metadata, columns=columns,
                    rows=np.arange(1, table.num_rows + 1, dtype=np.int64),
                    ignored_columns=ignored)


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
