"""Parametric axisymmetric geometry and mesh of the motorized spindle (pygmsh + gmsh).

spec (twin.spindle.spec.SpindleSpec) → rectangles in the (r, z) half-plane → OCC
fragments (conformal at every touching edge) → triangles (Frontal-Delaunay) → named sets:

* regions: one per spec region (cells of all its parts);
* boundaries: every outer facet gets exactly one name of `BOUNDARY_NAMES`, decided facet
  by facet from the region it belongs to and what lies in front of it (rules in
  `classify_boundary`);
* interfaces: the facets shared by a bearing's outer ring and its sleeve, named by the
  bearing's `interface` (contact_front, contact_rear).

`build_mesh(spec, size_factor)` returns plain arrays (`SpindleMesh`); `write_msh` writes
them as a gmsh 2.2 file with physical groups (what `twin.fem.AxiMesh.from_msh` reads);
`mesh_quality` gives the minimum angle and the worst aspect ratio.  Coordinates are metres
with x = r and y = z.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin.io.atomic import atomic_target
from twin.signal_guard import signals_kept
from twin.spindle.spec import BOUNDARY_NAMES, PartSpec, Rectangle, SpindleSpec

if TYPE_CHECKING:
    from pygmsh.occ.rectangle import Rectangle as OccRectangle

MM = 1e-3
_TRIANGLE = 2  # gmsh element type: 3-node triangle


@dataclass
class SpindleMesh:
    """Triangle mesh with named sets, all plain numpy arrays (SI: metres)."""

    points: np.ndarray  # (n_nodes, 2) r, z
    triangles: np.ndarray  # (n_cells, 3) node indices
    cell_region: np.ndarray  # (n_cells,) region name per cell
    lines: dict[str, np.ndarray] = field(default_factory=dict)  # name -> (n_edges, 2)

    @property
    def regions(self) -> dict[str, np.ndarray]:
        return {str(n): np.where(self.cell_region == n)[0] for n in np.unique(self.cell_region)}


# ------------------------------------------------------------------------- meshing
def _part_size_m(part: PartSpec, spec: SpindleSpec, size_factor: float) -> float:
    thin = min(part.r_outer_mm - part.r_inner_mm, part.z_end_mm - part.z_start_mm)
    local = min(spec.mesh.element_size_mm, thin / spec.mesh.min_elements_across)
    return local * size_factor * MM


def build_mesh(spec: SpindleSpec, size_factor: float = 1.0) -> SpindleMesh:
    """Mesh the spindle of `spec`; `size_factor` < 1 refines (element size × factor)."""
    if not (np.isfinite(size_factor) and size_factor > 0):
        raise ValueError(f"size_factor must be positive, got {size_factor}")
    import gmsh
    import pygmsh

    with signals_kept(), pygmsh.occ.Geometry() as geom:
        gmsh.option.setNumber("General.Terminal", 0)
        def rectangle(box: Rectangle) -> OccRectangle:  # a spec part or channel (r/z in mm)
            return geom.add_rectangle(
                [box.r_inner_mm * MM, box.z_start_mm * MM, 0.0],
                (box.r_outer_mm - box.r_inner_mm) * MM,
                (box.z_end_mm - box.z_start_mm) * MM,
            )

        parts = [rectangle(p) for p in spec.parts]
        channels = [rectangle(c) for c in spec.coolant_channels]
        occ = gmsh.model.occ
        occ.synchronize()
        part_tags = [(2, int(p._id)) for p in parts]
        channel_tags = [(2, int(c._id)) for c in channels]
        _, pieces = occ.fragment(part_tags, channel_tags)
        void = {tag for piece in pieces[len(parts):] for _, tag in piece}
        surface_part: dict[int, int] = {}
        for i, piece in enumerate(pieces[: len(parts)]):
            for _, tag in piece:
                if tag not in void:
                    surface_part[tag] = i
        occ.synchronize()

        # local sizes: thin parts (bearing rings, sleeves) get several elements across,
        # and so do the walls around the coolant channels
        sizes = [_part_size_m(p, spec, size_factor) for p in spec.parts]
        owners = [([(2, tag)], sizes[i]) for tag, i in surface_part.items()]
        owners += [
            (piece, _part_size_m(c, spec, size_factor))
            for c, piece in zip(spec.coolant_channels, pieces[len(parts):], strict=True)
        ]
        point_size: dict[int, float] = {}
        for dim_tags, size in owners:
            for _, pt in gmsh.model.getBoundary(dim_tags, combined=False, recursive=True):
                point_size[pt] = min(point_size.get(pt, np.inf), size)
        if void:
            occ.remove([(2, t) for t in sorted(void)])
            occ.synchronize()
        for pt, size in point_size.items():
            gmsh.model.mesh.setSize([(0, pt)], size)
        gmsh.option.setNumber("Mesh.MeshSizeMax", spec.mesh.element_size_mm * size_factor * MM)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay: well-shaped triangles
        gmsh.option.setNumber("Mesh.RandomSeed", 1)
        gmsh.model.mesh.generate(2)

        node_tags, coords, _ = gmsh.model.mesh.getNodes()
        index = np.full(int(node_tags.max()) + 1, -1, dtype=np.int64)
        index[node_tags.astype(np.int64)] = np.arange(node_tags.size)
        points = coords.reshape(-1, 3)[:, :2].copy()
        tri_blocks, region_blocks = [], []
        for tag, i in sorted(surface_part.items()):
            types, _, nodes = gmsh.model.mesh.getElements(2, tag)
            for etype, enodes in zip(types, nodes, strict=True):
                if etype != _TRIANGLE:
                    raise RuntimeError(f"gmsh produced element type {etype}, expected triangles")
                tri = index[enodes.astype(np.int64)].reshape(-1, 3)
                tri_blocks.append(tri)
                region_blocks.append(np.full(tri.shape[0], spec.parts[i].region, dtype=object))

    triangles = np.vstack(tri_blocks)
    cell_region = np.concatenate(region_blocks)
    # drop geometry points no triangle uses (e.g. corners of removed channels)
    used = np.unique(triangles)
    renumber = np.full(points.shape[0], -1, dtype=np.int64)
    renumber[used] = np.arange(used.size)
    points, triangles = points[used], renumber[triangles]
    points[np.abs(points[:, 0]) < 1e-12, 0] = 0.0  # exactly on the axis
    mesh = SpindleMesh(points=points, triangles=triangles, cell_region=cell_region)
    mesh.lines = _named_lines(mesh, spec)
    return mesh


# ------------------------------------------------------------------ named facets
def _edges(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All cell edges (sorted node pairs), their cell and the cell's opposite vertex."""
    t = triangles
    edges = np.vstack([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    opposite = np.concatenate([t[:, 2], t[:, 0], t[:, 1]])
    cell = np.tile(np.arange(t.shape[0]), 3)
    return np.sort(edges, axis=1), cell, opposite


def _ray_escapes(spec: SpindleSpec, start: np.ndarray, normal: np.ndarray) -> bool:
    """True if a ray from `start` (mm) along the axis-aligned `normal` meets no part."""
    r, z = start
    axis = int(np.argmax(np.abs(normal)))
    sign = np.sign(normal[axis])
    for p in spec.parts:
        if axis == 0:  # radial ray at fixed z
            if p.z_start_mm < z < p.z_end_mm and (
                (sign > 0 and p.r_outer_mm > r) or (sign < 0 and p.r_inner_mm < r)
            ):
                return False
        else:  # axial ray at fixed r
            if p.r_inner_mm < r < p.r_outer_mm and (
                (sign > 0 and p.z_end_mm > z) or (sign < 0 and p.z_start_mm < z)
            ):
                return False
    return True


def classify_boundary(spec: SpindleSpec, region: str, mid_mm: np.ndarray,
                      normal: np.ndarray) -> str:
    """Name of an outer facet from its region, midpoint (mm) and outward unit normal.

    Rules, first match wins:
      1. on r = 0                                      → axis
      2. in front of it lies a coolant channel         → coolant
      3. rotor: outer diameter → air_gap_rotor, front/rear faces → rotor_end_front/_rear
      4. stator bore                                   → air_gap_stator
      5. rotating regions (spec.spindle.rotating_regions), facing open air:
         the front end face → nose_face, other front faces → nose_outer, rear → shaft_rear;
         facing the inside of the spindle → shaft_internal
      6. stationary regions facing open air: the mount face (spec.structure) → mount,
         otherwise housing_outer; facing the inside of the spindle → internal_air
    "Facing open air" means a ray from the facet along its normal meets no part.
    """
    eps = 1e-3  # mm: step off the facet into the void in front of it
    r, z = mid_mm
    axis = int(np.argmax(np.abs(normal)))
    n = np.zeros(2)
    n[axis] = np.sign(normal[axis])
    if r < 1e-6 and axis == 0:
        return "axis"
    ahead = np.asarray(mid_mm) + eps * n
    if any(c.contains(ahead[0], ahead[1]) for c in spec.coolant_channels):
        return "coolant"
    if region == spec.motor.rotor:
        if axis == 0 and n[0] > 0:
            return "air_gap_rotor"
        if axis == 1:
            return "rotor_end_front" if n[1] > 0 else "rotor_end_rear"
    if region == spec.motor.stator and axis == 0 and n[0] < 0:
        return "air_gap_stator"
    escapes = _ray_escapes(spec, ahead, n)
    if region in spec.spindle.rotating_regions:
        if not escapes:
            return "shaft_internal"
        shaft = spec.region_box("shaft")
        front = z > 0.5 * (shaft.z_start_mm + shaft.z_end_mm)
        if front and axis == 1 and n[1] > 0:
            return "nose_face"
        return "nose_outer" if front else "shaft_rear"
    if not escapes:
        return "internal_air"
    st = spec.structure
    if (axis == 1 and n[1] < 0 and abs(z - st.mount_z_mm) < 1e-6
            and st.mount_r_min_mm - 1e-6 <= r <= st.mount_r_max_mm + 1e-6):
        return "mount"
    return "housing_outer"


def _named_lines(mesh: SpindleMesh, spec: SpindleSpec) -> dict[str, np.ndarray]:
    edges, cell, opposite = _edges(mesh.triangles)
    key = edges[:, 0] * mesh.points.shape[0] + edges[:, 1]
    order = np.argsort(key, kind="stable")
    key_sorted = key[order]
    first = np.r_[True, key_sorted[1:] != key_sorted[:-1]]
    starts = np.where(first)[0]
    counts = np.diff(np.r_[starts, key_sorted.size])
    lines: dict[str, list[np.ndarray]] = {name: [] for name in BOUNDARY_NAMES}
    interface_of = {}
    for side in ("front", "rear"):
        b = spec.bearings[side]
        interface_of[frozenset((b.outer_ring, b.sleeve))] = b.interface
        lines[b.interface] = []
    p_mm = mesh.points / MM
    for s, c in zip(starts, counts, strict=True):
        e = order[s]
        if c == 1:
            a, b = p_mm[edges[e, 0]], p_mm[edges[e, 1]]
            mid = 0.5 * (a + b)
            tangent = b - a
            normal = np.array([tangent[1], -tangent[0]])
            if np.dot(normal, mid - p_mm[opposite[e]]) < 0:
                normal = -normal
            name = classify_boundary(spec, mesh.cell_region[cell[e]], mid, normal)
            lines[name].append(edges[e])
        elif c == 2:
            pair = frozenset(mesh.cell_region[cell[order[s:s + 2]]])
            if pair in interface_of:
                lines[interface_of[pair]].append(edges[e])
        else:
            raise RuntimeError("non-manifold mesh: an edge is shared by three cells")
    out = {k: np.array(v, dtype=np.int64).reshape(-1, 2) for k, v in lines.items() if v}
    for side in ("front", "rear"):
        name = spec.bearings[side].interface
        if name not in out:
            raise ValueError(
                f"bearings.{side}: outer ring and sleeve do not touch, interface {name!r} is empty"
            )
    return out


# ------------------------------------------------------------------ quality, I/O
def mesh_quality(points: np.ndarray, triangles: np.ndarray) -> dict[str, float]:
    """Minimum interior angle (degrees) and worst aspect ratio (longest edge / shortest
    altitude · √3/2, 1 for an equilateral triangle) of a triangle mesh."""
    p = points[triangles]  # (m, 3, 2)
    e = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 1], p[:, 0] - p[:, 2]], axis=1)
    length = np.linalg.norm(e, axis=2)
    area = 0.5 * np.abs(e[:, 0, 0] * e[:, 2, 1] - e[:, 0, 1] * e[:, 2, 0])
    angles = []
    for i in range(3):
        u, v = -e[:, i - 1], e[:, i]
        cos = np.sum(u * v, axis=1) / (length[:, i - 1] * length[:, i])
        angles.append(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    longest = length.max(axis=1)
    min_altitude = 2.0 * area / longest
    aspect = longest / min_altitude * (np.sqrt(3.0) / 2.0)
    return {
        "min_angle_deg": float(np.min(angles)),
        "max_aspect": float(aspect.max()),
        "min_area_m2": float(area.min()),
        "n_nodes": int(points.shape[0]),
        "n_cells": int(triangles.shape[0]),
    }


def write_msh(mesh: SpindleMesh, path: str | Path) -> Path:
    """Write `mesh` as gmsh 2.2 ASCII with named physical groups, atomically."""
    import meshio

    path = Path(path)
    region_names = sorted(set(mesh.cell_region))
    line_names = sorted(mesh.lines)
    field_data = {}
    tag = 0
    region_tag = {}
    for name in region_names:
        tag += 1
        region_tag[name] = tag
        field_data[name] = np.array([tag, 2])
    line_edges, line_tags = [], []
    for name in line_names:
        tag += 1
        field_data[name] = np.array([tag, 1])
        line_edges.append(mesh.lines[name])
        line_tags.append(np.full(mesh.lines[name].shape[0], tag))
    tri_tags = np.array([region_tag[n] for n in mesh.cell_region])
    line_tag_arr = np.concatenate(line_tags)
    out = meshio.Mesh(
        np.ascontiguousarray(np.column_stack([mesh.points, np.zeros(mesh.points.shape[0])])),
        [("triangle", np.ascontiguousarray(mesh.triangles)),
         ("line", np.ascontiguousarray(np.vstack(line_edges)))],
        cell_data={"gmsh:physical": [tri_tags, line_tag_arr],
                   "gmsh:geometrical": [tri_tags, line_tag_arr]},
        field_data=field_data,
    )
    with atomic_target(path) as tmp:
        meshio.write(tmp, out, file_format="gmsh22", binary=False)
    return path
