"""NSEL, ESEL, NSLE, ESLN, ALLSEL, CM, CMSEL, CMDELE (valid in every processor)."""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import MODEL, Call, Handler, command, specs_of
from apdl_like.errors import ApdlError
from apdl_like.model import Component
from apdl_like.selection import combine, in_range, number_range

if TYPE_CHECKING:
    from apdl_like.state import SessionState

_ANY_OR_BEGIN = MODEL | {"BEGIN"}


def _mode(c: Call) -> str:
    mode = c.label(1, "S")
    if mode not in ("S", "R", "A", "U", "ALL", "NONE", "INVE"):
        raise ApdlError(f"field 1: selection type must be S, R, A, U, ALL, NONE or INVE, "
                        f"got {mode!r}")
    return mode


def _select(c: Call, current: np.ndarray, default_item: str,
            pick: Callable[[str], np.ndarray]) -> np.ndarray:
    """The selection after an xSEL command: Type (field 1) combines `current` with the items
    `pick(Item)` marks (Item is field 2, `default_item` when blank); ALL, NONE and INVE need
    no item."""
    mode = _mode(c)
    if mode in ("ALL", "NONE", "INVE"):
        return combine(mode, current, current)
    return combine(mode, current, pick(c.label(2, default_item)))


def _range(c: Call) -> tuple[float, float, float]:
    vmin = c.num(4, what="VMIN")
    vmax = c.num(5, vmin, what="VMAX")
    vinc = c.num(6, 1.0, what="VINC")
    return vmin, vmax, vinc


def _nodes_picked(s: SessionState, c: Call, item: str) -> np.ndarray:
    nodes = s.db.nodes
    if item == "NODE" and c.label(4) == "ALL":
        return np.ones(len(nodes.ids), bool)  # NSEL,S,NODE,,ALL: every node
    if item == "NODE":
        return number_range(nodes.ids, *_range(c))
    if item == "LOC":
        comp = c.label(3)
        if comp not in ("X", "Y", "Z"):
            raise ApdlError(f"field 3: LOC takes X or Y (Z is 0 in a 2-D model), got {comp!r}")
        vmin = c.num(4, 0.0, what="VMIN")  # MAPDL: a blank VMIN is 0
        vmax = c.num(5, vmin, what="VMAX")
        local = s.db.active_system.from_global(nodes.xy)
        values = np.zeros(len(nodes.ids)) if comp == "Z" else local[:, "XY".index(comp)]
        return in_range(values, vmin, vmax)
    raise ApdlError(f"field 2: item must be NODE or LOC, got {item!r}")


def _elements_picked(s: SessionState, c: Call, item: str) -> np.ndarray:
    el = s.db.elements
    if item == "ELEM":
        return number_range(el.ids, *_range(c))
    if item in ("TYPE", "MAT", "REAL"):
        values = {"TYPE": el.type, "MAT": el.mat, "REAL": el.real}[item]
        return number_range(values, *_range(c))
    if item == "ENAME":  # ESEL,S,ENAME,,55: by the element type's name number
        numbers = {num: int(m.group(1)) if (m := re.search(r"(\d+)$", et.name)) else 0
                   for num, et in s.db.element_types.items()}
        values = np.array([numbers.get(int(t), 0) for t in el.type], dtype=float)
        named = re.fullmatch(r"[A-Z]+(\d+)", c.label(4))  # ESEL,S,ENAME,,PLANE55 too
        if named:
            number = float(named.group(1))
            return number_range(values, number, number, 1.0)
        return number_range(values, *_range(c))
    if item == "CENT" or item == "LOC":
        comp = c.label(3)
        if comp not in ("X", "Y"):
            raise ApdlError(f"field 3: {item} takes X or Y, got {comp!r}")
        vmin = c.num(4, what="VMIN")
        vmax = c.num(5, vmin, what="VMAX")
        return in_range(_centroids(s)[:, "XY".index(comp)], vmin, vmax)
    raise ApdlError(f"field 2: item must be ELEM, TYPE, ENAME, MAT, REAL or CENT, got "
                    f"{item!r}")


def _table_selection(table: str, default_item: str,
                     pick: Callable[[SessionState, Call, str], np.ndarray]) -> Handler:
    """The handler of NSEL / ESEL: selects among `s.db.<table>` the items `pick` marks."""

    def select(s: SessionState, c: Call) -> None:
        entities = getattr(s.db, table)
        entities.selected = _select(c, entities.selected, default_item,
                                    lambda item: pick(s, c, item))

    return select


nsel = command("NSEL", _ANY_OR_BEGIN, 7)(_table_selection("nodes", "NODE", _nodes_picked))
_select_elements = _table_selection("elements", "ELEM", _elements_picked)


@command("ESEL", _ANY_OR_BEGIN, 7)
def esel(s: SessionState, c: Call) -> None:
    """ESEL: a new element selection; as MAPDL documents for ESORT, it also restores the
    elements' original order (PRETAB lists by number again; *GET,,SORT still reads the
    last sort)."""
    s.element_order = None
    _select_elements(s, c)


def _centroids(s: SessionState) -> np.ndarray:
    el = s.db.elements
    corner = el.nodes[:, :4]
    idx = s.db.nodes.index(corner.ravel()).reshape(corner.shape)
    present = (corner > 0) & (idx >= 0)
    xy = s.db.nodes.xy[np.where(present, idx, 0)]
    # unique corners only (K = L counts once)
    dup = np.zeros_like(present)
    dup[:, 3] = corner[:, 3] == corner[:, 2]
    w = (present & ~dup).astype(float)
    return (xy * w[..., None]).sum(axis=1) / np.maximum(w.sum(axis=1), 1.0)[:, None]


def _element_node_indices(s: SessionState, element_mask: np.ndarray) -> np.ndarray:
    nums = s.db.elements.nodes[element_mask]
    nums = nums[nums > 0]
    idx = s.db.nodes.index(np.unique(nums))
    return idx[idx >= 0]


@command("NSLE", _ANY_OR_BEGIN, 3)
def nsle(s: SessionState, c: Call) -> None:
    mode = _mode(c)
    nodes = s.db.nodes
    picked = np.zeros(len(nodes.ids), bool)
    picked[_element_node_indices(s, s.db.elements.selected)] = True
    nodes.selected = combine(mode, nodes.selected, picked)


@command("ESLN", _ANY_OR_BEGIN, 3)
def esln(s: SessionState, c: Call) -> None:
    mode = _mode(c)
    key = c.int(2, 0, what="EKEY")
    el, nodes = s.db.elements, s.db.nodes
    num = el.nodes
    idx = nodes.index(num.ravel()).reshape(num.shape)
    sel = np.zeros(num.shape, bool)
    ok = (num > 0) & (idx >= 0)
    sel[ok] = nodes.selected[idx[ok]]
    picked = np.all(sel | ~ok, axis=1) if key == 1 else np.any(sel, axis=1)
    el.selected = combine(mode, el.selected, picked)


@command("ALLSEL", _ANY_OR_BEGIN, 2)
def allsel(s: SessionState, c: Call) -> None:
    s.db.nodes.selected = np.ones(len(s.db.nodes), bool)
    s.db.elements.selected = np.ones(len(s.db.elements), bool)
    s.db.unselected_keypoints.clear()
    s.db.unselected_lines.clear()
    s.db.unselected_areas.clear()


def _select_numbered(s: SessionState, c: Call, numbers: list[int], xy: np.ndarray,
                     unselected: set[int], item_name: str) -> None:
    """KSEL/LSEL: Type (S, R, A, U, ALL, NONE, INVE), Item (the entity's number, or LOC of
    its keypoint / its midpoint in the active coordinate system), Comp, VMIN, VMAX, VINC."""
    ids = np.array(numbers, np.int64)

    def pick(item: str) -> np.ndarray:
        if item == item_name:
            return number_range(ids, *_range(c))
        if item == "LOC":
            comp = c.label(3)
            if comp not in ("X", "Y"):
                raise ApdlError(f"field 3: LOC takes X or Y, got {comp!r}")
            vmin = c.num(4, 0.0, what="VMIN")
            vmax = c.num(5, vmin, what="VMAX")
            local = s.db.active_system.from_global(xy)
            return in_range(local[:, "XY".index(comp)], vmin, vmax)
        raise ApdlError(f"field 2: item must be {item_name} or LOC, got {item!r}")

    chosen = _select(c, ~np.isin(ids, list(unselected)), item_name, pick)
    unselected.clear()
    unselected.update(int(n) for n in ids[~chosen])


@command("KSEL", _ANY_OR_BEGIN, 7)
def ksel(s: SessionState, c: Call) -> None:
    kps = s.db.keypoints
    numbers = sorted(kps)
    _select_numbered(s, c, numbers, np.array([kps[n] for n in numbers], float),
                     s.db.unselected_keypoints, "KP")


@command("LSEL", _ANY_OR_BEGIN, 7)
def lsel(s: SessionState, c: Call) -> None:
    kps, lines = s.db.keypoints, s.db.lines
    numbers = sorted(lines)
    mids = np.array([0.5 * (np.array(kps[lines[n].k1]) + np.array(kps[lines[n].k2]))
                     for n in numbers], float)
    _select_numbered(s, c, numbers, mids, s.db.unselected_lines, "LINE")


@command("ASEL", _ANY_OR_BEGIN, 7)
def asel(s: SessionState, c: Call) -> None:
    kps, areas = s.db.keypoints, s.db.areas
    numbers = sorted(areas)
    centroids = np.array([np.mean([kps[k] for k in areas[n]], axis=0) for n in numbers],
                         float)
    _select_numbered(s, c, numbers, centroids, s.db.unselected_areas, "AREA")


@command("ESLA", _ANY_OR_BEGIN, 1)
def esla(s: SessionState, c: Call) -> None:
    """ESLA,Type: the elements AMESH made in the selected areas."""
    mode = _mode(c)
    if mode not in ("S", "R", "A", "U"):
        raise ApdlError(f"field 1: ESLA takes S, R, A or U, got {mode!r}")
    chosen = [n for n in sorted(s.db.area_elements) if n not in s.db.unselected_areas]
    numbers = np.concatenate([s.db.area_elements[n] for n in chosen]) if chosen else \
        np.zeros(0, np.int64)
    el = s.db.elements
    el.selected = combine(mode, el.selected, np.isin(el.ids, numbers))


_COMPONENT_NAME = re.compile(r"[A-Z][A-Z0-9_]{0,31}\Z")


def _component_name(c: Call, i: int) -> str:
    name = c.raw(i).upper()
    if not _COMPONENT_NAME.match(name):
        raise ApdlError(f"field {i}: {c.raw(i)!r} is not a valid component name")
    return name


@command("CM", _ANY_OR_BEGIN, 3)
def cm(s: SessionState, c: Call) -> None:
    name = _component_name(c, 1)
    entity = c.label(2)
    if entity == "NODE":
        s.db.components[name] = Component("NODE", s.db.nodes.selected_ids().copy())
    elif entity == "ELEM":
        s.db.components[name] = Component("ELEM", s.db.elements.selected_ids().copy())
    else:
        raise ApdlError(f"field 2: entity must be NODE or ELEM, got {entity or '(empty)'!r}")


@command("CMDELE", _ANY_OR_BEGIN, 1)
def cmdele(s: SessionState, c: Call) -> None:
    name = _component_name(c, 1)
    if s.db.components.pop(name, None) is None:
        raise ApdlError(f"component {name} does not exist")


def component(s: SessionState, name: str) -> Component:
    comp = s.db.components.get(name.upper())
    if comp is None:
        known = ", ".join(sorted(s.db.components)) or "none"
        raise ApdlError(f"component {name.upper()} does not exist (known: {known})")
    return comp


def component_mask(s: SessionState, comp: Component) -> np.ndarray:
    return comp.mask(s.db.nodes if comp.entity == "NODE" else s.db.elements)


@command("CMSEL", _ANY_OR_BEGIN, 3)
def cmsel(s: SessionState, c: Call) -> None:
    mode = c.label(1, "S")
    if mode in ("ALL", "NONE"):
        for comp in s.db.components.values():
            table = s.db.nodes if comp.entity == "NODE" else s.db.elements
            picked = component_mask(s, comp)
            table.selected = table.selected | picked if mode == "ALL" else \
                table.selected & ~picked
        return
    if mode not in ("S", "R", "A", "U"):
        raise ApdlError(f"field 1: selection type must be S, R, A, U, ALL or NONE, got {mode!r}")
    comp = component(s, _component_name(c, 2))
    table = s.db.nodes if comp.entity == "NODE" else s.db.elements
    table.selected = combine(mode, table.selected, component_mask(s, comp))


COMMANDS = (
    *specs_of(nsel, esel, nsle, esln, allsel, ksel, lsel, asel, esla, cm, cmdele, cmsel),
)
