"""What the twin may read: every input is a regular file of bounded size.

A fifo, a device or a folder given where a file is expected would block a reader forever
(`/dev/zero`, a fifo nobody writes) or fill the memory; such an input is refused with an
`InputError` naming it before a byte is read.  The `--out` side lives in `twin.io.atomic`.
"""

from __future__ import annotations

import os
import re
import stat
import tomllib
from pathlib import Path

from twin.errors import InputError

MAX_INPUT_BYTES = 512 * 2**20
"""Largest input file read (512 MiB): a day of 10 Hz samples as CSV is under 100 MiB."""


def regular_file_info(path: str | os.PathLike[str], *, use: str, column: str | None = None,
                      missing_ok: bool = False) -> os.stat_result | None:
    """`path`'s stat (through symlinks) if it names a regular file, else InputError.

    `use` says what the command wants the file for ("read file", "use as output") and
    starts the message when the file cannot be looked at; with `missing_ok` a path with
    nothing there (or a dangling symlink) gives None instead.
    """
    try:
        info = Path(path).stat()
    except OSError as exc:
        if missing_ok and isinstance(exc, FileNotFoundError):
            return None
        raise InputError(f"cannot {use}: {exc.strerror or exc}", file=str(path),
                         column=column) from None
    if stat.S_ISDIR(info.st_mode):
        raise InputError("is a folder, not a file", file=str(path), column=column)
    if not stat.S_ISREG(info.st_mode):
        raise InputError(f"is not a regular file (a device, fifo or socket); cannot {use}",
                         file=str(path), column=column)
    return info


def check_input_file(path: str | os.PathLike[str], *, column: str | None = None,
                     max_bytes: int = MAX_INPUT_BYTES) -> Path:
    """`path` if it names an existing regular file of at most `max_bytes`, else InputError."""
    info = regular_file_info(path, use="read file", column=column)
    assert info is not None  # None only with missing_ok
    if info.st_size > max_bytes:
        raise InputError(f"file of {info.st_size} bytes is larger than the {max_bytes} bytes "
                         "an input may have", file=str(path), column=column)
    return Path(path)


def read_input_bytes(path: str | os.PathLike[str], *, column: str | None = None,
                     max_bytes: int = MAX_INPUT_BYTES) -> bytes:
    """The bytes of a checked input file (`check_input_file`); OSError → InputError."""
    file = check_input_file(path, column=column, max_bytes=max_bytes)
    try:
        return file.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read file: {exc.strerror or exc}", file=str(path),
                         column=column) from None


def read_input_text(path: str | os.PathLike[str], *, column: str | None = None,
                    max_bytes: int = MAX_INPUT_BYTES) -> str:
    """The UTF-8 text of a checked input file; a bad byte names its line."""
    data = read_input_bytes(path, column=column, max_bytes=max_bytes)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise InputError("not UTF-8 text", file=str(path), row=line, column=column) from None


def parse_toml(text: str, file: str, column: str | None = None) -> dict:
    """TOML text as a dict; a syntax error names its line, and nesting too deep for the
    parser (thousands of `[`) is refused instead of exhausting the stack."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        match = re.search(r"line (\d+)", str(exc))
        row = int(match.group(1)) if match else None
        if row is None and "end of document" in str(exc):
            row = text.rstrip("\n").count("\n") + 1
        raise InputError(f"not valid TOML: {exc}", file=file, row=row, column=column) from None
    except RecursionError:
        raise InputError("not valid TOML: nested too deeply", file=file, column=column) from None


def read_toml(path: str | os.PathLike[str], *, column: str | None = None,
              max_bytes: int = 2**20) -> dict:
    """A checked input file (at most 1 MiB: a spec or scenario is a page) parsed as TOML."""
    return parse_toml(read_input_text(path, column=column, max_bytes=max_bytes), str(path),
                      column)
