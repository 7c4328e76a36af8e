"""Writers for the replay outputs (CSV, JSON, VTU fields, the ParaView .pvd), each
atomic (`twin.atomic`): a crash never leaves a half-written output for --resume to trust.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Iterable, Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from twin.atomic import atomic_target, write_text_atomic


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

    with atomic_target(path) as tmp:
        meshio.write(tmp, mesh, file_format="vtu")
    return Path(path)


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
