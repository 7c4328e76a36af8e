"""What the twin may read: every input is a regular file of bounded size.

A fifo, a device or a folder given where a file is expected would block a reader forever
(`/dev/zero`, a fifo nobody writes) or fill the memory; such an input is refused with an
`InputError` naming it before a byte is read.  The `--out` side lives in `twin.io.atomic`.
"""

from __future__ import annotations

import codecs
import os
import re
import stat
import tomllib
from pathlib import Path
from typing import Any

from twin.errors import InputError, TomlError, key_path

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
    """The UTF-8 text of a checked input file; a bad byte names its line.  A file whose
    lines all end in a bare CR (classic Mac OS, Excel's "CSV (Macintosh)") reads as if
    they ended in LF, as editors show it: read as it was, it was one line, a comment, and
    a run "an empty file", a profile "not a readable CSV line", a scenario not TOML."""
    data = read_input_bytes(path, column=column, max_bytes=max_bytes)
    if b"\r" in data and b"\n" not in data:
        data = data.replace(b"\r", b"\n")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        if data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):  # Excel's "Unicode"
            raise InputError("UTF-16 text; save it as UTF-8", file=str(path),
                             column=column) from None
        line = data[: exc.start].count(b"\n") + 1
        raise InputError(f"not UTF-8 text{_legacy_hint(data[exc.start:exc.start + 1])}",
                         file=str(path), row=line, column=column, row_unit="line") from None


def _legacy_hint(byte: bytes) -> str:
    """What a byte that is no UTF-8 most likely is: Excel's "CSV (Comma delimited)" on
    Windows writes Windows-1252 ('ü' as 0xFC), and "not UTF-8 text" alone left the user
    to guess what to change."""
    try:
        character = byte.decode("cp1252")
    except UnicodeDecodeError:
        return f" (byte 0x{byte[0]:02X}); save it as UTF-8"
    return (f" (byte 0x{byte[0]:02X}, {character!r} in Windows-1252 or Latin-1); save it as "
            "UTF-8 (Excel: 'CSV UTF-8')")


MAX_TOML_BYTES = 2**20
"""Largest TOML input (a scenario, a spindle spec): the bundled spec is 15 kB."""


def read_toml(path: str | os.PathLike[str], *, column: str | None = None,
              max_bytes: int = MAX_TOML_BYTES) -> tuple[str, dict]:
    """The text of a TOML input file and its data (`parse_toml`); a file that cannot be
    read as text is a TomlError too, told as a syntax error is (`file, line 2: ...`).
    `column`: the option that named the file."""
    try:
        text = read_input_text(path, column=column, max_bytes=max_bytes)
    except InputError as exc:
        raise TomlError(exc.reason, file=exc.file, line=exc.row, key=exc.column) from None
    return text, parse_toml(text, str(path))


def parse_toml(text: str, file: str) -> dict:
    """TOML text as a dict; a syntax error names its line, and nesting too deep for the
    parser (thousands of `[`) is refused instead of exhausting the stack."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        match = re.search(r"line (\d+)", str(exc))
        row = int(match.group(1)) if match else None
        if row is None and "end of document" in str(exc):
            row = text.rstrip("\n").count("\n") + 1
        raise TomlError(f"not valid TOML: {exc}", file=file, line=row) from None
    except RecursionError:
        raise TomlError("not valid TOML: nested too deeply", file=file) from None


def toml_error(text: str | None, file: str, loc: tuple, message: str,
               more: int = 0) -> TomlError:
    """TomlError at `loc` (`('faults', 'dropouts', 1)`) of a TOML file, at its line when
    the `text` is known; `more`: how many other problems the file has."""
    if more > 0:
        message += f" (and {more} more problem{'s' if more > 1 else ''})"
    return TomlError(message, file=file, line=None if text is None else toml_line_of(text, loc),
                     key=key_path(loc) or None)


def toml_validation_error(exc: Any, text: str | None, file: str) -> TomlError:
    """The first problem of a pydantic `ValidationError` of TOML data (a scenario, a
    spindle spec) as a TomlError: one wording for every TOML file."""
    loc, message = TomlError.validation_problem(exc)
    return toml_error(text, file, loc, message, exc.error_count() - 1)


def toml_line_of(text: str, loc: tuple) -> int | None:
    """Best-effort line of a location (`faults.dropouts.1.sensor`, `parts.3.region`) in
    TOML text, for a validation error to name: the line of a list's item itself (tomllib
    keeps no positions, so the text is searched), else of its key, else of its table's
    header; None if none is there (a missing table)."""
    lines = text.split("\n")
    path = [str(k) for k in loc]
    header_at, body_from, used = None, 0, 0
    for n in range(len(path), 0, -1):  # the deepest [a.b] or k-th [[a.b]] header there is
        dotted = r"\s*\.\s*".join(map(re.escape, path[:n]))
        if n < len(path) and path[n].isdigit():  # an item of an array of tables
            hits = [i for i, ln in enumerate(lines)
                    if re.match(r"^\s*\[\[\s*" + dotted + r"\s*\]\]", ln)]
            if len(hits) > int(path[n]):
                header_at, used = hits[int(path[n])], n + 1
                break
        hit = next((i for i, ln in enumerate(lines)
                    if re.match(r"^\s*\[\s*" + dotted + r"\s*\]", ln)), None)
        if hit is not None:
            header_at, used = hit, n
            break
    if header_at is not None:
        body_from = header_at + 1
    rest = path[used:]
    if rest and not rest[0].isdigit():
        key = re.compile(r"^\s*" + re.escape(rest[0]) + r"\s*=")
        for i in range(body_from, len(lines)):
            if header_at is not None and lines[i].lstrip().startswith("["):
                break
            if key.match(lines[i]):
                if len(rest) > 1 and rest[1].isdigit():
                    offset = sum(len(ln) + 1 for ln in lines[:i]) + lines[i].index("=") + 1
                    item = _array_item_offset(text, offset, int(rest[1]))
                    if item is not None:
                        return text.count("\n", 0, item) + 1
                return i + 1
    return None if header_at is None else header_at + 1


def _array_item_offset(text: str, offset: int, index: int) -> int | None:
    """Offset in `text` of item `index` of the TOML array whose value starts after
    `offset` (just past its key's `=`); None if no array, or fewer items, is there.
    Strings and comments are skipped: a `,` or `[` inside them separates nothing."""
    i = offset
    while i < len(text) and text[i] in " \t":
        i += 1
    if i >= len(text) or text[i] != "[":
        return None
    depth, count, expecting = 0, -1, False
    while i < len(text):
        c = text[i]
        if c == "#":
            i = text.find("\n", i)
            if i < 0:
                return None
            continue
        if depth == 1 and expecting and c not in " \t\r\n,]":
            count, expecting = count + 1, False
            if count == index:
                return i
        if c in "\"'":
            i = _string_end(text, i)
            continue
        if c in "[{":
            depth += 1
            expecting = expecting or depth == 1
        elif c in "]}":
            depth -= 1
            if depth == 0:
                return None
        elif c == "," and depth == 1:
            expecting = True
        i += 1
    return None


def _string_end(text: str, i: int) -> int:
    """Offset just past the TOML string starting at `i` (basic or literal, one-line or
    triple-quoted); the text's end for an unterminated one."""
    quote = text[i]
    delimiter = quote * 3 if text.startswith(quote * 3, i) else quote
    j = i + len(delimiter)
    while j < len(text):
        if quote == '"' and text[j] == "\\":
            j += 2
            continue
        if text.startswith(delimiter, j):
            return j + len(delimiter)
        j += 1
    return len(text)
