"""The one atomic writer: write beside the target, then `os.replace`.

A crash or a kill never leaves a half-written output (that --resume or a reader could
mistake for a finished one).  Every file the project writes goes through `atomic_target`;
`write_bytes`, `write_text`, `write_json` and `write_csv` are its common forms.  The rename
replaces only a regular file or nothing (`twin.io.destinations`), and temporary files a
killed writer left beside a target are removed by the next write of that target.
"""

from __future__ import annotations

import csv
import glob
import io
import json
import os
import re
import secrets
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from twin.io.destinations import refuse_special


@contextmanager
def atomic_target(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path in the target's folder; replace the target on success.

    The temporary name keeps the target's suffix (writers such as meshio pick the format
    from it) and is created by the writer itself, so it gets the usual permissions
    (umask), unlike mkstemp's 0600.  The parent folder is created if needed.
    """
    target = Path(path)
    refuse_special(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    remove_orphans_of(target)
    tmp = target.with_name(temporary_name(target.stem, target.suffix))
    try:
        yield tmp
        refuse_special(target)  # again: something may have appeared there meanwhile
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)


# `.stem.PID.HEX.suffix`: the process that writes it, so a later one can tell an orphan
_TEMPORARY = re.compile(r"^\..+\.(\d+)\.[0-9a-f]{8}(\..*)?$")
_STEM = re.compile(r"^\.(.+)\.\d+\.[0-9a-f]{8}(\..*)?$")


def temporary_name(stem: str, suffix: str = "") -> str:
    """A hidden name beside an output, unique to this process and call."""
    return f".{stem}.{os.getpid()}.{secrets.token_hex(4)}{suffix}"


def output_name(name: str) -> str:
    """The output a `temporary_name` stands for (`.run.123.0a1b2c3d.partial` → `run`), any
    other name as it is: a figure drawn in a staging folder names the run, not the folder."""
    match = _STEM.match(name)
    return match.group(1) if match else name


def is_orphan(name: str) -> bool:
    """True for a `temporary_name` whose writing process is gone (killed mid-way)."""
    match = _TEMPORARY.match(name)
    return match is not None and not _alive(int(match.group(1)))


def is_temporary(name: str) -> bool:
    """True for any `temporary_name`, orphaned or still being written."""
    return _TEMPORARY.match(name) is not None


def remove_orphans_of(target: Path) -> None:
    """Remove the temporary files a killed writer of `target` left beside it."""
    for entry in target.parent.glob(f".{glob.escape(target.stem)}.*{glob.escape(target.suffix)}"):
        if is_orphan(entry.name) and entry.is_file():
            entry.unlink(missing_ok=True)


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (OverflowError, OSError):
        return True  # another user's process, or a pid this system cannot have: keep
    return True


def write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write `data` to `path` atomically."""
    with atomic_target(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write `text` (UTF-8) to `path` atomically.  A file name's bytes that are not UTF-8
    (Python's surrogate escapes, in an error naming the file) are written as the terminal
    shows them (`bad\\udcffname.csv`): the report of a batch holding such a file failed."""
    return write_bytes(path, text.encode("utf-8", errors="backslashreplace"))


def _json_default(value: object) -> object:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def write_json(path: str | os.PathLike[str], obj: object) -> Path:
    """Indented JSON (numpy scalars and arrays as numbers and lists; NaN refused: it is not
    JSON), one trailing newline, atomically."""
    text = json.dumps(obj, indent=2, default=_json_default, allow_nan=False)
    return write_text(path, text + "\n")


def _csv_cell(v: object) -> str:
    if isinstance(v, float | np.floating):
        return f"{float(v):.6g}" if np.isfinite(v) else ""
    return str(v)


def write_csv(path: str | os.PathLike[str], header: Sequence[str],
              rows: Iterable[Sequence]) -> Path:
    """CSV with one header row; floats as %.6g, NaN/inf as an empty cell; atomically."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow([_csv_cell(v) for v in row])
    return write_text(path, buf.getvalue())
