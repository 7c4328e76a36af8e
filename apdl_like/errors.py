"""`ApdlError`: bad deck input, named by file:line, the command and what is wrong.

It is a `twin.errors.InputError`, so every CLI of the project maps it to exit code 2 with a
one-line message and no traceback.
"""

from __future__ import annotations

from twin.errors import InputError


class ApdlError(InputError):
    """A deck problem: `file:line: COMMAND: what is wrong`."""

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        line: int | None = None,
        command: str | None = None,
    ) -> None:
        super().__init__(message, file=file, row=line, column=command)
        self.line = line
        self.command = command

    def located(self, file: str | None, line: int | None, command: str | None) -> ApdlError:
        """The same error with the location filled in where it was still unknown."""
        return ApdlError(
            self.reason,
            file=self.file if self.file is not None else file,
            line=self.line if self.line is not None else line,
            command=self.command if self.command is not None else command,
        )

    def __str__(self) -> str:
        where = ""
        if self.file is not None:
            where = f"{self.file}:{self.line}" if self.line is not None else str(self.file)
        elif self.line is not None:
            where = f"line {self.line}"
        parts = [p for p in (where, self.command) if p]
        return ": ".join([*parts, self.reason])
