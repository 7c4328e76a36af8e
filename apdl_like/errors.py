"""`ApdlError`: bad deck input, named by file:line, the command and what is wrong.

It is a `twin.errors.InputError`, so every CLI of the project maps it to exit code 2 with a
one-line message and no traceback.
"""

from __future__ import annotations

from twin.errors import InputError


class ApdlError(InputError):
    """A deck problem: `file:line: COMMAND: what is wrong` (the error's row is the deck line,
    its column the command)."""

    def __init__(self, message: str, *, file: str | None = None, line: int | None = None,
                 command: str | None = None) -> None:
        super().__init__(message, file=file, row=line, column=command)

    @property
    def line(self) -> int | None:
        return self.row

    @property
    def command(self) -> str | None:
        return self.column

    def where(self) -> str:
        if self.file is not None:
            where = f"{self.file}:{self.line}" if self.line is not None else str(self.file)
        elif self.line is not None:
            where = f"line {self.line}"
        else:
            where = ""
        return ": ".join(p for p in (where, self.command) if p)
