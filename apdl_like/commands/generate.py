"""/PREP7 generation: CSYS, LOCAL, FILL, NGEN, EGEN, EMID, NUMMRG and coupled sets (CP,
CPNGEN, CPINTF, CPSGEN).

Coordinates are stored global Cartesian (x = r, y = z for an axisymmetric model).  The
fields of N, FILL and NGEN are in the active system (`apdl_like.coordinates`): in CSYS,1 or
a cylindrical LOCAL X is the radius and Y the angle θ in degrees, and FILL interpolates in
(r, θ), as MAPDL does.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import ANY, PREP7, Call, command, specs_of
from apdl_like.coordinates import FIRST_LOCAL, CoordinateSystem
from apdl_like.errors import ApdlError

if TYPE_CHECKING:
    from apdl_like.state import SessionState

MAX_GENERATED = 1_000_000
COUPLING_LABELS = ("TEMP", "UX", "UY", "ALL")


@command("CSYS", ANY, 1)
def csys(s: SessionState, c: Call) -> None:
    """CSYS,KCN: the active coordinate system (0 Cartesian, 1 cylindrical, ≥ 11 LOCAL)."""
    kcn = c.int(1, 0, what="KCN")
    if kcn in (2, 3, 4, 5, 6) or 7 <= kcn < FIRST_LOCAL:
        raise ApdlError(f"field 1 (KCN): coordinate system {kcn} is not supported in a 2-D "
                        "model (use 0, 1 or a LOCAL system)")
    s.db.coordinate_system(kcn)  # an undefined local system is an error
    s.db.csys = kcn


def _define_system(s: SessionState, c: Call, relative: bool) -> None:
    """LOCAL/CLOCAL,KCN,KCS,XC,YC,ZC,THXY,THYZ,THZX,PAR1: a local system, made active."""
    kcn = c.int(1, what="KCN")
    if kcn < FIRST_LOCAL:
        raise ApdlError(f"field 1 (KCN): a local system's number must be ≥ {FIRST_LOCAL}, "
                        f"got {kcn}")
    kind = c.label(2, "0")
    cylindrical = {"0": False, "CART": False, "1": True, "CYLIN": True}.get(kind)
    if cylindrical is None:
        raise ApdlError(f"field 2 (KCS): only 0 (Cartesian) and 1 (cylindrical) exist in a "
                        f"2-D model, got {kind!r}")
    for i, what in ((5, "ZC"), (7, "THYZ"), (8, "THZX")):
        if c.num(i, 0.0, what=what) != 0.0:
            raise ApdlError(f"field {i} ({what}) must be 0: the system would leave the XY "
                            "plane of a 2-D model")
    if c.num(9, 1.0, what="PAR1") != 1.0:
        raise ApdlError("field 9 (PAR1): elliptical systems are not supported")
    a, b, theta = c.num(3, 0.0, what="XC"), c.num(4, 0.0, what="YC"), c.num(6, 0.0, what="THXY")
    if relative:  # CLOCAL: origin and rotation given in the active system
        active = s.db.active_system
        a, b = active.to_global(a, b)
        theta += active.theta_xy_deg
        if active.cylindrical:  # its X axis points along the radius through the origin
            theta += float(active.from_global(np.array([[a, b]]))[0, 1])
    s.db.local_systems[kcn] = CoordinateSystem(cylindrical, (a, b), theta)
    s.db.csys = kcn  # MAPDL: the new system becomes the active one


@command("LOCAL", ANY, 10)
def local(s: SessionState, c: Call) -> None:
    """LOCAL,KCN,KCS,XC,YC,ZC,THXY: origin (global Cartesian) and rotation about Z."""
    _define_system(s, c, relative=False)


@command("CLOCAL", ANY, 10)
def clocal(s: SessionState, c: Call) -> None:
    """CLOCAL,KCN,KCS,XL,YL,ZL,THXY: a local system placed in the active one."""
    _define_system(s, c, relative=True)


@command("CSDELE", ANY, 3)
def csdele(s: SessionState, c: Call) -> None:
    """CSDELE,KCN1,KCN2,KCINC: delete local systems (ALL: every one)."""
    systems = s.db.local_systems
    if c.label(1, "ALL") == "ALL":
        chosen = list(systems)
    else:
        first = c.int(1, what="KCN1")
        chosen = list(range(first, c.int(2, first, what="KCN2") + 1,
                            max(c.int(3, 1, what="KCINC"), 1)))
    for n in chosen:
        systems.pop(n, None)
    if s.db.csys in chosen:
        s.db.csys = 0  # MAPDL falls back to the global Cartesian system


def _node_xy(s: SessionState, number: int) -> np.ndarray:
    nodes = s.db.nodes
    i = int(nodes.index(number)[0])
    if i < 0:
        raise ApdlError(f"node {number} does not exist")
    return s.db.active_system.from_global(nodes.xy[i : i + 1])[0]


def _spacing(n: int, space: float) -> np.ndarray:
    """Fractions 0 < f_1 < ... < f_{n-1} < 1 of n intervals whose last/first ratio is space."""
    if n < 1:
        return np.zeros(0)
    if space <= 0.0:
        raise ApdlError(f"SPACE must be positive (a ratio), got {space!r}")
    if n == 1 or space == 1.0:
        lengths = np.ones(n)
    else:
        lengths = space ** (np.arange(n) / (n - 1))
    return np.cumsum(lengths)[:-1] / lengths.sum()


@command("FILL", PREP7, 8)
def fill(s: SessionState, c: Call) -> None:
    """FILL,NODE1,NODE2,NFILL,NSTRT,NINC,ITIME,INC,SPACE: nodes between two nodes."""
    history = s.db.node_history
    if c.given(1):
        n1 = c.int(1, what="NODE1")
        n2 = c.int(2, what="NODE2")
    elif len(history) >= 2:
        n1, n2 = history[-2], history[-1]
    else:
        raise ApdlError("FILL without nodes needs two nodes defined before it (N)")
    nfill = c.int(3, abs(n2 - n1) - 1, what="NFILL")
    if nfill < 1:
        return
    ninc = c.int(5, (n2 - n1) // (nfill + 1) if n2 != n1 else 1, what="NINC")
    nstrt = c.int(4, n1 + ninc, what="NSTRT")
    itime, inc = c.int(6, 1, what="ITIME"), c.int(7, 1, what="INC")
    space = c.num(8, 1.0, what="SPACE")
    if nfill * itime > MAX_GENERATED:
        raise ApdlError(f"FILL would make more than {MAX_GENERATED} nodes")
    fractions = _spacing(nfill + 1, space)
    for k in range(itime):
        a, b = _node_xy(s, n1 + k * inc), _node_xy(s, n2 + k * inc)
        for j, f in enumerate(fractions):
            x, y = s.db.active_system.to_global(*(a + f * (b - a)))
            s.db.nodes.add(nstrt + k * inc + j * ninc, x, y)


@command("NGEN", PREP7, 9)
def ngen(s: SessionState, c: Call) -> None:
    """NGEN,ITIME,INC,NODE1,NODE2,NINC,DX,DY,DZ: copies of a node pattern, offset."""
    itime = c.int(1, what="ITIME")
    inc = c.int(2, what="INC")
    nodes = s.db.nodes
    nodes.flush()
    if c.label(3) == "ALL" or not c.given(3):
        pattern = nodes.selected_ids()
    else:
        n1 = c.int(3, what="NODE1")
        n2 = c.int(4, n1, what="NODE2")
        ninc = c.int(5, 1, what="NINC")
        if ninc < 1:
            raise ApdlError("field 5 (NINC) must be ≥ 1")
        wanted = np.arange(n1, n2 + 1, ninc)
        pattern = wanted[nodes.index(wanted) >= 0]
    dx, dy = c.num(6, 0.0, what="DX"), c.num(7, 0.0, what="DY")
    if c.given(8) and c.num(8) != 0.0:
        raise ApdlError("field 8 (DZ) must be 0 in a 2-D model")
    if pattern.size * max(itime - 1, 0) > MAX_GENERATED:
        raise ApdlError(f"NGEN would make more than {MAX_GENERATED} nodes")
    system = s.db.active_system
    local = system.from_global(nodes.xy[nodes.index(pattern)])
    for k in range(1, itime):
        for num, (a, b) in zip(pattern.tolist(), local, strict=True):
            x, y = system.to_global(a + k * dx, b + k * dy)
            nodes.add(num + k * inc, x, y)


@command("EGEN", PREP7, 14)
def egen(s: SessionState, c: Call) -> None:
    """EGEN,ITIME,NINC,IEL1,IEL2,IEINC,MINC,TINC,RINC: copies of an element pattern with
    node numbers (and attributes) incremented."""
    itime = c.int(1, what="ITIME")
    ninc = c.int(2, what="NINC")
    el = s.db.elements
    el.flush()
    if not len(el.ids):
        raise ApdlError("there are no elements to generate from")
    if c.label(3) == "ALL" or not c.given(3):
        pattern = np.nonzero(el.selected)[0]
    else:
        first = c.int(3, what="IEL1")
        if first < 0:
            pattern = np.arange(len(el.ids) - min(-first, len(el.ids)), len(el.ids))
        else:
            last = c.int(4, first, what="IEL2")
            step = c.int(5, 1, what="IEINC")
            wanted = np.arange(first, last + 1, max(step, 1))
            idx = el.index(wanted)
            if np.any(idx < 0):
                raise ApdlError(f"element {int(wanted[np.nonzero(idx < 0)[0][0]])} does not exist")
            pattern = idx
    minc, tinc, rinc = (c.int(i, 0, what=w) for i, w in ((6, "MINC"), (7, "TINC"), (8, "RINC")))
    if pattern.size * max(itime - 1, 0) > MAX_GENERATED:
        raise ApdlError(f"EGEN would make more than {MAX_GENERATED} elements")
    number = int(el.ids.max()) + 1
    rows = [(int(el.type[i]), int(el.mat[i]), int(el.real[i]), el.nodes[i].copy())
            for i in pattern]
    nodes = s.db.nodes
    for k in range(1, itime):
        for etype, mat, real, conn in rows:
            new = np.where(conn > 0, conn + k * ninc, 0)
            missing = new[(new > 0) & (nodes.index(np.maximum(new, 1)) < 0)]
            if missing.size:
                raise ApdlError(f"EGEN: node {int(missing[0])} does not exist")
            if etype + k * tinc not in s.db.element_types:
                raise ApdlError(f"EGEN: element type {etype + k * tinc} is not defined")
            el.add(number, etype + k * tinc, mat + k * minc, real + k * rinc,
                   tuple(int(v) for v in new))
            number += 1


@command("EMID", PREP7, 2)
def emid(s: SessionState, c: Call) -> None:
    """EMID: mid-side nodes at the edge midpoints of quadratic elements that lack them."""
    db = s.db
    el, nodes = db.elements, db.nodes
    el.flush()
    nodes.flush()
    if not len(el.ids):
        return
    next_number = int(nodes.ids.max()) + 1
    made: dict[tuple[int, int], int] = {}
    for row in range(len(el.ids)):
        et = db.element_types.get(int(el.type[row]))
        if et is None or not et.quadratic or et.triangle6:
            continue
        conn = el.nodes[row]
        for col, (a, b) in zip(range(4, 8), ((0, 1), (1, 2), (2, 3), (3, 0)), strict=True):
            if conn[col] > 0:
                continue
            na, nb = int(conn[a]), int(conn[b])
            if na == nb:
                conn[col] = na  # the collapsed edge of a triangle
                continue
            key = (min(na, nb), max(na, nb))
            num = made.get(key)
            if num is None:
                ia, ib = nodes.index(np.array([na, nb]))
                x, y = 0.5 * (nodes.xy[ia] + nodes.xy[ib])
                num = made[key] = next_number
                next_number += 1
                nodes.add(num, float(x), float(y))
            conn[col] = num
    el.version += 1
    s.say(f"EMID: {len(made)} mid-side nodes")


@command("NUMMRG", PREP7, 5)
def nummrg(s: SessionState, c: Call) -> None:
    """NUMMRG,NODE|ALL[,TOLER]: elements use the lowest-numbered of coincident nodes."""
    label = c.label(1, "ALL")
    if label not in ("NODE", "ALL", "KP", "ELEM", "MAT", "TYPE", "REAL", "CP", "CE"):
        raise ApdlError(f"field 1: NUMMRG label must be NODE or ALL, got {label!r}")
    if label not in ("NODE", "ALL"):
        return
    from scipy.spatial import cKDTree

    nodes, el = s.db.nodes, s.db.elements
    nodes.flush()
    el.flush()
    if len(nodes.ids) < 2:
        return
    extent = float(np.ptp(nodes.xy, axis=0).max()) or 1.0
    toler = c.num(2, 1e-4, what="TOLER") * extent
    pairs = cKDTree(nodes.xy).query_pairs(toler, output_type="ndarray")
    if not pairs.size:
        return
    keep = np.arange(len(nodes.ids))
    for a, b in sorted(map(tuple, pairs)):
        ra, rb = keep[a], keep[b]
        keep[max(ra, rb)] = min(ra, rb)
    keep = keep[keep]
    new_number = nodes.ids[keep]
    idx = nodes.index(np.maximum(el.nodes, 1))
    el.nodes = np.where((el.nodes > 0) & (idx >= 0), new_number[np.maximum(idx, 0)], el.nodes)
    el.version += 1
    s.say(f"NUMMRG: {int(np.sum(keep != np.arange(keep.size)))} coincident nodes merged")


@command("ESURF", PREP7, 3)
def esurf(s: SessionState, c: Call) -> None:
    """ESURF: surface elements (the active TYPE, e.g. SURF151) on the exterior faces of the
    selected solid elements whose nodes are all selected."""
    from apdl_like.plane_solve import corners_and_midside

    db = s.db
    et = db.element_types.get(db.active_type)
    if et is None or et.physics != "surface":
        raise ApdlError(f"ESURF needs a surface element type active (ET,n,SURF151; TYPE,n), "
                        f"got {et.name if et else 'none'}")
    corners, _, solid = corners_and_midside(db)
    el, nodes = db.elements, db.nodes
    chosen = solid & el.selected
    a = corners[chosen].ravel()
    b = np.roll(corners[chosen], -1, axis=1).ravel()
    keep = a != b
    a, b = a[keep], b[keep]
    all_a = corners[solid].ravel()
    all_b = np.roll(corners[solid], -1, axis=1).ravel()
    ok = all_a != all_b
    ids = nodes.ids
    lo = np.minimum(ids[all_a[ok]], ids[all_b[ok]]) * (1 << 31) + \
        np.maximum(ids[all_a[ok]], ids[all_b[ok]])
    keys, counts = np.unique(lo, return_counts=True)
    exterior = set(keys[counts == 1].tolist())
    number = int(el.ids.max()) + 1
    made = 0
    for i, j in zip(a.tolist(), b.tolist(), strict=True):
        key = min(ids[i], ids[j]) * (1 << 31) + max(ids[i], ids[j])
        if key in exterior and nodes.selected[i] and nodes.selected[j]:
            el.add(number, db.active_type, db.active_mat, db.active_real,
                   (int(ids[i]), int(ids[j])))
            number += 1
            made += 1
    el.flush()
    s.say(f"ESURF: {made} surface elements")


def _coupling_label(c: Call, i: int) -> str:
    label = c.label(i)
    if label not in COUPLING_LABELS:
        raise ApdlError(f"field {i}: coupled DOF must be one of {', '.join(COUPLING_LABELS)}, "
                        f"got {label or '(empty)'!r}")
    return label


def _set_number(s: SessionState, c: Call) -> int:
    sets = s.db.couplings
    if not c.given(1) or c.label(1) in ("HIGH", "NEXT"):
        return max(sets, default=0) + 1
    return c.int(1, what="NSET")


@command("CP", PREP7, 19)
def cp(s: SessionState, c: Call) -> None:
    """CP,NSET,Lab,NODE1,...,NODE17: the nodes share one value of Lab."""
    nset = _set_number(s, c)
    label = _coupling_label(c, 2)
    nodes = s.db.nodes
    if c.label(3) == "ALL":
        numbers = nodes.selected_ids()
    else:
        numbers = np.array([c.int(i, what="NODE") for i in range(3, c.count() + 1)
                            if c.given(i)], np.int64)
    if np.any(nodes.index(np.abs(numbers)) < 0):
        raise ApdlError(f"node {int(numbers[nodes.index(np.abs(numbers)) < 0][0])} does not "
                        "exist")
    _add_coupling(s, nset, label, numbers[numbers > 0])


def _add_coupling(s: SessionState, nset: int, label: str, numbers: np.ndarray) -> None:
    old = s.db.couplings.get(nset)
    if old is not None and old[0] != label:
        raise ApdlError(f"coupled set {nset} holds {old[0]}, not {label}")
    merged = numbers if old is None else np.union1d(old[1], numbers)
    s.db.couplings[nset] = (label, np.unique(merged))


@command("CPNGEN", PREP7, 5)
def cpngen(s: SessionState, c: Call) -> None:
    """CPNGEN,NSET,Lab,NODE1,NODE2,NINC: nodes NODE1..NODE2 into one coupled set."""
    nset = _set_number(s, c)
    label = _coupling_label(c, 2)
    n1 = c.int(3, what="NODE1")
    n2 = c.int(4, n1, what="NODE2")
    ninc = c.int(5, 1, what="NINC")
    wanted = np.arange(n1, n2 + 1, max(ninc, 1))
    _add_coupling(s, nset, label, wanted[s.db.nodes.index(wanted) >= 0])


@command("CPINTF", PREP7, 2)
def cpintf(s: SessionState, c: Call) -> None:
    """CPINTF,Lab,TOLER: one coupled set per group of coincident selected nodes (within
    TOLER, default 1e-4, in every coordinate): the two sides of an interface meshed apart."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    label = _coupling_label(c, 1)
    toler = c.num(2, 1e-4, what="TOLER")
    nodes = s.db.nodes
    nodes.flush()
    chosen = np.nonzero(nodes.selected)[0]
    pairs = cKDTree(nodes.xy[chosen]).query_pairs(toler, p=np.inf, output_type="ndarray")
    if not pairs.size:
        return
    n = chosen.size
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, group = connected_components(graph, directed=False)
    sizes = np.bincount(group)
    for g in np.nonzero(sizes > 1)[0]:
        members = nodes.ids[chosen[group == g]]
        _add_coupling(s, max(s.db.couplings, default=0) + 1, label, members)
    s.say(f"CPINTF: {int(np.sum(sizes > 1))} coupled sets")


@command("CPSGEN", PREP7, 6)
def cpsgen(s: SessionState, c: Call) -> None:
    """CPSGEN,ITIME,INC,NSET1,NSET2,NINC: copies of coupled sets, node numbers + k·INC."""
    itime, inc = c.int(1, what="ITIME"), c.int(2, what="INC")
    first = c.int(3, what="NSET1")
    last = c.int(4, first, what="NSET2")
    step = c.int(5, 1, what="NINC")
    sets = s.db.couplings
    pattern = [n for n in range(first, last + 1, max(step, 1)) if n in sets]
    if not pattern:
        raise ApdlError(f"coupled set {first} does not exist")
    nodes = s.db.nodes
    for k in range(1, itime):
        for n in pattern:
            label, numbers = sets[n]
            new = numbers + k * inc
            new = new[nodes.index(new) >= 0]
            if new.size:
                sets[max(sets) + 1] = (label, new)


COMMANDS = (
    *specs_of(csys, local, clocal, csdele, fill, ngen, egen, emid, nummrg, esurf, cp, cpngen,
              cpintf, cpsgen),
)
