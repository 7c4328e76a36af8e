"""Error types shared by every command, and how the command lines present them.

`InputError` is the one error a user is meant to see: bad input named precisely (file,
row/line, column/field).  The CLIs (`twin`, `apdl-like`) print it without a traceback and
exit with code 2 through `report_errors`.  This module stays light (no twin command, no
numerical library) so that any CLI can import it without loading the others.
"""

from __future__ import annotations

import copy
import functools
import importlib
import os
import signal
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from typing import Any, NoReturn, Self

EXIT_INPUT_ERROR = 2
EXIT_INTERNAL_ERROR = 1
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports Ctrl-C
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, as a shell reports `cmd | head`
INTERRUPTED = "interrupted"  # the one line a Ctrl-C prints


class InputError(ValueError):
    """Bad user input: a file, a row/line, a column/field and what is wrong with it."""

    ROW = "row"
    COLUMN = "column"
    """How `where` calls the row and the column (a table's words; `TomlError` has its own);
    an error's `row_unit` says otherwise where the row is a file's line (a CSV table)."""
    MISSING = "missing"
    UNKNOWN = "unknown field"
    """What `validation_problem` calls a value left out and a name the schema lacks."""

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        row: int | None = None,
        column: str | None = None,
        row_unit: str | None = None,
    ) -> None:
        super().__init__(message)
        self.reason = message
        self.file = file
        self.row = row
        self.column = column
        # what `where` calls the row: "line" for a text file's line (a CSV table's, as an
        # editor numbers them: `RawTable.row_unit`), else the class's word
        self.row_unit = row_unit or self.ROW

    def where(self) -> str:
        """The location as the message shows it (`data.csv, line 3, column 'T_C'`, a
        Parquet file's `data.parquet, row 3, column 'T_C'`), or ''.
        A command-line option in the column's place is called one (`RUN.csv, option
        '--time'`): a user reading "column '--out'" looked for it in a file."""
        return place(self.file, self.row, self.column, row_unit=self.row_unit,
                     column_word=self.COLUMN)

    def located(self, file: str | None = None, row: int | None = None,
                column: str | None = None, row_unit: str | None = None) -> Self:
        """The same error with its location filled in where it was still unknown (a
        reader's error re-raised by the caller that knows the file); a row filled in comes
        with `row_unit` (default: the error's own), a row already known keeps its unit."""
        err = copy.copy(self)
        err.file = self.file if self.file is not None else file
        if self.row is None and row is not None:
            err.row = row
            err.row_unit = row_unit or self.row_unit
        err.column = self.column if self.column is not None else column
        return err

    def __str__(self) -> str:
        where = self.where()
        return f"{where}: {self.reason}" if where else self.reason

    @classmethod
    def validation_problem(cls, exc: Any) -> tuple[tuple, str]:
        """The location (pydantic's `loc`) and the words of the first problem of a pydantic
        `ValidationError` (duck-typed: this module loads no library), with the class's
        words for a missing and an unknown name: one reading of pydantic's messages for
        every typed file (a scenario, a spindle spec, a model file's metadata)."""
        first = exc.errors()[0]
        # pydantic's words for a nested model ("a valid dictionary or instance of
        # Metadata") name a class of ours, not anything in the file; a validator's own
        # message comes after "Value error, "
        message = first["msg"].removeprefix("Value error, ").split(" or instance of ")[0]
        if first["type"] == "missing":  # pydantic's "Field required"
            message = cls.MISSING
        elif first["type"] == "extra_forbidden":
            message = cls.UNKNOWN
        return tuple(first["loc"]), message


def place(file: str | None = None, row: int | None = None, column: str | None = None, *,
          row_unit: str = InputError.ROW, column_word: str = InputError.COLUMN,
          last_row: int | None = None) -> str:
    """A place in an input as every message tells it: `data.csv, line 3, column 'T_C'`
    (`row_unit` "line" for a text file's line, "row" for a Parquet file's data row), a
    stretch `data.csv, lines 3–9, column 'T_C'` up to `last_row`, a command-line option
    in the column's place `option '--time'`; '' for none."""
    where = []
    if file is not None:
        where.append(str(file))
    if row is not None:
        if last_row is not None and last_row != row:
            where.append(f"{row_unit}s {row}–{last_row}")
        else:
            where.append(f"{row_unit} {row}")
    if column is not None:
        kind = "option" if column.startswith("--") else column_word
        where.append(f"{kind} {column!r}")
    return ", ".join(where)


def key_path(loc: Sequence[object]) -> str:
    """A place in nested data as a user reads it: `faults.dropouts[1].sensor` (a table's key
    after a dot, a list's item by its index in brackets), '' for the top."""
    path = ""
    for item in loc:
        if isinstance(item, int):
            path += f"[{item}]"
        else:
            path += ("." if path else "") + str(item)
    return path


class TomlError(InputError):
    """Bad TOML input (a scenario, a spindle spec): `file, line 3, key 'faults.stuck'`.
    Its row is the line and its column the key (of a value or a table, `key_path`: a
    list's item as `faults.dropouts[1]`): told as a table's "row" and "column", a user
    looked for a column in a TOML file."""

    ROW = "line"
    COLUMN = "key"
    MISSING = "missing required key"
    UNKNOWN = "unknown key (check the spelling and the unit in the name)"

    def __init__(self, message: str, *, file: str | None = None, line: int | None = None,
                 key: str | None = None) -> None:
        super().__init__(message, file=file, row=line, column=key)


class MetadataError(InputError):
    """A model file's metadata field that is missing, of the wrong type or inconsistent:
    `model.safetensors, metadata field 'features.taus_min': ...`; told as a table's
    "column", a user looked for a column in a model file."""

    COLUMN = "metadata field"

    def __init__(self, message: str, *, file: str | None = None,
                 field: str | None = None) -> None:
        super().__init__(message, file=file, column=field)

    @classmethod
    def from_validation(cls, exc: Any, file: str) -> MetadataError:
        """The first problem of a pydantic `ValidationError`, at its field."""
        loc, message = cls.validation_problem(exc)
        return cls(message, file=file, field=key_path(loc) or None)


def _help_hint(exc: InputError) -> str:
    """`; see 'twin simulate --help'` after a bad value of an option alone (no file), as
    click ends the usage errors it finds itself (an unknown option, a value out of its
    bounds): `--speed -100` ended without it, `--jobs 0` with it."""
    if exc.file is not None or not (exc.column or "").startswith("--"):
        return ""
    # the running command's click context: typer vendors click as typer._click since 0.2x,
    # and used click itself before (pyproject allows typer >= 0.12); neither is imported
    # here unless a command runs
    for module in ("typer._click.globals", "click"):
        try:
            context = importlib.import_module(module).get_current_context(silent=True)
        except (ImportError, AttributeError):
            continue
        if context is not None:
            return f"; see '{context.command_path} --help'"
    return ""


def report_errors(func: Callable[..., Any]) -> Callable[..., Any]:
    """Wrap a CLI command: `InputError` → one line and exit 2, anything unexpected → one
    line and exit 1 (no traceback either way), Ctrl-C → 130, a closed pipe → 141."""
    # typer is needed only once a command is wired, never by the library
    from typer import Exit

    def interrupted() -> Exit:
        print(INTERRUPTED, file=sys.stderr)
        watch = _CTRL_C.get()
        if watch is not None:
            watch.pressed, watch.told = False, True
        return Exit(EXIT_INTERRUPTED)

    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            result = func(*args, **kwargs)
            raise_if_interrupted()
            return result
        except InputError as exc:
            print(f"error: {exc}{_help_hint(exc)}", file=sys.stderr)
            raise Exit(EXIT_INPUT_ERROR) from None
        except Exit:
            raise
        except KeyboardInterrupt:
            raise interrupted() from None
        except BrokenPipeError:
            # the reader went away (`twin model-info M | head`): not an error of ours;
            # silence the final flush and exit as a SIGPIPE'd process would
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            raise Exit(EXIT_BROKEN_PIPE) from None
        except Exception as exc:  # noqa: BLE001 - the last line of defence of a CLI
            if _pressed():  # a library made Ctrl-C its own error (pydantic's SchemaError)
                raise interrupted() from None
            print(f"internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
            raise Exit(EXIT_INTERNAL_ERROR) from None

    return wrapper


@dataclass
class _CtrlCWatch:
    """What one console script saw of Ctrl-C: `pressed` once SIGINT came and until a command
    told it, `told` once `report_errors` printed it (so that `exit_interrupted` does not
    print it again).  One per `run_console_script`, reached through `_CTRL_C`."""

    pressed: bool = False
    told: bool = False

    def note(self, signum: int, frame: object) -> None:
        """The SIGINT handler while the script runs: note, then interrupt as Python does."""
        self.pressed = True
        raise KeyboardInterrupt


_CTRL_C: ContextVar[_CtrlCWatch | None] = ContextVar("ctrl_c_watch", default=None)
"""The running console script's watch; `run_console_script` sets it and resets it, so no
state outlives a run (a test calling it twice starts clean)."""


def _pressed() -> bool:
    watch = _CTRL_C.get()
    return watch is not None and watch.pressed


def raise_if_interrupted() -> None:
    """Raise KeyboardInterrupt if Ctrl-C was pressed and no command has told it yet: a
    library swallowed it (a `try: ... except:` around an import, a weakref callback), and a
    long command asks here between its steps.  (Only under `run_console_script`.)"""
    if _pressed():
        raise KeyboardInterrupt


def _unraisable(unraisable: Any) -> None:
    # "Exception ignored in ...": a Ctrl-C that landed in a weakref callback or __del__ is
    # no traceback to print; it is noted, and told as Ctrl-C
    if not isinstance(unraisable.exc_value, KeyboardInterrupt):
        sys.__unraisablehook__(unraisable)


@contextmanager
def _ctrl_c_noted(watch: _CtrlCWatch) -> Iterator[None]:
    """Note every Ctrl-C in `watch` while a console script runs (see
    `raise_if_interrupted`); a SIGINT that is ignored (`nohup`, a background job) or someone
    else's is left alone, and only the told/not-told bookkeeping applies then."""
    token = _CTRL_C.set(watch)
    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        try:
            yield
        finally:
            _CTRL_C.reset(token)
        return
    hook = sys.unraisablehook
    signal.signal(signal.SIGINT, watch.note)
    sys.unraisablehook = _unraisable
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        sys.unraisablehook = hook
        _CTRL_C.reset(token)


def run_console_script(app: Callable[..., Any], prog_name: str) -> None:
    """Run a typer app as its console script, with a usage error (an option value out of
    its choices or bounds, a missing or unknown option) told like every other bad input:
    one line, `error: what; see 'COMMAND --help'`, exit 2.  Left to click and rich, it was
    a usage block and a box that wraps the message over several lines."""
    from typer import Abort

    empty = _empty_argument(app, prog_name, sys.argv[1:])
    if empty is not None:
        print(f"error: {empty}", file=sys.stderr)
        sys.exit(EXIT_INPUT_ERROR)
    watch = _CtrlCWatch()
    try:
        with _ctrl_c_noted(watch):
            code = app(prog_name=prog_name, standalone_mode=False)
    except KeyboardInterrupt:  # while typer builds the command line from the functions
        exit_interrupted(told=watch.told)
    except Abort:
        print("aborted", file=sys.stderr)
        sys.exit(EXIT_INTERNAL_ERROR)
    except Exception as exc:  # noqa: BLE001 - click's errors, vendored or not, told here
        if type(exc).__name__ == "NoArgsIsHelpError":  # as typer's rich_format_error tells it
            # nothing ran: the help, exit 2.  The error made it (ctx.get_help()), and typer's
            # rich help prints itself there and leaves the message empty; calling the app
            # again to print it showed the help twice
            help_text = exc.format_message()  # type: ignore[attr-defined]  # a UsageError
            if help_text:
                print(help_text)
            sys.exit(EXIT_INPUT_ERROR)
        format_message = getattr(exc, "format_message", None)
        if format_message is None:
            print(f"internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
            sys.exit(EXIT_INTERNAL_ERROR)
        context = getattr(exc, "ctx", None)
        hint = f"; see '{context.command_path} --help'" if context is not None else ""
        message = " ".join(format_message().split()).rstrip(".")
        # a choice typer checks through pydantic keeps pydantic's "Value error, " before
        # the words that matter ("'some' is not one of 'none', 'end', 'every'")
        message = message.replace(": Value error, ", ": ", 1)
        print(f"error: {message}{hint}", file=sys.stderr)
        sys.exit(getattr(exc, "exit_code", EXIT_INPUT_ERROR))
    if code == EXIT_INTERRUPTED:
        # typer turns a Ctrl-C while it reads the options into this code without a word
        exit_interrupted(told=watch.told)
    sys.exit(code if isinstance(code, int) else 0)


def _empty_argument(app: Callable[..., Any], prog_name: str, args: list[str]) -> str | None:
    """The message for an empty argument (`--out ""` or `--out=`: a shell variable left
    unset), or None.  No option or argument of a command takes an empty text, and a path
    read it as `.`: `twin replay run.csv --out "$DIR"` wrote its folders, summary.json and
    report.html into the current folder, and `twin replay ""` replayed it."""
    for k, arg in enumerate(args):
        if arg.startswith("--") and arg.endswith("=") and len(arg) > 3:
            what = f"option {arg[:-1]!r} is empty"
        elif arg == "":
            before = args[k - 1] if k else ""
            what = "an empty argument" + (f" after {before!r}" if before else "")
        else:
            continue
        command = _command_path(app, prog_name, args)
        return f"{what} (an unset shell variable?); see '{command} --help'"
    return None


def _command_path(app: Callable[..., Any], prog_name: str, args: list[str]) -> str:
    """`prog_name` and the (sub)command names that lead `args` (`twin drift fit`)."""
    import typer.main

    command = typer.main.get_command(app)  # type: ignore[arg-type]
    words = [prog_name]
    for arg in args:
        commands = getattr(command, "commands", None)
        if not commands or arg not in commands:
            break
        command = commands[arg]
        words.append(arg)
    return " ".join(words)


def exit_interrupted(*, told: bool = False) -> NoReturn:
    """End the process after a Ctrl-C: one line (`interrupted`; none if a command `told`
    it already), exit code 130.  A Ctrl-C typer or the loading caught is told here."""
    if not told:
        print(INTERRUPTED, file=sys.stderr)
    forget_keyboard_interrupt()
    sys.exit(EXIT_INTERRUPTED)


def forget_keyboard_interrupt() -> None:
    """Clear CPython's note that a KeyboardInterrupt ended a string exec or eval.

    A Ctrl-C landing in one (a dataclass's generated methods are compiled so, while a
    module loads) is noted as unhandled even when a caller catches it; under `python -m`
    the interpreter then ends the process by SIGINT once it has exited with 130 (one
    Ctrl-C of `python -m twin replay` in four did).  The note is cleared when a string
    exec starts, so an empty one clears it; a console script never reads it.
    """
    exec("")
