"""ANSYS archive (CDB) exchange: NBLOCK / EBLOCK / CMBLOCK.

Writing: `write_cdb` stores an AxiMesh as MAPDL would archive it — ET/KEYOPT (PLANE55,
axisymmetric), MP per material, NBLOCK (thermal-mesh nodes: the two faces of a contact
interface are separate, coincident nodes), EBLOCK (triangles as the degenerate quad K = L),
CMBLOCK element components per region and node components per boundary and per interface
face (NAME_A, NAME_B).  Contact pairs themselves are not archived as CONTA172/TARGE169
elements: in a session they act through the mesh's interfaces (real sets 101, 102, ...).

Reading: the block parsers take the fixed-width format line that precedes the data, as
MAPDL and mapdl-archive write it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from apdl_like.errors import ApdlError
from apdl_like.writer import DeckLayout, component_name

if TYPE_CHECKING:
    from twin.fem import AxiMesh

_NFORMAT = re.compile(
    r"\(\s*(\d+)\s*i\s*(\d+)\s*,\s*(\d+)\s*e\s*(\d+)\s*\.\s*\d+(?:\s*e\s*\d+)?\s*\)",
    re.I,
)
_IFORMAT = re.compile(r"\(\s*(\d+)\s*i\s*(\d+)\s*\)", re.I)


MAX_FORMAT_FIELDS = 64
"""Most fields and characters per field a block's format line may declare (MAPDL writes
19i9, 8i10, 3i9 and 6e21.13e3): `(999999999i9)` would make a reader loop for ever."""
def _checked_format(block: str, *pairs: tuple[int, int]) -> None:
    for count, width in pairs:
        if not (1 <= count <= MAX_FORMAT_FIELDS and 1 <= width <= MAX_FORMAT_FIELDS):
            raise ApdlError(f"{block} format declares {count} fields of {width} characters; "
                            f"each must lie in 1..{MAX_FORMAT_FIELDS}")


def _fixed(line: str, width: int, count: int, start: int = 0) -> list[str]:
    return [line[start + k * width : start + (k + 1) * width] for k in range(count)]


def parse_nblock(lines: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Node numbers and (n, 3) coordinates from an NBLOCK's format line and data."""
    m = _NFORMAT.fullmatch(lines[0].strip())
    if m is None:
        raise ApdlError(f"NBLOCK format {lines[0].strip()!r} is not of the form (3i9,6e21.13e3)")
    ni, iw, nf, fw = (int(g) for g in m.groups())
    _checked_format("NBLOCK", (ni, iw), (nf, fw))
    ids, xyz = [], []
    for k, line in enumerate(lines[1:], start=1):
        if not line.strip():
            continue
        try:
            ints = _fixed(line, iw, ni)
            floats = [f for f in _fixed(line, fw, nf, ni * iw) if f.strip()]
            ids.append(int(ints[0]))
            coords = [float(f.replace("D", "E").replace("d", "e")) for f in floats[:3]]
        except ValueError:
            raise ApdlError(f"NBLOCK data line {k} is not in the declared format") from None
        if not np.all(np.isfinite(coords)):
            raise ApdlError(f"NBLOCK data line {k}: node {ids[-1]} has a non-finite coordinate")
        xyz.append(coords + [0.0] * (3 - len(coords)))
    return np.asarray(ids, np.int64), np.asarray(xyz, float).reshape(-1, 3)


def parse_eblock(lines: tuple[str, ...]) -> list[tuple[int, int, int, int, list[int]]]:
    """(element number, type, material, real, node numbers) per element (solid format)."""
    m = _IFORMAT.fullmatch(lines[0].strip())
    if m is None:
        raise ApdlError(f"EBLOCK format {lines[0].strip()!r} is not of the form (19i9)")
    _checked_format("EBLOCK", (int(m.group(1)), int(m.group(2))))
    width = int(m.group(2))
    out = []
    rows = iter(enumerate(lines[1:], start=1))
    for k, line in rows:
        if not line.strip():
            continue
        try:
            values = [int(v) for v in _fixed(line, width, len(line.rstrip()) // width)]
            if len(values) < 11:
                raise ValueError
            n_nodes = values[8]
            nodes = values[11:]
            while len(nodes) < n_nodes:  # more than 8 nodes continue on the next line
                _, more = next(rows)
                nodes += [int(v) for v in _fixed(more, width, len(more.rstrip()) // width)]
        except (ValueError, StopIteration):
            raise ApdlError(f"EBLOCK data line {k} is not in the solid-element format") from None
        out.append((values[10], values[1], values[0], values[2], nodes[:n_nodes]))
    return out


def parse_cmblock(lines: tuple[str, ...]) -> np.ndarray:
    """Entity numbers of a CMBLOCK (a negative number closes a range from the previous one)."""
    m = _IFORMAT.fullmatch(lines[0].strip())
    if m is None:
        raise ApdlError(f"CMBLOCK format {lines[0].strip()!r} is not of the form (8i10)")
    _checked_format("CMBLOCK", (int(m.group(1)), int(m.group(2))))
    width = int(m.group(2))
    values: list[int] = []
    for line in lines[1:]:
        try:
            values += [int(v) for v in _fixed(line, width, len(line.rstrip()) // width)]
        except ValueError:
            raise ApdlError("CMBLOCK data is not in the declared format") from None
    out: list[int] = []
    for v in values:
        if v < 0:
            if not out or -v < out[-1] or -v - out[-1] > 50_000_000:
                raise ApdlError("CMBLOCK range without a valid start")
            out += range(out[-1] + 1, -v + 1)
        else:
            out.append(v)
    return np.unique(np.asarray(out, np.int64))


def _cmblock(name: str, entity: str, numbers: np.ndarray) -> list[str]:
    numbers = np.sort(np.asarray(numbers, np.int64))
    out = [f"CMBLOCK,{name},{entity},{numbers.size:8d}", "(8i10)"]
    for k in range(0, numbers.size, 8):
        out.append("".join(f"{v:10d}" for v in numbers[k : k + 8]))
    return out


def cdb_text(mesh: AxiMesh, materials: Mapping[str, object] | None = None,
             title: str = "") -> str:
    """The archive text of an AxiMesh (see the module docstring)."""
    thermal = mesh.thermal
    n = thermal.p.shape[1]
    layout = DeckLayout.for_mesh(mesh)
    region_names = sorted(mesh.regions)
    cell_mat = np.ones(mesh.n_cells, np.int64)
    mat_regions = sorted(materials) if materials else region_names
    for i, name in enumerate(mat_regions, start=1):
        cell_mat[mesh.region(name)] = i
    out = [f"/COM,{title or 'spindle twin mesh'} (apdl_like export-cdb)", "/PREP7", "/NOPR",
           f"/TITLE,{title or 'spindle twin mesh'}", "ET,1,55", "KEYOPT,1,3,1"]
    if materials:
        for i, name in enumerate(mat_regions, start=1):
            m = materials[name]
            out.append(f"! material {i}: {name}")
            for label, value in (("KXX", m.k), ("DENS", m.rho), ("C", m.c), ("EX", m.E),
                                 ("PRXY", m.nu), ("ALPX", m.alpha)):
                out.append(f"MP,{label},{i},{value!r}")
    out += [f"NBLOCK,6,SOLID,{n:10d},{n:10d}", "(3i9,6e21.13e3)"]
    for i in range(n):
        x, y = thermal.p[:, i]
        out.append(f"{i + 1:9d}{0:9d}{0:9d}{x:21.13E}{y:21.13E}{0.0:21.13E}")
    out.append("N,R5.3,LOC,       -1,")
    ne = mesh.n_cells
    out += [f"EBLOCK,19,SOLID,{ne:10d},{ne:10d}", "(19i9)"]
    t = thermal.t + 1
    for e in range(ne):
        head = (cell_mat[e], 1, 1, 1, 0, 0, 0, 0, 4, 0, e + 1)
        nodes = (t[0, e], t[1, e], t[2, e], t[2, e])
        out.append("".join(f"{v:9d}" for v in (*head, *nodes)))
    out.append(f"{-1:9d}")
    for name in region_names:
        out += _cmblock(layout.regions[name], "ELEM", mesh.regions[name] + 1)
    for name in sorted(mesh.boundaries):
        out += _cmblock(layout.boundaries[name], "NODE",
                        np.unique(thermal.facets[:, mesh.boundaries[name]]) + 1)
    for name in sorted(mesh.interfaces):
        iface = mesh.interfaces[name]
        for side, facets in (("A", iface.facets_a), ("B", iface.facets_b)):
            out += _cmblock(component_name(name)[:30] + f"_{side}", "NODE",
                            np.unique(thermal.facets[:, facets]) + 1)
    out += ["/GOPR", "FINISH", ""]
    return "\n".join(out)


def write_cdb(mesh: AxiMesh, path: str | Path, materials: Mapping[str, object] | None = None,
              title: str = "") -> Path:
    """Write the archive atomically."""
    from twin.io.atomic import write_bytes

    return write_bytes(path, cdb_text(mesh, materials, title).encode("ascii"))
