"""Error types shared by every command.

`InputError` is the one error a user is meant to see: bad input named precisely (file,
row/line, column/field).  The CLI prints it without a traceback and exits with code 2.
"""

from __future__ import annotations


class InputError(ValueError):
    """Bad user input: a file, a row/line, a column/field and what is wrong with it."""

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        row: int | None = None,
        column: str | None = None,
    ) -> None:
        self.file = file
        self.row = row
        self.column = column
        self.reason = message
        where = []
        if file is not None:
            where.append(str(file))
        if row is not None:
            where.append(f"row {row}")
        if column is not None:
            where.append(f"column {column!r}")
        super().__init__(f"{', '.join(where)}: {message}" if where else message)
