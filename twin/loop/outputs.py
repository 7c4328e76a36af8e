"""Atomic writers for the replay outputs (CSV, JSON, VTU fields, the ParaView .pvd).

Every file is written to a temporary name in its own folder and moved into place with
os.replace, so a crash or a kill never leaves a half-written output that --resume would
mistake for a finished one.
"""

from __future__ import annotations

import csv
import io
import json
import os
import tempfile
from collections.abc import Iterable, Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def publish(tmp: str | Path, path: Path) -> Path:
    """Move a finished temporary file into place with ordinary file permissions.

    mkstemp creates files readable by their owner only; outputs are meant to be shared.
    """
    os.chmod(tmp, 0o666 & ~_umask())
    os.replace(tmp, path)
    return path


def temporary_beside(path: Path, suffix: str) -> str:
    """A new empty temporary file in `path`'s folder (created, closed)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=suffix)
    os.close(fd)
    return tmp


def write_bytes_atomic(path: str | Path, data: bytes) -> Path:
    path = Path(path)
    tmp = temporary_beside(path, ".tmp")
    try:
        Path(tmp).write_bytes(data)
        return publish(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_text_atomic(path: str | Path, text: str) -> Path:
    return write_bytes_atomic(path, text.encode("utf-8"))


def _json_default(value):  # noqa: ANN001, ANN202
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def write_json_atomic(path: str | Path, obj: object) -> Path:
    text = json.dumps(obj, indent=2, default=_json_default, allow_nan=False)
    return write_text_atomic(path, text + "\n")


def write_csv_atomic(path: str | Path, header: Sequence[str], rows: Iterable[Sequence]) -> Path:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    for row in rows:
        writer.writerow(["" if _is_nan(v) else _fmt(v) for v in row])
    return write_text_atomic(path, buf.getvalue())


def _is_nan(v: object) -> bool:
    return isinstance(v, float | np.floating) and not np.isfinite(v)


def _fmt(v: object) -> str:
    if isinstance(v, float | np.floating):
        return f"{float(v):.6g}"
    return str(v)


def write_vtu_atomic(path: str | Path, mesh) -> Path:  # noqa: ANN001 - meshio.Mesh
    """meshio.Mesh → .vtu (binary, compressed), atomically."""
    import meshio

    path = Path(path)
    tmp = temporary_beside(path, ".vtu")
    try:
        meshio.write(tmp, mesh, file_format="vtu")
        return publish(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_pvd_atomic(path: str | Path, entries: Sequence[tuple[float, str]]) -> Path:
    """ParaView collection: (time s, relative .vtu path) per entry."""
    lines = [
        '<?xml version="1.0"?>',
        '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
        "  <Collection>",
    ]
    for t, file in entries:
        lines.append(f'    <DataSet timestep="{t:g}" group="" part="0" file={quoteattr(file)}/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    return write_text_atomic(path, "\n".join(lines))
