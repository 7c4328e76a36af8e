"""Error types shared by every command, and how the command lines present them.

`InputError` is the one error a user is meant to see: bad input named precisely (file,
row/line, column/field).  The CLIs (`twin`, `apdl-like`) print it without a traceback and
exit with code 2 through `report_errors`.  This module stays light (no twin command, no
numerical library) so that any CLI can import it without loading the others.
"""

from __future__ import annotations

import copy
import functools
import os
import sys
from collections.abc import Callable
from typing import Any, Self

EXIT_INPUT_ERROR = 2
EXIT_INTERNAL_ERROR = 1
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports Ctrl-C
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, as a shell reports `cmd | head`


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
        super().__init__(message)
        self.reason = message
        self.file = file
        self.row = row
        self.column = column

    def where(self) -> str:
        """The location as the message shows it (`data.csv, row 3, column 'T_C'`), or ''."""
        where = []
        if self.file is not None:
            where.append(str(self.file))
        if self.row is not None:
            where.append(f"row {self.row}")
        if self.column is not None:
            where.append(f"column {self.column!r}")
        return ", ".join(where)

    def located(self, file: str | None = None, row: int | None = None,
                column: str | None = None) -> Self:
        """The same error with its location filled in where it was still unknown (a
        reader's error re-raised by the caller that knows the file)."""
        err = copy.copy(self)
        err.file = self.file if self.file is not None else file
        err.row = self.row if self.row is not None else row
        err.column = self.column if self.column is not None else column
        return err

    def __str__(self) -> str:
        where = self.where()
        return f"{where}: {self.reason}" if where else self.reason


def report_errors(func: Callable[..., Any]) -> Callable[..., Any]:
    """Wrap a CLI command: `InputError` → one line and exit 2, anything unexpected → one
    line and exit 1 (no traceback either way), Ctrl-C → 130, a closed pipe → 141."""
    # typer is needed only once a command is wired, never by the library
    from typer import Exit

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return func(*args, **kwargs)
        except InputError as exc:
            print(f"error: {exc}", file=sys.stderr)
            raise Exit(EXIT_INPUT_ERROR) from None
        except Exit:
            raise
        except KeyboardInterrupt:
            print("interrupted", file=sys.stderr)
            raise Exit(EXIT_INTERRUPTED) from None
        except BrokenPipeError:
            # the reader went away (`twin model-info M | head`): not an error of ours;
            # silence the final flush and exit as a SIGPIPE'd process would
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            raise Exit(EXIT_BROKEN_PIPE) from None
        except Exception as exc:  # noqa: BLE001 - the last line of defence of a CLI
            print(f"internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
            raise Exit(EXIT_INTERNAL_ERROR) from None

    return wrapper
