"""The one atomic writer: write beside the target, then `os.replace`.

A crash or a kill never leaves a half-written output (that --resume or a reader could
mistake for a finished one).  Every file the project writes goes through `atomic_target`;
`write_bytes`, `write_text`, `write_json` and `write_csv` are its common forms.
"""

from __future__ import annotations

import csv
import io
import json
import os
import secrets
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np


@contextmanager
def atomic_target(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path in the target's folder; replace the target on success.

    The temporary name keeps the target's suffix (writers such as meshio pick the format
    from it) and is created by the writer itself, so it gets the usual permissions
    (umask), unlike mkstemp's 0600.  The parent folder is created if needed.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.stem}.{os.getpid()}.{secrets.token_hex(4)}{target.suffix}")
    try:
        yield tmp
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)


def write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write `data` to `path` atomically."""
    with atomic_target(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write `text` (UTF-8) to `path` atomically."""
    return write_bytes(path, text.encode("utf-8"))


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
