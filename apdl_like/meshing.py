"""AMESH: free triangle meshing of keypoint polygons (A, RECTNG) with gmsh.

All requested areas go into one OpenCASCADE model and are fragmented, so areas that touch
share their edge nodes (APDL would need AGLUE/NUMMRG for that).  New nodes that coincide
with nodes already in the database are merged into them, which keeps separate AMESH calls
conforming too.  Quadratic element types get mid-side nodes on the edge midpoints.  The
mesh size is ESIZE, or a tenth of the largest area extent when ESIZE is not set.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from apdl_like.errors import ApdlError

if TYPE_CHECKING:
    from apdl_like.state import SessionState

MAX_NEW_ELEMENTS = 200_000


def _triangulate(polygons: list[np.ndarray], size: float) -> tuple[np.ndarray, np.ndarray]:
    import gmsh

    owner = not gmsh.isInitialized()
    if owner:
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("amesh")
        occ = gmsh.model.occ
        surfaces = []
        for poly in polygons:
            pts = [occ.addPoint(x, y, 0.0) for x, y in poly]
            lines = [occ.addLine(pts[i], pts[(i + 1) % len(pts)]) for i in range(len(pts))]
            surfaces.append((2, occ.addPlaneSurface([occ.addCurveLoop(lines)])))
        if len(surfaces) > 1:
            occ.fragment(surfaces[:1], surfaces[1:])
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", size / 4.0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.Algorithm", 6)  # Frontal-Delaunay: regular triangles
        gmsh.model.mesh.generate(2)
        tags, coords, _ = gmsh.model.mesh.getNodes()
        _, elem_nodes = gmsh.model.mesh.getElementsByType(2)
    except Exception as exc:  # noqa: BLE001 - gmsh raises plain Exception
        raise ApdlError(f"gmsh could not mesh the areas: {exc}") from None
    finally:
        if owner:
            gmsh.finalize()
        elif gmsh.isInitialized():
            gmsh.model.remove()
    xy = np.asarray(coords).reshape(-1, 3)[:, :2]
    tags = np.asarray(tags, np.int64)
    lookup = np.full(tags.max() + 1 if tags.size else 1, -1, np.int64)
    lookup[tags] = np.arange(tags.size)
    tri = lookup[np.asarray(elem_nodes, np.int64)].reshape(-1, 3)
    return xy, tri


def mesh_areas(s: SessionState, area_numbers: list[int]) -> None:
    db = s.db
    et = db.element_types.get(db.active_type)
    if et is None:
        raise ApdlError(f"element type {db.active_type} is not defined (ET, then TYPE)")
    polygons = [np.array([db.keypoints[k] for k in db.areas[a]], float) for a in area_numbers]
    allpts = np.vstack(polygons)
    extent = float(np.ptp(allpts, axis=0).max())
    if not extent > 0.0:
        raise ApdlError("the areas have no extent")
    size = db.esize if db.esize is not None else extent / 10.0
    total = 0.0
    for poly in polygons:
        x, y = poly[:, 0], poly[:, 1]
        total += 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    if total <= 0.0:
        raise ApdlError("an area has zero size (check the keypoint order)")
    if 2.5 * total / size**2 > MAX_NEW_ELEMENTS:
        raise ApdlError(f"ESIZE {size:g} would make more than {MAX_NEW_ELEMENTS} elements")
    xy, tri = _triangulate(polygons, size)
    if tri.size == 0:
        raise ApdlError("gmsh produced no triangles")
    used = np.unique(tri)
    xy_used = xy[used]
    remap = np.full(xy.shape[0], -1, np.int64)
    remap[used] = np.arange(used.size)
    tri = remap[tri]
    if et.quadratic:
        edges = np.sort(np.vstack([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
        uniq, inverse = np.unique(edges, axis=0, return_inverse=True)
        mids = 0.5 * (xy_used[uniq[:, 0]] + xy_used[uniq[:, 1]])
        mid_of = (inverse.ravel() + used.size).reshape(3, -1).T  # per triangle: IJ, JK, KI
        all_xy = np.vstack([xy_used, mids])
    else:
        mid_of = None
        all_xy = xy_used
    # node numbers: merge with coincident existing nodes, number the rest after the maximum
    nodes = db.nodes
    nodes.flush()
    numbers = np.zeros(all_xy.shape[0], np.int64)
    fresh = np.ones(all_xy.shape[0], bool)
    if len(nodes.ids):
        dist, near = cKDTree(nodes.xy).query(all_xy)
        hit = dist <= 1e-9 * max(extent, 1e-300)
        numbers[hit] = nodes.ids[near[hit]]
        fresh = ~hit
    start = int(nodes.ids.max()) + 1 if len(nodes.ids) else 1
    numbers[fresh] = np.arange(start, start + int(fresh.sum()))
    for num, (x, y) in zip(numbers[fresh], all_xy[fresh], strict=True):
        nodes.add(int(num), float(x), float(y))
    nodes.flush()
    el = db.elements
    el.flush()
    first = int(el.ids.max()) + 1 if len(el.ids) else 1
    for k, t in enumerate(tri):
        i, j, kk = (int(numbers[v]) for v in t)
        if mid_of is None:
            conn: tuple[int, ...] = (i, j, kk, kk)
        else:
            m_ij, m_jk, m_ki = (int(numbers[v]) for v in mid_of[k])
            conn = (i, j, kk, m_ij, m_jk, m_ki) if et.triangle6 else \
                (i, j, kk, kk, m_ij, m_jk, kk, m_ki)
        el.add(first + k, db.active_type, db.active_mat, db.active_real, conn)
    el.flush()
    s.say(f"AMESH: {len(tri)} elements, {int(fresh.sum())} new nodes (size {size:g})")
