"""Field files: the spindle section as VTU (one per time) and a ParaView .pvd collection.

One writer for every field file the project writes (`twin replay`'s `fields/`, `twin
simulate`'s `fields/`).  The section is stored as it is modelled: x = r, y = z (axial),
coordinates in metres, triangles of the thermal (split) mesh, vertex values only.

Point arrays, always these names and units:
    temperature_C     temperature, °C
    displacement_um   displacement (u_r, u_z, 0), µm, relative to the uniform temperature
                      at the start of the run (the thermal drift, as the nose probe reports it)
    von_mises_MPa     von Mises thermal stress, MPa, relative to the stress-free
                      reference temperature of the structure (`ElasticProblem.T_ref`)
Cell array:
    region            region number, 1-based, regions in sorted name order
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from twin.io.atomic import write_bytes, write_text


def field_point_data(temperature_C: np.ndarray, displacement_m: np.ndarray,
                     von_mises_Pa: np.ndarray) -> dict[str, np.ndarray]:
    """The point arrays in the documented units from SI values at the n vertices.

    displacement_m: (2, n) u_r, u_z in m; stored as (n, 3) µm with a zero third component
    (ParaView's vector convention).
    """
    n = np.shape(temperature_C)[0]
    disp_um = np.zeros((n, 3))
    disp_um[:, :2] = 1e6 * np.asarray(displacement_m, float).T
    return {
        "temperature_C": np.asarray(temperature_C, float),
        "displacement_um": disp_um,
        "von_mises_MPa": 1e-6 * np.asarray(von_mises_Pa, float),
    }


def section_mesh(points_m: np.ndarray, triangles: np.ndarray,
                 point_data: dict[str, np.ndarray], region: np.ndarray) -> Any:
    """meshio.Mesh of the section: points (2, n) r, z in m; triangles (3, m) vertex ids;
    `point_data` from `field_point_data`; region (m,) number per cell."""
    import meshio

    points = np.zeros((points_m.shape[1], 3))
    points[:, :2] = points_m.T
    return meshio.Mesh(points, [("triangle", np.asarray(triangles.T, dtype=np.int64))],
                       point_data=point_data,
                       cell_data={"region": [np.asarray(region, dtype=np.int32)]})


def write_vtu(path: str | os.PathLike[str], mesh: Any, compress: bool = False) -> Path:
    """meshio.Mesh → .vtu, atomically (`vtu_bytes`): uncompressed unless `compress`.

    Field frames stay uncompressed: a default-spindle frame takes 0.5 ms to write (meshio's
    base64: 0.7 ms) against 4-6 ms to compute its displacement and stress; zlib (level 1)
    would make it 2.6-3.3 ms for 120 against 220 kB.  A replay's start states are
    compressed (one per estimator window: 68 kB in 1.5-2 ms; meshio's zlib level 6 in
    base64: 91 kB in 4.5-5.8 ms).
    """
    return write_bytes(path, vtu_bytes(mesh, compress))


def vtu_bytes(mesh: Any, compress: bool = False) -> bytes:
    """A meshio.Mesh as VTK XML UnstructuredGrid with raw appended binary data (zlib-
    compressed blocks if `compress`); the mesh's `field_data` (1-D float arrays: a time,
    a few stated values) as VTK FieldData in ASCII with each value's repr, which reads
    back bit for bit.

    Written here, not by meshio 5.3.5, whose writer knows only inline base64 (a third
    more bytes than the values) and always stores the cell types as Int64 and the
    connectivity in the cells' own integer type.  Here the connectivity and offsets are
    Int32 where the point count allows, the types UInt8 (as VTK holds them), and the
    values keep their type (float64 fields stay float64).  The default spindle's frame:
    220 kB against meshio's 412 kB; meshio.read and VTK (ParaView, pyvista) read it.
    A 6-h replay's 360 frames: 80 MB against 148 MB.
    Appended raw data is what VTK's own writer writes by default.
    """
    from xml.sax.saxutils import quoteattr

    points = np.asarray(mesh.points, dtype=float)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise ValueError(f"points must be (n, 2) or (n, 3), got {points.shape}")
    if points.shape[1] == 2:  # VTK points have three coordinates
        points = np.column_stack([points, np.zeros(len(points))])
    n_points = len(points)
    index = np.int32 if n_points <= np.iinfo(np.int32).max else np.int64
    connectivity, offsets, types = [], [], []
    for block in mesh.cells:
        if block.type not in _VTK_CELL_TYPES:
            raise ValueError(f"cell type {block.type!r} has no VTK type here")
        nodes = np.asarray(block.data)
        connectivity.append(nodes.astype(index).ravel())
        offsets.append(np.full(len(nodes), nodes.shape[1], dtype=index))
        types.append(np.full(len(nodes), _VTK_CELL_TYPES[block.type], dtype=np.uint8))
    n_cells = sum(len(t) for t in types)
    # offsets: the end of each cell's run in the connectivity
    arrays: list[tuple[str, str, np.ndarray]] = [
        ("Points", "Points", points),
        ("Cells", "connectivity", np.concatenate(connectivity) if connectivity
         else np.zeros(0, index)),
        ("Cells", "offsets", np.cumsum(np.concatenate(offsets), dtype=index) if offsets
         else np.zeros(0, index)),
        ("Cells", "types", np.concatenate(types) if types else np.zeros(0, np.uint8)),
    ]
    arrays += [("PointData", name, np.asarray(values)) for name, values in mesh.point_data.items()]
    arrays += [("CellData", name, np.concatenate([np.asarray(b) for b in blocks]))
               for name, blocks in mesh.cell_data.items()]

    head = ['<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1" '
            'byte_order="LittleEndian"'
            + (' compressor="vtkZLibDataCompressor"' if compress else "") + ">\n"
            "<UnstructuredGrid>\n"]
    field_data = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in mesh.field_data.items()}
    if field_data:
        head.append("<FieldData>" + "".join(
            f'<DataArray type="Float64" Name={quoteattr(name)} '
            f'NumberOfTuples="{values.size}" format="ascii">'
            f'{" ".join(repr(float(v)) for v in values)}</DataArray>'
            for name, values in field_data.items()) + "</FieldData>\n")
    head.append(f'<Piece NumberOfPoints="{n_points}" NumberOfCells="{n_cells}">\n')
    blocks: list[bytes] = []
    offset = 0
    section = None
    for group, name, values in arrays:
        if group != section:
            if section is not None:
                head.append(f"</{section}>\n")
            head.append(f"<{group}>\n")
            section = group
        data = np.ascontiguousarray(values, dtype=values.dtype.newbyteorder("<"))
        components = "" if data.ndim == 1 else \
            f' NumberOfComponents="{int(np.prod(data.shape[1:]))}"'
        head.append(f'<DataArray type="{_VTK_TYPES[data.dtype.str[1:]]}" Name={quoteattr(name)}'
                    f'{components} format="appended" offset="{offset}"/>\n')
        block = _appended_block(data.tobytes(), compress)
        blocks.append(block)
        offset += len(block)
    head.append(f"</{section}>\n</Piece>\n</UnstructuredGrid>\n"
                '<AppendedData encoding="raw">\n_')
    # the newline after the data: meshio's reader of raw data takes the data up to the
    # last newline before </AppendedData>
    return "".join(head).encode("ascii") + b"".join(blocks) + \
        b"\n</AppendedData>\n</VTKFile>\n"


# meshio's cell names → VTK cell types (the cells the project writes; VTK's node order
# is meshio's for these)
_VTK_CELL_TYPES = {"line": 3, "triangle": 5, "quad": 9, "line3": 21, "triangle6": 22,
                   "quad8": 23}
_VTK_TYPES = {"f4": "Float32", "f8": "Float64", "i1": "Int8", "i2": "Int16", "i4": "Int32",
              "i8": "Int64", "u1": "UInt8", "u2": "UInt16", "u4": "UInt32", "u8": "UInt64"}
_ZLIB_BLOCK = 32768  # bytes of values per compressed block (VTK's default)


def _appended_block(data: bytes, compress: bool) -> bytes:
    """One array's bytes in the appended section: a UInt32 byte count then the values, or
    (compressed) the block count, block size, last block's size and each block's
    compressed size, then the zlib blocks (VTK's layout)."""
    if not compress:
        return np.array([len(data)], dtype="<u4").tobytes() + data
    import zlib

    # level 1: a few per cent larger than the default level 6 at a third of its time
    chunks = [zlib.compress(data[i:i + _ZLIB_BLOCK], 1) for i in range(0, len(data), _ZLIB_BLOCK)]
    last = len(data) - (len(chunks) - 1) * _ZLIB_BLOCK if chunks else 0
    header = np.array([len(chunks), _ZLIB_BLOCK, last, *map(len, chunks)], dtype="<u4")
    return header.tobytes() + b"".join(chunks)


def read_vtu(path: str | os.PathLike[str]) -> Any:
    """A .vtu file as a meshio.Mesh (its FieldData in `field_data`); InputError naming the
    file if it is not a readable one."""
    import contextlib
    import io

    from meshio import vtu

    from twin.errors import InputError

    try:  # the format's reader itself: meshio.read prints and exits on a bad file
        with contextlib.redirect_stdout(io.StringIO()):
            return vtu.read(str(path))
    except Exception as exc:  # noqa: BLE001 - meshio raises many kinds on a bad file
        why = f" ({exc})" if str(exc).strip() else ""
        raise InputError(f"not a readable .vtu file{why}", file=str(path)) from None


def write_pvd(path: str | os.PathLike[str], entries: Sequence[tuple[float, str]]) -> Path:
    """ParaView collection, atomically: (time s, .vtu path relative to the .pvd) per entry."""
    # here, not at the top: xml.sax.saxutils imports urllib.request, http and ssl (about
    # 10 ms of a cold replay, whose fields a forked child writes)
    from xml.sax.saxutils import quoteattr

    lines = [
        '<?xml version="1.0"?>',
        '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
        "  <Collection>",
    ]
    for t, file in entries:
        lines.append(f'    <DataSet timestep="{t:g}" group="" part="0" file={quoteattr(file)}/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    return write_text(path, "\n".join(lines))


def write_field_series(out_dir: str | os.PathLike[str],
                       frames: Iterable[tuple[float, str, Any]]) -> Path:
    """Write each (time s, relative .vtu name, meshio.Mesh) frame under `out_dir` (frames
    may be a generator: one mesh in memory at a time), then the collection
    `out_dir/fields.pvd` that ParaView opens as a time series."""
    out_dir = Path(out_dir)
    entries = []
    for t, name, mesh in frames:
        write_vtu(out_dir / name, mesh)
        entries.append((t, name))
    return write_pvd(out_dir / "fields.pvd", entries)
