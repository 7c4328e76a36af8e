"""Loads (valid in /PREP7 and /SOLU): D, F, SF, SFE, BF, BFE, IC, TUNIF, BFUNIF, TREF.

Every load command is a *record*: the entities it touches remember its id, so a later
command on a subset overrides only that subset, and the solver can turn each record back
into one region or boundary of the FEM mesh (see `apdl_like.fem_bridge`).  D,,TEMP, F,,HEAT,
SF/SFE (CONV, HFLUX) and BF/BFE (HGEN) also take a table, `%NAME%`
(`apdl_like.tabular_loads`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import LOADS, Call, command, existing, specs_of
from apdl_like.commands.selection import component, component_mask
from apdl_like.errors import ApdlError
from apdl_like.model import pair_keys
from apdl_like.solve import face_table
from apdl_like.tabular_loads import mark, table_slot

if TYPE_CHECKING:
    from apdl_like.state import SessionState


def _named_targets(s: SessionState, c: Call, i: int, entity: str) -> np.ndarray | None:
    """Rows named by field i without a number: ALL (the selected ones) or a component of
    `entity` (NODE or ELEM); None when the field is a number (or a parameter)."""
    noun, other = ("node", "elements") if entity == "NODE" else ("element", "nodes")
    table = s.db.nodes if entity == "NODE" else s.db.elements
    text = c.label(i)
    if not text:
        raise ApdlError(f"field {i} ({noun}) is required")
    if text == "ALL":
        return np.nonzero(table.selected)[0]
    if text == "P":
        raise ApdlError("graphical picking (P) is not available in a deck")
    if text[0].isalpha() and text.upper() in s.db.components:
        comp = component(s, text)
        if comp.entity != entity:
            raise ApdlError(f"component {text} holds {other}, not {noun}s")
        return np.nonzero(component_mask(s, comp))[0]
    if text[0].isalpha() and not any(ch in text for ch in "+-*/(") and \
            text.upper() not in s.params:
        raise ApdlError(f"field {i}: {text} is neither ALL, a component, nor a parameter")
    return None


def node_targets(s: SessionState, c: Call, i: int = 1, end_field: int | None = None) -> np.ndarray:
    """Node indices named by field i: ALL (selected), a component, or a number [NEND, NINC]."""
    named = _named_targets(s, c, i, "NODE")
    if named is not None:
        return named
    first = c.int(i, what="node")
    nums = np.array([first])
    if end_field is not None and c.given(end_field):
        last = c.int(end_field, what="NEND")
        step = c.int(end_field + 1, 1, what="NINC")
        if step < 1:
            raise ApdlError(f"field {end_field + 1} (NINC) must be ≥ 1")
        if (last - first) // step > 10_000_000:
            raise ApdlError("node range too long")
        nums = np.arange(first, last + 1, step)
    idx = s.db.nodes.index(nums)
    if np.any(idx < 0):
        raise ApdlError(f"node {int(nums[np.nonzero(idx < 0)[0][0]])} does not exist")
    return idx


def element_targets(s: SessionState, c: Call, i: int = 1) -> np.ndarray:
    named = _named_targets(s, c, i, "ELEM")
    if named is not None:
        return named
    num = c.int(i, what="element")
    idx = s.db.elements.index(num)
    if idx[0] < 0:
        raise ApdlError(f"element {num} does not exist")
    return idx


_D_LABELS = {"TEMP": ("d_temp",), "UX": ("d_ux",), "UY": ("d_uy",), "ALL": ("d_ux", "d_uy")}


@command("D", LOADS, 11)
def d(s: SessionState, c: Call) -> None:
    labels = [_dof_label(c, i) for i in (2, 7, 8, 9, 10, 11) if i == 2 or c.given(i)]
    value, slot = _dof_value(s, c, 3, labels, "VALUE")
    if c.given(4) and c.num(4) != 0.0:
        raise ApdlError("field 4 (VALUE2, imaginary part) is not supported")
    _fix_dofs(s, node_targets(s, c, 1, end_field=5), labels, value, slot)
    s.note_load(c)


def _dof_value(s: SessionState, c: Call, i: int, labels: list[str],
               what: str) -> tuple[float, int | None]:
    """(value, None) of field i, or (placeholder, slot) when it names a table (TEMP only)."""
    slot = table_slot(s, c, i)
    if slot is None:
        return c.num(i, 0.0, what=what), None
    if any(lab != "TEMP" for lab in labels):
        raise ApdlError(f"field {i} ({what}): a table is supported for TEMP only")
    return 0.0, slot


def _fix_dofs(s: SessionState, idx: np.ndarray, labels: list[str], value: float,
              slot: int | None = None) -> None:
    arrays = s.db.nodes.arrays
    for lab in labels:
        for key in _D_LABELS[lab]:
            arrays[key][idx] = value
    if "TEMP" in labels:
        mark(s.db, arrays["d_temp_table"], idx, slot)


def _dof_label(c: Call, i: int) -> str:
    if (lab := c.label(i)) in _D_LABELS:
        return lab
    raise ApdlError(f"field {i}: DOF label must be TEMP, UX, UY or ALL, got {lab or '(empty)'!r}")


@command("F", LOADS, 6)
def f_load(s: SessionState, c: Call) -> None:
    """F,NODE,HEAT,VALUE,,NEND,NINC: a heat flow into nodes, W (axisymmetric: over the whole
    circumference, as MAPDL takes it), a value or a table."""
    if c.label(2) != "HEAT":
        raise ApdlError(f"field 2: nodal load must be HEAT, got {c.label(2) or '(empty)'!r}")
    if c.given(4) and c.num(4) != 0.0:
        raise ApdlError("field 4 (VALUE2, imaginary part) is not supported")
    slot = table_slot(s, c, 3)
    value = 0.0 if slot is not None else c.num(3, 0.0, what="VALUE")
    idx = node_targets(s, c, 1, end_field=5)
    arrays = s.db.nodes.arrays
    arrays["f_heat"][idx] = value
    mark(s.db, arrays["f_heat_table"], idx, slot)
    s.note_load(c)


@command("FDELE", LOADS, 4)
def fdele(s: SessionState, c: Call) -> None:
    """FDELE,NODE,HEAT|ALL,NEND,NINC."""
    if c.label(2, "ALL") not in ("HEAT", "ALL"):
        raise ApdlError(f"field 2 must be HEAT or ALL, got {c.label(2)!r}")
    idx = node_targets(s, c, 1, end_field=3)
    s.db.nodes.arrays["f_heat"][idx] = np.nan
    mark(s.db, s.db.nodes.arrays["f_heat_table"], idx, None)


# ------------------------------------------------------------------ solid-model loads
# MAPDL keeps DK/DL/SFL on the keypoints and lines and transfers them to the mesh at SOLVE
# (SBCTRAN); here they are transferred when given, so the lines must be meshed by then.

def _nodes_on_lines(s: SessionState, c: Call, i: int) -> np.ndarray:
    """Indices of the nodes on the line named by field i, or on every selected line (ALL)."""
    if c.label(i) != "ALL":
        return _nodes_on_line(s, c.int(i, what="line"))
    chosen = [n for n in sorted(s.db.lines) if n not in s.db.unselected_lines]
    if not chosen:
        raise ApdlError(f"field {i}: ALL, but no line is selected (LSEL)")
    return np.unique(np.concatenate([_nodes_on_line(s, n) for n in chosen]))


def _nodes_on_line(s: SessionState, num: int) -> np.ndarray:
    """Indices of the nodes on straight line `num` (its ends included)."""
    ln = s.db.lines.get(num)
    if ln is None:
        raise ApdlError(f"line {num} does not exist")
    a = np.array(s.db.keypoints[ln.k1], float)
    b = np.array(s.db.keypoints[ln.k2], float)
    s.db.nodes.flush()
    xy = s.db.nodes.xy
    t = np.clip((xy - a) @ (b - a) / float((b - a) @ (b - a)), 0.0, 1.0)
    off = np.linalg.norm(xy - (a + t[:, None] * (b - a)), axis=1)
    idx = np.nonzero(off <= 1e-9 * float(np.linalg.norm(b - a)))[0]
    if idx.size == 0:
        raise ApdlError(f"line {num} has no nodes: mesh it (AMESH) before loading it")
    return idx


@command("DK", LOADS, 8)
def dk(s: SessionState, c: Call) -> None:
    """DK,KPOI,Lab,VALUE: a DOF constraint at the node on keypoint KPOI (ALL: selected)."""
    if c.label(1) == "ALL":
        chosen = [n for n in sorted(s.db.keypoints) if n not in s.db.unselected_keypoints]
    else:
        chosen = [c.int(1, what="KPOI")]
    s.db.nodes.flush()
    xy = s.db.nodes.xy
    idx = []
    for num in chosen:
        if num not in s.db.keypoints:
            raise ApdlError(f"keypoint {num} does not exist")
        dist = np.linalg.norm(xy - np.array(s.db.keypoints[num], float), axis=1)
        if dist.size == 0 or dist.min() > 1e-9 * max(1.0, float(np.abs(xy).max())):
            raise ApdlError(f"keypoint {num} has no node: mesh it (AMESH) before loading it")
        idx.append(int(np.argmin(dist)))
    if not idx:
        raise ApdlError("field 1: ALL, but no keypoint is selected (KSEL)")
    labels = [_dof_label(c, 2)]
    _fix_dofs(s, np.array(idx), labels, *_dof_value(s, c, 3, labels, "VALUE"))
    s.note_load(c)


@command("DL", LOADS, 6)
def dl(s: SessionState, c: Call) -> None:
    """DL,LINE,AREA,Lab,Value1: a DOF constraint on every node of a line."""
    labels = [_dof_label(c, 3)]
    if c.given(5):
        raise ApdlError("field 5 (Value2) is not supported")
    _fix_dofs(s, _nodes_on_lines(s, c, 1), labels, *_dof_value(s, c, 4, labels, "Value1"))
    s.note_load(c)


@command("DDELE", LOADS, 5)
def ddele(s: SessionState, c: Call) -> None:
    lab = c.label(2, "ALL")
    keys = {"TEMP": ("d_temp",), "UX": ("d_ux",), "UY": ("d_uy",),
            "ALL": ("d_temp", "d_ux", "d_uy")}.get(lab)
    if keys is None:
        raise ApdlError(f"field 2: DOF label must be TEMP, UX, UY or ALL, got {lab!r}")
    idx = node_targets(s, c, 1, end_field=3)
    for key in keys:
        s.db.nodes.arrays[key][idx] = np.nan
    if "d_temp" in keys:
        mark(s.db, s.db.nodes.arrays["d_temp_table"], idx, None)


def _faces_on_nodes(s: SessionState, idx: np.ndarray) -> np.ndarray:
    fem = face_table(s)
    mask = np.zeros(len(s.db.nodes.ids), bool)
    mask[idx] = True
    return np.nonzero(mask[fem.face_nodes[0]] & mask[fem.face_nodes[1]])[0]


def _set_face_load(s: SessionState, faces: np.ndarray, lab: str, v1: float | None,
                   v2: float | None, slot1: int | None = None,
                   slot2: int | None = None) -> None:
    """Lab's values v1 (h or flux), v2 (bulk temperature) on the faces; a slot: the value
    comes from that table (v1, v2 are placeholders then)."""
    db = s.db
    f = db.faces
    rec = db.next_record()
    if lab == "CONV":
        if v1 is not None:
            if v1 < 0.0:
                raise ApdlError(f"film coefficient must be ≥ 0, got {v1!r}")
            f.conv_h[faces] = v1
            mark(db, f.conv_h_table, faces, slot1)
        if v2 is not None:
            f.conv_bulk[faces] = v2
            mark(db, f.conv_bulk_table, faces, slot2)
        f.conv_record[faces] = rec
    elif lab == "RDSF":
        if v1 is None or not 0.0 < v1 <= 1.0:
            raise ApdlError(f"RDSF emissivity must lie in (0, 1], got {v1!r}")
        f.rdsf_emis[faces] = v1
        f.rdsf_encl[faces] = 1.0 if v2 is None else v2
    else:
        f.hflux[faces] = v1
        f.hflux_record[faces] = rec
        mark(db, f.hflux_table, faces, slot1)


@command("SF", LOADS, 4)
def sf(s: SessionState, c: Call) -> None:
    _load_faces_on(s, c, node_targets(s, c, 1), 4, "the node set")


def _load_faces_on(s: SessionState, c: Call, nodes: np.ndarray, bulk_field: int,
                   where: str) -> None:
    """SF/SFL: Lab in field 2 (CONV: h in field 3, the bulk temperature in `bulk_field`;
    HFLUX: the flux in field 3) on the exterior faces with all their nodes in `nodes`."""
    lab = c.label(2)
    if lab not in ("CONV", "HFLUX", "RDSF"):
        raise ApdlError(f"field 2: surface load must be CONV, HFLUX or RDSF, got "
                        f"{lab or '(empty)'!r}")
    slot1 = table_slot(s, c, 3) if lab != "RDSF" else None
    slot2 = table_slot(s, c, bulk_field) if lab == "CONV" else None
    v1 = 0.0 if slot1 is not None else c.num(3, what="VALUE")
    v2 = 0.0 if slot2 is not None else \
        c.num(bulk_field, what="bulk temperature") if lab == "CONV" else \
        c.num(bulk_field, 1.0, what="enclosure number") if lab == "RDSF" else None
    faces = _faces_on_nodes(s, nodes)
    if faces.size == 0:
        raise ApdlError(f"no exterior element face has all its nodes on {where}")
    _set_face_load(s, faces, lab, v1, v2, slot1, slot2)
    if lab != "RDSF":  # radiation surfaces also serve /AUX12 view factors without a SOLVE
        s.note_load(c)


@command("SFL", LOADS, 7)
def sfl(s: SessionState, c: Call) -> None:
    """SFL,LINE,Lab,VALI,VALJ,VAL2I,VAL2J: CONV (h, bulk temperature) or HFLUX on the
    element faces along a line; uniform only (VALJ and VAL2J blank or equal to the I end)."""
    for j, i in ((4, 3), (6, 5)):
        if c.given(j) and c.num(j) != c.num(i, 0.0):
            raise ApdlError(f"field {j}: a load varying along the line is not supported")
    _load_faces_on(s, c, _nodes_on_lines(s, c, 1), 5, "the line")


@command("SFDELE", LOADS, 2)
def sfdele(s: SessionState, c: Call) -> None:
    lab = c.label(2, "ALL")
    if lab not in ("CONV", "HFLUX", "RDSF", "ALL"):
        raise ApdlError(f"field 2 must be CONV, HFLUX, RDSF or ALL, got {lab!r}")
    faces = _faces_on_nodes(s, node_targets(s, c, 1))
    f = s.db.faces
    if lab in ("CONV", "ALL"):
        f.conv_h[faces], f.conv_bulk[faces], f.conv_record[faces] = np.nan, np.nan, -1
        mark(s.db, f.conv_h_table, faces, None)
        mark(s.db, f.conv_bulk_table, faces, None)
    if lab in ("HFLUX", "ALL"):
        f.hflux[faces], f.hflux_record[faces] = np.nan, -1
        mark(s.db, f.hflux_table, faces, None)
    if lab in ("RDSF", "ALL"):
        f.rdsf_emis[faces], f.rdsf_encl[faces] = np.nan, np.nan


def _element_faces(s: SessionState, elems: np.ndarray, lkey: int) -> np.ndarray:
    db = s.db
    fem = face_table(s)
    nodes = db.elements.nodes[elems]
    tri6 = np.array([db.element_types[int(t)].triangle6 for t in db.elements.type[elems]], bool)
    corners = nodes[:, :4].copy()
    corners[tri6, 3] = corners[tri6, 2]
    surface = np.array([db.element_types[int(t)].physics == "surface"
                        for t in db.elements.type[elems]], bool)
    if surface.all():  # SURF151: its one face is the solid face it lies on
        a, b = corners[:, 0], corners[:, 1]
    elif surface.any():
        raise ApdlError("SFE on surface and solid elements at once: select one kind")
    elif lkey == 3:
        a, b = corners[:, 2], corners[:, 3]
        a = np.where(tri6, corners[:, 2], a)
        b = np.where(tri6, corners[:, 0], b)
    else:
        a, b = {1: (corners[:, 0], corners[:, 1]), 2: (corners[:, 1], corners[:, 2]),
                4: (corners[:, 3], corners[:, 0])}[lkey]
    if np.any(a == b):
        bad = int(db.elements.ids[elems[np.nonzero(a == b)[0][0]]])
        raise ApdlError(f"face {lkey} of element {bad} is collapsed (triangle K = L)")
    faces = fem.face_index(pair_keys(a, b))
    if np.any(faces < 0):
        bad = int(db.elements.ids[elems[np.nonzero(faces < 0)[0][0]]])
        raise ApdlError(f"face {lkey} of element {bad} is not on the outer boundary")
    return faces


@command("SFE", LOADS, 8)
def sfe(s: SessionState, c: Call) -> None:
    lkey = c.int(2, 1, what="LKEY")
    if lkey not in (1, 2, 3, 4):
        raise ApdlError(f"field 2 (LKEY) must be 1..4, got {lkey}")
    lab = c.label(3)
    if lab not in ("CONV", "HFLUX"):
        raise ApdlError(f"field 3: surface load must be CONV or HFLUX, got {lab or '(empty)'!r}")
    kval = c.int(4, 0, what="KVAL")
    value, slot = _uniform_value(s, c, 5, (6, 7, 8),
                                 "values varying along a face (VAL2..VAL4) are not supported")
    faces = _element_faces(s, element_targets(s, c, 1), lkey)
    if lab == "CONV":
        if kval not in (0, 1, 2):
            raise ApdlError(f"field 4 (KVAL) must be 0/1 (film coefficient) or 2 (bulk "
                            f"temperature), got {kval}")
        _set_face_load(s, faces, lab, value if kval < 2 else None, value if kval == 2 else None,
                       slot if kval < 2 else None, slot if kval == 2 else None)
    else:
        _set_face_load(s, faces, lab, value, None, slot)
    s.note_load(c)


def _uniform_value(s: SessionState, c: Call, first: int, others: tuple[int, ...],
                   refusal: str) -> tuple[float, int | None]:
    """(VAL1, None), or (placeholder, slot) when VAL1 names a table; VAL2.. blank or equal
    (else ApdlError(refusal))."""
    slot = table_slot(s, c, first)
    value = 0.0 if slot is not None else c.num(first, what="VAL1")
    for i in others:
        if c.given(i) and (c.table(i) != c.table(first) if slot is not None else
                           c.num(i) != value):
            raise ApdlError(refusal)
    return value, slot


def _set_hgen(s: SessionState, elems: np.ndarray, value: float | None,
              slot: int | None = None) -> None:
    arrays = s.db.elements.arrays
    arrays["hgen"][elems] = np.nan if value is None else value
    arrays["hgen_record"][elems] = -1 if value is None else s.db.next_record()
    mark(s.db, arrays["hgen_table"], elems, slot)


@command("BF", LOADS, 6)
def bf(s: SessionState, c: Call) -> None:
    lab = c.label(2)
    if lab == "TEMP":
        value = c.num(3, what="VAL1")
        idx = node_targets(s, c, 1)
        s.db.nodes.arrays["bf_temp"][idx] = value
    elif lab == "HGEN":
        comp = s.db.components.get(c.label(1))
        slot = table_slot(s, c, 3)
        if comp is not None and comp.entity == "ELEM":
            _set_hgen(s, element_targets(s, c, 1), 0.0 if slot is not None else
                      c.num(3, what="VAL1"), slot)
        elif slot is not None:
            raise ApdlError("nodal HGEN from a table (BF,Node,HGEN,%table%) is not supported: "
                            "use BFE,ALL,HGEN,,%table% on the selected elements")
        else:
            # MAPDL: the nodal rate "multiplied by the weighted nodal volume of each element
            # adjacent to that node" (apdl_like.plane_thermal, `nodal_hgen`)
            value = c.num(3, what="VAL1")
            idx = node_targets(s, c, 1)
            s.db.nodes.arrays["bf_hgen"][idx] = value
    else:
        raise ApdlError(f"field 2: body load must be TEMP or HGEN, got {lab or '(empty)'!r}")
    s.note_load(c)


@command("BFE", LOADS, 7)
def bfe(s: SessionState, c: Call) -> None:
    lab = c.label(2)
    if lab != "HGEN":
        raise ApdlError(f"field 2: element body load must be HGEN, got {lab or '(empty)'!r}")
    stloc = c.int(3, 1, what="STLOC")
    if stloc != 1:
        raise ApdlError("field 3 (STLOC): only a uniform value from location 1 is supported")
    value, slot = _uniform_value(s, c, 4, (5, 6, 7), "HGEN varying inside an element "
                                 "(VAL2..VAL4) is not supported")
    _set_hgen(s, element_targets(s, c, 1), value, slot)
    s.note_load(c)


def _solid_entities(c: Call, command_name: str, table: dict, unselected: set[int],
                    field_name: str, what: str) -> list[int]:
    """The keypoints or areas of BFK/BFA field 1 (ALL: the selected ones); field 2 HGEN."""
    if c.label(2) != "HGEN":
        raise ApdlError(f"field 2: {command_name} supports HGEN, got "
                        f"{c.label(2) or '(empty)'!r}")
    chosen = [n for n in sorted(table) if n not in unselected] if c.label(1) == "ALL" else \
        [c.entity(1, field_name)]
    return existing(chosen, table, what)


@command("BFK", LOADS, 6)
def bfk(s: SessionState, c: Call) -> None:
    """BFK,KPOI|ALL,HGEN,VAL1: heat generation at keypoints.  As MAPDL transfers keypoint
    body loads, a meshed line or area whose keypoints all carry one takes it: along a line
    it varies linearly between the two end values (each element gets the value at its
    midpoint); an area takes a value only when its keypoints agree."""
    db = s.db
    for num in _solid_entities(c, "BFK", db.keypoints, db.unselected_keypoints, "KPOI",
                               "keypoint"):
        db.keypoint_hgen[num] = c.num(3, what="VAL1")
    el = db.elements
    el.flush()
    loads = db.keypoint_hgen
    for num, elements in db.line_elements.items():
        ln = db.lines[num]
        if ln.k1 in loads and ln.k2 in loads:
            idx = el.index(elements)
            p1, p2 = (np.array(db.keypoints[k], float) for k in (ln.k1, ln.k2))
            mid = 0.5 * (db.nodes.xy[db.nodes.index(el.nodes[idx, 0])] +
                         db.nodes.xy[db.nodes.index(el.nodes[idx, 1])])
            f = np.clip((mid - p1) @ (p2 - p1) / float((p2 - p1) @ (p2 - p1)), 0.0, 1.0)
            values = loads[ln.k1] + f * (loads[ln.k2] - loads[ln.k1])
            for value in np.unique(values):
                _set_hgen(s, idx[values == value], float(value))
    for num, elements in db.area_elements.items():
        kps = db.areas[num]
        if all(k in loads for k in kps) and len({loads[k] for k in kps}) == 1:
            _set_hgen(s, el.index(elements), loads[kps[0]])
    s.note_load(c)


@command("BFA", LOADS, 6)
def bfa(s: SessionState, c: Call) -> None:
    """BFA,AREA|ALL,HGEN,VAL1: heat generation on the elements of meshed areas (ALL: the
    selected ones), as MAPDL transfers an area body load to its elements."""
    db = s.db
    slot = table_slot(s, c, 3)
    value = 0.0 if slot is not None else c.num(3, what="VAL1")
    db.elements.flush()
    for num in _solid_entities(c, "BFA", db.areas, db.unselected_areas, "AREA", "area"):
        if num not in db.area_elements:
            raise ApdlError(f"area {num} is not meshed: AMESH it before BFA")
        _set_hgen(s, db.elements.index(db.area_elements[num]), value, slot)
    s.note_load(c)


@command("BFEDELE", LOADS, 2)
def bfedele(s: SessionState, c: Call) -> None:
    lab = c.label(2, "ALL")
    if lab not in ("HGEN", "ALL"):
        raise ApdlError(f"field 2 must be HGEN or ALL, got {lab!r}")
    _set_hgen(s, element_targets(s, c, 1), None)


@command("IC", LOADS, 5)
def ic(s: SessionState, c: Call) -> None:
    lab = c.label(2, "TEMP")
    if lab != "TEMP":
        raise ApdlError(f"field 2: initial condition must be TEMP, got {lab!r}")
    value = c.num(3, 0.0, what="VALUE")
    # the targets first: they merge nodes just added, which replaces the arrays
    idx = node_targets(s, c, 1)
    s.db.nodes.arrays["ic_temp"][idx] = value


@command("TUNIF", LOADS, 1)
def tunif(s: SessionState, c: Call) -> None:
    s.db.settings.tunif = c.num(1, 0.0, what="TEMP")


@command("BFUNIF", LOADS, 2)
def bfunif(s: SessionState, c: Call) -> None:
    if c.label(1) != "TEMP":
        raise ApdlError(f"field 1: BFUNIF supports TEMP only, got {c.label(1) or '(empty)'!r}")
    s.db.settings.tunif = c.num(2, 0.0, what="VALUE")


@command("TREF", LOADS, 1)
def tref(s: SessionState, c: Call) -> None:
    s.db.settings.tref = c.num(1, 0.0, what="TREF")


@command("SFCUM", LOADS, 4)
def sfcum(s: SessionState, c: Call) -> None:
    """SFCUM,Lab,Oper,FACT,FACT2: REPL (the default: a new surface load replaces the old
    one) with factors 1 is what SF, SFE and SFL do here; ADD, IGNO and factors are refused
    rather than ignored."""
    oper = c.label(2, "REPL")
    factors = [c.num(i, 1.0, what=name) for i, name in ((3, "FACT"), (4, "FACT2"))]
    if oper != "REPL" or factors != [1.0, 1.0]:
        raise ApdlError("only SFCUM,,REPL with factors 1 is supported (surface loads "
                        "replace the ones before them)")


COMMANDS = (
    *specs_of(d, ddele, f_load, fdele, dk, dl, sf, sfl, sfdele, sfe, sfcum, bf, bfe, bfk, bfa,
              bfedele, ic, tunif, bfunif, tref),
)
