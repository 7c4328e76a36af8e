"""A raw run table as read from a file, before validation and repair.

Readers (one per format, like meshio's registry) turn a file into a `RawTable`: float
columns keyed by name, the metadata, and for every row where it sits in the file, so that
every later error or finding can name the line a user sees in an editor.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class RawTable:
    """Columns of one recorded run exactly as stored in its file.

    `rows[i]` is the 1-based line number of sample i in a CSV file (as an editor shows
    it), or the 1-based data-row number in a Parquet file.  Missing values are NaN.
    """

    file: str
    metadata: dict[str, str]
    columns: dict[str, np.ndarray]
    rows: np.ndarray
    header_row: int | None = None
    ignored_columns: list[str] = field(default_factory=list)

    @property
    def n_samples(self) -> int:
        return int(self.rows.size)
