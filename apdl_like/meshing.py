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
from apdl_like.model import Line
from twin.signal_guard import signals_kept

if TYPE_CHECKING:
    from apdl_like.state import SessionState

MAX_NEW_ELEMENTS = 200_000
MAX_MODEL_ELEMENTS = 500_000
"""Elements a model may hold in all: AMESH in a *DO loop adds up, each call under the
per-call cap `MAX_NEW_ELEMENTS`."""


def check_new_elements(s: SessionState, count: float, size: float) -> None:
    """ApdlError before meshing if `count` new elements break either cap."""
    if count > MAX_NEW_ELEMENTS:
        raise ApdlError(f"ESIZE {size:g} would make more than {MAX_NEW_ELEMENTS} elements")
    s.db.elements.flush()
    if len(s.db.elements.ids) + count > MAX_MODEL_ELEMENTS:
        raise ApdlError(f"the model would hold more than {MAX_MODEL_ELEMENTS} elements")


ARC_OUTLINE_POINTS = 64  # points of an arc side in the outline that sorts elements to areas


def line_points(line: Line, p1: np.ndarray, p2: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Points at fractions f of a line from p1 to p2: along the chord, or along the arc
    about its centre (angle proportional to f) for an arc."""
    if not line.arc:
        return p1 + f[:, None] * (p2 - p1)
    centre = np.asarray(line.centre, float)
    d1, d2 = p1 - centre, p2 - centre
    r = float(np.hypot(*d1))
    t1, t2 = np.arctan2(d1[1], d1[0]), np.arctan2(d2[1], d2[0])
    if t2 - t1 > np.pi:  # the shorter way round, as MAPDL draws it
        t2 -= 2 * np.pi
    elif t1 - t2 > np.pi:
        t2 += 2 * np.pi
    t = t1 + f * (t2 - t1)
    return centre + np.column_stack([r * np.cos(t), r * np.sin(t)])


def _arc_between(s: SessionState, a: int, b: int) -> Line | None:
    """The arc line joining keypoints a and b, if there is one."""
    for line in s.db.lines.values():
        if line.arc and {line.k1, line.k2} == {a, b}:
            return line
    return None


def area_outline(s: SessionState, area: int) -> np.ndarray:
    """The area's boundary as a polygon: its keypoints, with arc sides sampled densely."""
    db = s.db
    kps = db.areas[area]
    out = []
    for a, b in zip(kps, [*kps[1:], kps[0]], strict=True):
        p1, p2 = np.array(db.keypoints[a], float), np.array(db.keypoints[b], float)
        arc = _arc_between(s, a, b)
        if arc is None:
            out.append(p1[None, :])
        else:
            f = np.linspace(0.0, 1.0, ARC_OUTLINE_POINTS, endpoint=False)
            out.append(line_points(arc, p1, p2, f))
    return np.vstack(out)


def _triangulate(boundaries: list[tuple[np.ndarray, np.ndarray]],
                 size: float) -> tuple[np.ndarray, np.ndarray]:
    """Triangles of the areas whose boundaries are given as closed point lists (n, 2) with
    their keypoint flags (n,): every boundary point becomes a node and no boundary segment
    is divided further (the lines' divisions, as MAPDL's free mesher keeps them, so a
    neighbouring area's line mesh matches node for node); inside, the size grows from the
    boundary spacing up to `size`.  Keypoints come first in the node order (MAPDL numbers
    an area's keypoint nodes before its line and interior nodes)."""
    import gmsh

    owner = not gmsh.isInitialized()
    # gmsh changes signal handlers process-wide: restored after finalize (twin.signal_guard)
    with signals_kept():
        if owner:
            gmsh.initialize(readConfigFiles=False, interruptible=False)
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.model.add("amesh")
            occ = gmsh.model.occ
            surfaces = []
            tags = [np.zeros(len(poly), int) for poly, _ in boundaries]
            for first in (True, False):
                for (poly, corner), tag in zip(boundaries, tags, strict=True):
                    seg = np.hypot(*(np.roll(poly, -1, axis=0) - poly).T)
                    local = 0.5 * (seg + np.roll(seg, 1))  # a point's size: its two segments
                    for i in np.nonzero(corner == first)[0]:
                        tag[i] = occ.addPoint(poly[i, 0], poly[i, 1], 0.0, float(local[i]))
            for tag in tags:
                lines = [occ.addLine(int(tag[i]), int(tag[(i + 1) % tag.size]))
                         for i in range(tag.size)]
                surfaces.append((2, occ.addPlaneSurface([occ.addCurveLoop(lines)])))
            if len(surfaces) > 1:
                occ.fragment(surfaces[:1], surfaces[1:])
            occ.synchronize()
            for _, curve in gmsh.model.getEntities(1):
                gmsh.model.mesh.setTransfiniteCurve(curve, 2)  # a boundary segment stays whole
            gmsh.option.setNumber("Mesh.MeshSizeMax", size)
            gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
            gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 1)
            gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 1)
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
    outlines = [area_outline(s, a) for a in area_numbers]
    allpts = np.vstack(polygons)
    extent = float(np.ptp(allpts, axis=0).max())
    if not extent > 0.0:
        raise ApdlError("the areas have no extent")
    size = db.esize if db.esize is not None else extent / 10.0
    total = 0.0
    for poly in outlines:
        x, y = poly[:, 0], poly[:, 1]
        total += 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    if total <= 0.0:
        raise ApdlError("an area has zero size (check the keypoint order)")
    check_new_elements(s, 2.5 * total / size**2, size)
    boundaries = [_divided_boundary(s, a, size) for a in area_numbers]
    longest = max(float(np.hypot(*(np.roll(b, -1, axis=0) - b).T).max()) for b, _ in boundaries)
    xy, tri = _triangulate(boundaries, max(size, longest))
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
    db.nodes.flush()
    before = len(db.nodes.ids)
    numbers = place_nodes(s, all_xy, extent)
    fresh = len(db.nodes.ids) - before
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
    centroids = xy_used[tri].mean(axis=1)
    for num, poly in zip(area_numbers, outlines, strict=True):
        inside = _inside(poly, centroids)
        db.area_elements[num] = first + np.nonzero(inside)[0]
    s.say(f"AMESH: {len(tri)} elements, {fresh} new nodes (size {size:g})")


def _divided_boundary(s: SessionState, area: int, size: float) -> tuple[np.ndarray, np.ndarray]:
    """The area's boundary as the nodes its lines get, and which of them are keypoints: per
    side its divisions (LESIZE, L, ESIZE's NDIV, else the element size), spaced by its
    ratio, on its arc when it is one.  Lines without divisions of their own keep the ones
    they are meshed with."""
    db = s.db
    kps = db.areas[area]
    out = []
    for a, b in zip(kps, [*kps[1:], kps[0]], strict=True):
        n, hard = _side_divisions(s, a, b, size)
        line = _line_of(s, a, b)
        if line is not None and not hard:
            line.ndiv = n  # meshed now: an area meshed later must match it
        p1, p2 = np.array(db.keypoints[a], float), np.array(db.keypoints[b], float)
        out.append(line_points(_arc_between(s, a, b) or Line(a, b), p1, p2,
                               _side(s, a, b, n))[:-1])
    corner = np.concatenate([np.arange(len(side)) == 0 for side in out])
    return np.vstack(out), corner


def _inside(polygon: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Which points lie inside the polygon (even-odd rule on a ray along +x)."""
    x, y = points[:, 0:1], points[:, 1:2]
    x0, y0 = polygon[:, 0], polygon[:, 1]
    x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
    spans = (y0 > y) != (y1 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    return (spans & (x < cross)).sum(axis=1) % 2 == 1


def side_fractions(n: int, space: float) -> np.ndarray:
    """0 = f_0 < ... < f_n = 1 for n divisions whose last/first length ratio is `space`."""
    lengths = np.ones(n) if n == 1 or space == 1.0 else space ** (np.arange(n) / (n - 1))
    return np.concatenate([[0.0], np.cumsum(lengths) / lengths.sum()])


def _line_of(s: SessionState, a: int, b: int) -> Line | None:
    """The line joining keypoints a and b, if there is one."""
    for line in s.db.lines.values():
        if {line.k1, line.k2} == {a, b}:
            return line
    return None


def _side_divisions(s: SessionState, a: int, b: int, size: float) -> tuple[int, bool]:
    """(divisions, hard?) of the area side a -> b: a line's own NDIV (LESIZE, L) is hard,
    ESIZE's or the element size's is soft (the mapped mesher may change it)."""
    db = s.db
    line = _line_of(s, a, b)
    if line is not None and line.ndiv:
        return line.ndiv, True
    length = float(np.hypot(*np.subtract(db.keypoints[b], db.keypoints[a])))
    return db.esize_divisions or _divisions(length, size), False


def _side(s: SessionState, a: int, b: int, n: int) -> np.ndarray:
    """Fractions along the area side from keypoint a to b for n divisions, spaced by its
    line's LESIZE ratio (given in the line's own direction)."""
    line = _line_of(s, a, b)
    f = side_fractions(n, line.space if line is not None else 1.0)
    return f if line is None or line.k1 == a else 1.0 - f[::-1]


def _matched(s: SessionState, one: tuple[int, int], other: tuple[int, int],
             size: float) -> tuple[int, Line | None] | None:
    """Divisions of two opposite sides for a mapped mesh (None if they cannot match) and
    the line whose soft divisions change to match: as in MAPDL, a side with soft divisions
    takes the hard divisions of the opposite side."""
    (n1, hard1), (n2, hard2) = _side_divisions(s, *one, size), _side_divisions(s, *other, size)
    if n1 == n2:
        return n1, None
    if hard1 == hard2:
        return None
    return (n1 if hard1 else n2), _line_of(s, *(other if hard1 else one))


def _divisions(length: float, size: float) -> int:
    n = length / size
    if not n <= MAX_NEW_ELEMENTS:  # before allocating a side of n divisions
        raise ApdlError(f"ESIZE {size:g} would make more than {MAX_NEW_ELEMENTS} elements")
    return max(1, int(np.ceil(n - 1e-9)))


def mapped_grid(s: SessionState, area: int, size: float) -> np.ndarray | None:
    """Node coordinates (nv+1, nu+1, 2) of a mapped mesh of a 4-sided area whose opposite
    sides have as many divisions, by transfinite interpolation; None if it cannot map."""
    db = s.db
    kps = db.areas[area]
    if len(kps) != 4:
        return None
    k0, k1, k2, k3 = kps
    along = _matched(s, (k0, k1), (k3, k2), size)
    across = _matched(s, (k0, k3), (k1, k2), size)
    if along is None or across is None:
        return None
    for n, soft in (along, across):
        if soft is not None:
            soft.ndiv = n  # the line keeps them: an area meshed later matches this one
    bottom, top = _side(s, k0, k1, along[0]), _side(s, k3, k2, along[0])
    left, right = _side(s, k0, k3, across[0]), _side(s, k1, k2, across[0])
    check_new_elements(s, (bottom.size - 1) * (left.size - 1), size)
    p0, p1, p2, p3 = (np.array(db.keypoints[k], float) for k in kps)
    u = 0.5 * (bottom + top)[None, :, None]
    v = 0.5 * (left + right)[:, None, None]

    def side(a: int, b: int, pa: np.ndarray, pb: np.ndarray, f: np.ndarray) -> np.ndarray:
        """Points of the side a -> b at fractions f: on its arc when it is one (a Coons
        patch then keeps the mesh on the curved boundary)."""
        return line_points(_arc_between(s, a, b) or Line(a, b), pa, pb, f)

    b = side(k0, k1, p0, p1, bottom)[None, :, :]
    t = side(k3, k2, p3, p2, top)[None, :, :]
    lft = side(k0, k3, p0, p3, left)[:, None, :]
    rgt = side(k1, k2, p1, p2, right)[:, None, :]
    corner = (1 - u) * (1 - v) * p0 + u * (1 - v) * p1 + u * v * p2 + (1 - u) * v * p3
    return (1 - v) * b + v * t + (1 - u) * lft + u * rgt - corner


def place_nodes(s: SessionState, xy: np.ndarray, extent: float) -> np.ndarray:
    """Node numbers for points (n, 2): an existing coincident node, else a new number."""
    nodes = s.db.nodes
    nodes.flush()
    numbers = np.zeros(xy.shape[0], np.int64)
    fresh = np.ones(xy.shape[0], bool)
    if len(nodes.ids):
        dist, near = cKDTree(nodes.xy).query(xy)
        hit = dist <= 1e-9 * max(extent, 1e-300)
        numbers[hit] = nodes.ids[near[hit]]
        fresh = ~hit
    start = int(nodes.ids.max()) + 1 if len(nodes.ids) else 1
    numbers[fresh] = np.arange(start, start + int(fresh.sum()))
    for num, (x, y) in zip(numbers[fresh], xy[fresh], strict=True):
        nodes.add(int(num), float(x), float(y))
    nodes.flush()
    return numbers


def mesh_mapped(s: SessionState, area: int, grid: np.ndarray) -> int:
    """Quads (or 8-node quads with mid-side nodes) on a mapped grid; returns the count."""
    db = s.db
    et = db.element_types[db.active_type]
    nv, nu = grid.shape[0] - 1, grid.shape[1] - 1
    extent = float(np.ptp(grid.reshape(-1, 2), axis=0).max())
    # MAPDL's order: side by side around the area from its first keypoint, each side's
    # end keypoints (when still unnumbered) before its interior nodes; then the interior
    sides = [[(0, i) for i in range(nu + 1)], [(j, nu) for j in range(nv + 1)],
             [(nv, i) for i in range(nu, -1, -1)], [(j, 0) for j in range(nv, -1, -1)]]
    order: list[tuple[int, int]] = []
    for side in sides:
        order += [p for p in (side[0], side[-1]) if p not in order]
        order += side[1:-1]
    order += [(j, i) for j in range(1, nv) for i in range(1, nu)]
    pts = np.array([grid[j, i] for j, i in order])
    numbers = place_nodes(s, pts, extent)
    number_at = {ji: int(n) for ji, n in zip(order, numbers, strict=True)}
    mids: dict[tuple, int] = {}
    el = db.elements
    el.flush()
    first = int(el.ids.max()) + 1 if len(el.ids) else 1
    count = 0
    for j in range(nv):
        for i in range(nu):
            corners = [number_at[(j, i)], number_at[(j, i + 1)], number_at[(j + 1, i + 1)],
                       number_at[(j + 1, i)]]
            conn: tuple[int, ...] = tuple(corners)
            if et.quadratic:
                cells = [((j, i), (j, i + 1)), ((j, i + 1), (j + 1, i + 1)),
                         ((j + 1, i + 1), (j + 1, i)), ((j + 1, i), (j, i))]
                side = []
                for a, b in cells:
                    key = (min(a, b), max(a, b))
                    if key not in mids:
                        mid = 0.5 * (grid[a] + grid[b])
                        mids[key] = int(place_nodes(s, mid[None, :], extent)[0])
                    side.append(mids[key])
                conn = (*corners, *side)
            el.add(first + count, db.active_type, db.active_mat, db.active_real, conn)
            count += 1
    el.flush()
    db.area_elements[area] = np.arange(first, first + count)
    return count
