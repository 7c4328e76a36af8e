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

from twin.io.atomic import atomic_target, write_text


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
    """meshio.Mesh → .vtu (binary, uncompressed unless `compress`: zlib), atomically; the
    mesh's `field_data` (1-D float arrays: a time, a few stated values) as VTK FieldData.

    Uncompressed: zlib took seven eighths of the write (7.7 of 8.7 ms per frame of the
    default spindle, a tenth of a 3-method replay's run time) for files 2.7 times smaller
    (150 against 410 kB).  A replay's start states are compressed (one per estimator
    window: 90 against 300 kB).
    """
    import meshio

    field_data = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in mesh.field_data.items()}
    with atomic_target(path) as tmp:
        meshio.write(tmp, mesh, file_format="vtu", compression="zlib" if compress else None)
        if field_data:
            _add_field_data(Path(tmp), field_data)
    return Path(path)


def _add_field_data(path: Path, field_data: dict[str, np.ndarray]) -> None:
    """Put `field_data` in the written file as FieldData of its grid (meshio 5 reads it but
    does not write it); ASCII with each value's repr, which reads back bit for bit."""
    arrays = "".join(
        f'<DataArray type="Float64" Name="{name}" NumberOfTuples="{values.size}" '
        f'format="ascii">{" ".join(repr(float(v)) for v in values)}</DataArray>'
        for name, values in field_data.items())
    text = path.read_text(encoding="ascii")
    at = text.index("<Piece ")
    path.write_text(f"{text[:at]}<FieldData>{arrays}</FieldData>\n{text[at:]}",
                    encoding="ascii")


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
