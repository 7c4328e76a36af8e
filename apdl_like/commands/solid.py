"""/PREP7 solid model and meshing: K, KGEN, L, LESIZE, A, AL, RECTNG, ESIZE, MSHAPE, MSHKEY,
AMESH, LMESH.

A 4-sided area whose opposite sides have as many divisions (LESIZE, or ESIZE) is meshed
mapped, with quads (8-node ones for a quadratic element type); any other area, or MSHAPE,1
(triangles), is meshed free by gmsh.  Keypoint coordinates follow the active CSYS.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import PREP7, Call, CommandSpec, command, existing, ignored, specs_of
from apdl_like.errors import ApdlError
from apdl_like.model import Line

if TYPE_CHECKING:
    from apdl_like.state import SessionState

MAX_DIVISIONS = 10_000


@command("K", PREP7, 4)
def k(s: SessionState, c: Call) -> None:
    """K,NPT,X,Y: a keypoint (number 0 or blank: the next free one)."""
    kps = s.db.keypoints
    num = c.int(1, 0, what="NPT")
    if num == 0:
        num = max(kps, default=0) + 1
    if c.given(4) and c.num(4) != 0.0:
        raise ApdlError("field 4 (Z) must be 0 in a 2-D model")
    kps[num] = s.db.active_system.to_global(c.num(2, 0.0, what="X"), c.num(3, 0.0, what="Y"))


@command("KGEN", PREP7, 8)
def kgen(s: SessionState, c: Call) -> None:
    """KGEN,ITIME,NP1,NP2,NINC,DX,DY,DZ,KINC: copies of keypoints, offset."""
    itime = c.int(1, what="ITIME")
    kps = s.db.keypoints
    if c.label(2) == "ALL":
        pattern = sorted(kps)
    else:
        first = c.entity(2, "NP1")
        last = c.int(3, first, what="NP2")
        pattern = [n for n in range(first, last + 1, max(c.int(4, 1, what="NINC"), 1))
                   if n in kps]
    dx, dy = c.num(5, 0.0, what="DX"), c.num(6, 0.0, what="DY")
    kinc = c.int(8, 0, what="KINC")
    top = max(kps, default=0)
    system = s.db.active_system
    for j in range(1, itime):
        for idx, n in enumerate(pattern):
            a, b = system.from_global(np.array([kps[n]]))[0]
            new = n + j * kinc if kinc else top + (j - 1) * len(pattern) + idx + 1
            kps[new] = system.to_global(a + j * dx, b + j * dy)


@command("L", PREP7, 4)
def line(s: SessionState, c: Call) -> None:
    """L,P1,P2[,NDIV,SPACE]: a straight line between two keypoints."""
    p1, p2 = c.entity(1, "P1"), c.entity(2, "P2")
    for p in (p1, p2):
        if p not in s.db.keypoints:
            raise ApdlError(f"keypoint {p} does not exist")
    if p1 == p2:
        raise ApdlError("a line needs two different keypoints")
    ndiv = c.int(3, 0, what="NDIV") or None
    arc = False
    system = s.db.active_system
    if system.cylindrical:
        (r1, t1), (r2, t2) = system.from_global(np.array([s.db.keypoints[p1],
                                                          s.db.keypoints[p2]], float))
        tol = 1e-9 * max(r1, r2, 1e-300)
        arc = abs(r1 - r2) <= tol and abs(t1 - t2) > 1e-9 and r1 > tol
        if not arc and abs(t1 - t2) > 1e-9 and min(r1, r2) > tol:
            raise ApdlError("a line in a cylindrical CSYS between different radii and angles "
                            "is a spiral, which is not supported")
    s.db.lines[max(s.db.lines, default=0) + 1] = Line(p1, p2, ndiv, c.num(4, 1.0, what="SPACE"),
                                                      arc, system.origin)


@command("LESIZE", PREP7, 9)
def lesize(s: SessionState, c: Call) -> None:
    """LESIZE,NL1,SIZE,ANGSIZ,NDIV,SPACE: divisions (or size) and spacing ratio of lines."""
    lines = s.db.lines
    chosen = sorted(lines) if c.label(1) == "ALL" else [c.entity(1, "NL1")]
    for n in chosen:
        if n not in lines:
            raise ApdlError(f"line {n} does not exist")
    space = c.num(5, 1.0, what="SPACE")
    if not space > 0.0:
        raise ApdlError(f"field 5 (SPACE) must be a positive ratio, got {space!r}")
    for n in chosen:
        ln = lines[n]
        if c.given(4):
            ndiv = c.int(4, what="NDIV")
        elif c.given(2):
            size = c.num(2, what="SIZE")
            if not size > 0.0:
                raise ApdlError(f"field 2 (SIZE) must be positive, got {size!r}")
            length = float(np.hypot(*np.subtract(s.db.keypoints[ln.k2], s.db.keypoints[ln.k1])))
            ndiv = max(1, int(np.ceil(length / size - 1e-9)))
        else:
            ndiv = ln.ndiv or 1
        if not 1 <= ndiv <= MAX_DIVISIONS:
            raise ApdlError(f"NDIV must lie in 1..{MAX_DIVISIONS}, got {ndiv}")
        ln.ndiv, ln.space = ndiv, space


@command("A", PREP7, 18)
def area(s: SessionState, c: Call) -> None:
    """A,P1,P2,...: an area through keypoints (in order around it)."""
    pts = [c.entity(i, "keypoint") for i in range(1, c.count() + 1) if c.given(i)]
    if len(pts) < 3:
        raise ApdlError("an area needs at least 3 keypoints")
    for p in pts:
        if p not in s.db.keypoints:
            raise ApdlError(f"keypoint {p} does not exist")
    add_area(s, pts)


def add_area(s: SessionState, pts: list[int]) -> None:
    """A new area through keypoints; like MAPDL, the lines between consecutive keypoints
    that do not exist yet are created first, numbered in order around the area (SFL, LESIZE
    and LSEL then find them by number)."""
    lines = s.db.lines
    for p1, p2 in zip(pts, pts[1:] + pts[:1], strict=True):
        if not any({ln.k1, ln.k2} == {p1, p2} for ln in lines.values()):
            lines[max(lines, default=0) + 1] = Line(p1, p2)
    s.db.areas[max(s.db.areas, default=0) + 1] = pts


@command("AL", PREP7, 10)
def area_lines(s: SessionState, c: Call) -> None:
    """AL,L1,L2,...: an area bounded by lines (in order around it)."""
    nums = [c.entity(i, "line") for i in range(1, c.count() + 1) if c.given(i)]
    if len(nums) < 3:
        raise ApdlError("an area needs at least 3 lines")
    lines = s.db.lines
    for n in nums:
        if n not in lines:
            raise ApdlError(f"line {n} does not exist")
    first, second = lines[nums[0]], lines[nums[1]]
    start = first.k1 if first.k1 not in (second.k1, second.k2) else first.k2
    pts, at = [], start
    for n in nums:
        ln = lines[n]
        if at not in (ln.k1, ln.k2):
            raise ApdlError(f"line {n} does not continue the loop of the lines before it")
        pts.append(at)
        at = ln.k2 if at == ln.k1 else ln.k1
    if at != start:
        raise ApdlError("the lines do not close a loop")
    s.db.areas[max(s.db.areas, default=0) + 1] = pts


@command("RECTNG", PREP7, 4)
def rectng(s: SessionState, c: Call) -> None:
    """RECTNG,X1,X2,Y1,Y2: a rectangular area (4 keypoints, 4 lines, 1 area)."""
    _rectangle(s, c.num(1, what="X1"), c.num(2, what="X2"), c.num(3, what="Y1"),
               c.num(4, what="Y2"))


@command("BLC4", PREP7, 5)
def blc4(s: SessionState, c: Call) -> None:
    """BLC4,XCORNER,YCORNER,WIDTH,HEIGHT: a rectangle by a corner and its sides (a 2-D
    model: DEPTH must be blank or 0)."""
    if c.given(5) and c.num(5) != 0.0:
        raise ApdlError("field 5 (DEPTH) makes a block volume: only 2-D areas are supported")
    x, y = c.num(1, 0.0, what="XCORNER"), c.num(2, 0.0, what="YCORNER")
    _rectangle(s, x, x + c.num(3, what="WIDTH"), y, y + c.num(4, what="HEIGHT"))


def _rectangle(s: SessionState, x1: float, x2: float, y1: float, y2: float) -> None:
    if x1 == x2 or y1 == y2:
        raise ApdlError("the rectangle has zero width or height")
    kps = s.db.keypoints
    first = max(kps, default=0) + 1
    corners = [(x1, y1), (x2, y1), (x2, y2), (x1, y2)]
    for i, xy in enumerate(corners):
        kps[first + i] = xy
    add_area(s, list(range(first, first + 4)))


@command("ESIZE", PREP7, 2)
def esize(s: SessionState, c: Call) -> None:
    """ESIZE,SIZE,NDIV: element edge length, or divisions per line when SIZE is blank."""
    if c.given(1):
        size = c.num(1, what="SIZE")
        if not size > 0.0:
            raise ApdlError(f"field 1 (SIZE) must be positive, got {size!r}")
        s.db.esize, s.db.esize_divisions = size, None
    elif c.given(2):
        ndiv = c.int_in(2, 1, MAX_DIVISIONS, what="NDIV")
        s.db.esize_divisions = ndiv
    else:
        raise ApdlError("ESIZE needs SIZE (field 1) or NDIV (field 2)")


@command("MSHAPE", PREP7, 2)
def mshape(s: SessionState, c: Call) -> None:
    """MSHAPE,KEY: 0 quads (mapped where the area allows), 1 triangles."""
    key = c.int(1, 0, what="KEY")
    if key not in (0, 1):
        raise ApdlError(f"field 1 must be 0 (quads) or 1 (triangles), got {key}")
    s.db.mesh_triangles = key == 1


def _range_of(c: Call, table: dict, what: str, field: str) -> list[int]:
    """Fields 1..3 of AMESH/LMESH: ALL (or blank), or N1, N2, NINC (each must exist)."""
    if c.label(1, "ALL") == "ALL":
        return sorted(table)
    first = c.entity(1, f"{field}1")
    last = c.entity(2, f"{field}2") if c.given(2) else first
    step = c.int(3, 1, what="NINC")
    if step < 1:
        raise ApdlError("field 3 (NINC) must be ≥ 1")
    return existing(list(range(first, last + 1, step)), table, what)


@command("AATT", PREP7, 5)
def aatt(s: SessionState, c: Call) -> None:
    """AATT,MAT,REAL,TYPE: the attributes AMESH gives the elements of the selected areas
    (blank fields: 1, as MAPDL's defaults); ESYS and SECN (fields 4, 5) other than 0 are
    not supported."""
    if c.num(4, 0.0, what="ESYS") != 0.0 or c.num(5, 0.0, what="SECN") != 0.0:
        raise ApdlError("fields 4-5 (ESYS, SECN) other than 0 are not supported")
    db = s.db
    chosen = [num for num in sorted(db.areas) if num not in db.unselected_areas]
    if not chosen:
        raise ApdlError("no area is selected")
    attrs = (c.int(1, 1, what="MAT"), c.int(2, 1, what="REAL"), c.int(3, 1, what="TYPE"))
    for num in chosen:
        db.area_attributes[num] = attrs


@command("AMESH", PREP7, 3)
def amesh(s: SessionState, c: Call) -> None:
    """AMESH,NA1,NA2,NINC or AMESH,ALL (the selected areas, as MAPDL); each area's elements
    take its AATT attributes, else the active TYPE, MAT and REAL."""
    from apdl_like.meshing import mapped_grid, mesh_areas, mesh_mapped  # loaded when used

    db = s.db
    areas = db.areas
    chosen = _range_of(c, areas, "area", "NA")
    if c.label(1, "ALL") == "ALL":
        chosen = [num for num in chosen if num not in db.unselected_areas]
    chosen = [num for num in chosen if num not in db.meshed_areas]
    if not chosen:
        raise ApdlError("no unmeshed areas to mesh")
    active = (db.active_mat, db.active_real, db.active_type)
    try:
        free: dict[tuple[int, int, int], list[int]] = {}
        for num in chosen:
            attrs = db.area_attributes.get(num, active)
            db.active_mat, db.active_real, db.active_type = attrs
            et = db.element_types.get(db.active_type)
            if et is None:
                raise ApdlError(f"element type {db.active_type} is not defined (ET, then TYPE"
                                f"{' or AATT' if num in db.area_attributes else ''})")
            pts = np.array([db.keypoints[p] for p in areas[num]], float)
            extent = float(np.ptp(pts, axis=0).max())
            size = db.esize if db.esize is not None else extent / 10.0
            grid = None if db.mesh_triangles or et.triangle6 else mapped_grid(s, num, size)
            if grid is None:
                free.setdefault(attrs, []).append(num)
            else:
                s.say(f"AMESH: area {num} mapped, {mesh_mapped(s, num, grid)} elements")
        for attrs, nums in free.items():
            db.active_mat, db.active_real, db.active_type = attrs
            mesh_areas(s, nums)
    finally:
        db.active_mat, db.active_real, db.active_type = active
    db.meshed_areas.update(chosen)


@command("LMESH", PREP7, 3)
def lmesh(s: SessionState, c: Call) -> None:
    """LMESH,NL1,NL2,NINC: line elements (LINK33, LINK34 ...) along lines, NDIV from LESIZE
    (with its spacing ratio) or ESIZE.  Node numbering as MAPDL's: a line's end keypoints
    first (when they have no node yet), then its interior nodes from k1 to k2."""
    from apdl_like.meshing import line_points, place_nodes, side_fractions

    db = s.db
    lines = db.lines
    chosen = _range_of(c, lines, "line", "NL")
    et = db.element_types.get(db.active_type)
    if et is None:
        raise ApdlError(f"element type {db.active_type} is not defined (ET, then TYPE)")
    if et.physics != "line":
        raise ApdlError(f"LMESH meshes line elements; type {db.active_type} is {et.name}")
    for num in chosen:
        if num in db.line_elements:
            continue
        ln = lines[num]
        p1, p2 = (np.array(db.keypoints[k], float) for k in (ln.k1, ln.k2))
        length = float(np.hypot(*(p2 - p1)))
        if ln.ndiv:
            n = ln.ndiv
        elif db.esize_divisions:
            n = db.esize_divisions
        elif db.esize is not None:
            n = max(1, int(np.ceil(length / db.esize - 1e-9)))
        else:
            raise ApdlError(f"line {num} has no element size: give LESIZE or ESIZE first")
        if n > MAX_DIVISIONS:
            raise ApdlError(f"line {num}: {n} divisions exceed {MAX_DIVISIONS}")
        f = side_fractions(n, ln.space)
        points = line_points(ln, p1, p2, f)
        order = [0, n, *range(1, n)]
        numbers = np.empty(n + 1, np.int64)
        numbers[order] = place_nodes(s, points[order], max(length, 1e-300))
        el = db.elements
        el.flush()
        start = int(el.ids.max()) + 1 if len(el.ids) else 1
        for e in range(n):
            el.add(start + e, db.active_type, db.active_mat, db.active_real,
                   (int(numbers[e]), int(numbers[e + 1])))
        el.flush()
        db.line_elements[num] = np.arange(start, start + n)
    s.say(f"LMESH: {len(chosen)} line(s) meshed")


COMMANDS = (
    *specs_of(aatt, k, kgen, line, lesize, area, area_lines, rectng, blc4, esize, mshape, amesh,
              lmesh),
    CommandSpec("MSHKEY", PREP7, 1, ignored),  # mapped wherever the area allows
)
