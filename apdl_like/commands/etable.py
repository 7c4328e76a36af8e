"""/POST1 element tables: ETABLE and SSUM (*GET,Par,SSUM,,ITEM,Lab).

ETABLE,Lab,Item,Comp stores one value per selected element (0 for the others) of the
current thermal result, as MAPDL's element table does; SSUM sums every column over the
elements selected when it runs.  The items are the thermal ones decks use:

    SMISC,1    of LINK31/32/33/34  HEAT RATE Q = g (TI − TJ), W (apdl_like.line_thermal)
    SMISC,2/3  of LINK32/33        the node temperatures TI, TJ
    SMISC,2    of SURF151          heat rate its convection takes out of the solid,
                                   ∫ h (T − T_bulk) dA, W
    TG,X|Y|SUM of PLANE35/55/77    thermal gradient at the centroid, °C/m
    TF,X|Y|SUM of PLANE35/55/77    heat flux −(KXX ∂T/∂x, KYY ∂T/∂y) at the centroid, W/m²
    VOLU                           element volume, m³: area × unit thickness (planar), the
                                   full 360° ∫ 2πr dA (axisymmetric), A·L of LINK32/33
    HEAT                           the element's nodal heat flows summed over its nodes, W,
                                   counted as FSUM counts them (an element force item:
                                   MAPDL sums, not averages, them): q̇·V for an element with
                                   heat generation and no face load, as its conduction part
                                   sums to zero

An element without the item gets 0, as in MAPDL's table.  ESORT,ETAB,Lab sorts the selected
elements by a column for *GET,,SORT and PRETAB's order (EUSORT undoes it).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import POST, Call, command, specs_of
from apdl_like.commands.post1 import sorted_rows
from apdl_like.commands.post26 import plane_solution
from apdl_like.errors import ApdlError
from apdl_like.model import pair_keys

if TYPE_CHECKING:
    from apdl_like.plane_thermal import PlaneThermal, ThermalInputs
    from apdl_like.state import SessionState


def _smisc(s: SessionState, comp: int) -> np.ndarray:
    """Per element of the deck's table the SMISC item `comp` (NaN where it has none)."""
    model, inputs = plane_solution(s)
    res = s.result()
    if res.analysis != "thermal":
        raise ApdlError("ETABLE,,SMISC reads a thermal result")
    T = res.temperature
    db = s.db
    el = db.elements
    out = np.full(len(el.ids), np.nan)
    names = np.array([db.element_types[int(t)].name for t in el.type])
    links = model.links
    if comp == 1 and links is not None:
        rate = links.heat_rate(T, inputs.kxx, inputs.hf or [])
        ok = links.kind != "mass"
        out[links.elements[ok]] = rate[ok]
    if comp in (2, 3) and links is not None:
        bars = links.kind == "conduction"
        out[links.elements[bars]] = T[(links.i if comp == 2 else links.j)[bars]]
    if comp == 2:
        surf = np.nonzero(names == "SURF151")[0]
        if surf.size:
            keys = pair_keys(el.nodes[surf, 0], el.nodes[surf, 1])
            out[surf] = model.film_heat(inputs, T, keys)
    return out


def _centroid_item(s: SessionState, item: str, comp: str) -> np.ndarray:
    """TG (∇T, °C/m) or TF (heat flux, W/m²) at the element centroids: component X, Y or
    SUM (the vector's length); NaN for elements without it (links, surface elements)."""
    if comp not in ("X", "Y", "SUM"):
        raise ApdlError(f"field 3: {item} takes X, Y or SUM, got {comp or '(empty)'!r}")
    model, inputs = plane_solution(s)
    res = s.result()
    if res.analysis != "thermal":
        raise ApdlError(f"ETABLE,,{item} reads a thermal result")
    grad, flux = model.centroid_gradient(inputs, res.temperature, len(s.db.elements.ids))
    vec = grad if item == "TG" else flux
    return np.hypot(vec[:, 0], vec[:, 1]) if comp == "SUM" else vec[:, "XY".index(comp)]


def _thermal_model(s: SessionState, item: str) -> tuple[PlaneThermal, ThermalInputs]:
    model, inputs = plane_solution(s)
    if s.result().analysis != "thermal":
        raise ApdlError(f"ETABLE,,{item} reads a thermal result")
    return model, inputs


def _volume(s: SessionState) -> np.ndarray:
    """VOLU per element of the deck's table (NaN where an element has none)."""
    model, _ = _thermal_model(s, "VOLU")
    return model.element_volume(len(s.db.elements.ids))


def _heat(s: SessionState) -> np.ndarray:
    """HEAT per element of the table: its nodal heat flows summed, FSUM's sign (NaN for the
    unselected elements and SURF151, whose film is in the solid's heat)."""
    model, inputs = _thermal_model(s, "HEAT")
    T = s.result().temperature
    db = s.db
    out = np.full(len(db.elements.ids), np.nan)
    for e in np.nonzero(db.elements.selected)[0]:
        if db.element_types[int(db.elements.type[e])].physics != "surface":
            out[e] = -float(model.element_heat(inputs, T, int(e)).sum()) + 0.0  # no -0.0
    return out


@command("ETABLE", POST, 4)
def etable(s: SessionState, c: Call) -> None:
    """ETABLE,Lab,Item,Comp (ETABLE,ERAS deletes every column)."""
    lab = c.label(1)
    if lab in ("ERAS", "ERASE"):
        s.element_table.clear()
        return
    if not lab:
        raise ApdlError("field 1 (Lab) is required")
    item = c.label(2)
    if item in ("TG", "TF"):
        selected = s.db.elements.selected
        s.element_table[lab] = np.where(selected, np.nan_to_num(_centroid_item(s, item,
                                                                               c.label(3))), 0.0)
        return
    if item in ("VOLU", "HEAT"):
        values, what = (_volume(s) if item == "VOLU" else _heat(s)), item
    else:
        if item != "SMISC":
            raise ApdlError(f"field 2: ETABLE supports SMISC, TG, TF, VOLU and HEAT, got "
                            f"{item or '(empty)'!r}")
        comp = c.int(3, what="Comp")
        if comp not in (1, 2, 3):
            raise ApdlError("field 3: SMISC supports 1 (a link's HEAT RATE), 2 and 3 (a bar's "
                            "TI, TJ; 2: a SURF151's convection heat rate)")
        values, what = _smisc(s, comp), f"SMISC,{comp}"
    selected = s.db.elements.selected
    if not np.any(selected & ~np.isnan(values)):
        s.say(f"ETABLE: no selected element has {what}; {lab} is 0")
    s.element_table[lab] = np.where(selected, np.nan_to_num(values), 0.0)


@command("SSUM", POST, 0)
def ssum(s: SessionState, c: Call) -> None:
    """SSUM: each element table column summed over the selected elements."""
    selected = s.db.elements.selected
    s.element_sums = {lab: float(v[selected].sum()) for lab, v in s.element_table.items()
                      if v.size == selected.size}
    for lab, total in s.element_sums.items():
        s.say(f"SSUM: {lab} = {total:.6E}")


@command("ESORT", POST, 5)
def esort(s: SessionState, c: Call) -> None:
    """ESORT,ETAB,Lab,ORDER,KABS,NUMB: the selected elements sorted by element table column
    Lab (ORDER 0 descending, 1 ascending; KABS 1 sorts |value|), the first NUMB of them, for
    *GET,Par,SORT,,MAX|MIN|IMAX|IMIN and the order PRETAB lists them in; equal values keep
    the lower element number first."""
    if c.label(1, "ETAB") != "ETAB":
        raise ApdlError(f"field 1: ESORT sorts ETAB (the element table), got {c.label(1)!r}")
    lab = c.label(2)
    column = s.element_table.get(lab)
    if column is None:
        raise ApdlError(f"field 2: no element table column {lab or '(empty)'!r} (ETABLE)")
    elements = s.db.elements
    rows = np.nonzero(elements.selected[:column.size])[0]
    if rows.size == 0:
        raise ApdlError("no selected element to sort")
    rows, keys = sorted_rows(c, elements.ids, rows, column)
    s.last_sort = ("ESORT", elements.ids[rows].astype(float), keys.astype(float))
    s.element_order = rows


@command("EUSORT", POST, 0)
def eusort(s: SessionState, c: Call) -> None:
    """EUSORT: PRETAB lists the elements in number order again (*GET,,SORT keeps reading
    the last sort)."""
    s.element_order = None


@command("PRETAB", POST, 9)
def pretab(s: SessionState, c: Call) -> None:
    """PRETAB,Lab1,...,Lab9: the element table columns named (all blank: the first ten
    stored; GRP1..GRP5 in field 1: stored columns 1-10, 11-20, ...) for the selected
    elements, in ESORT's order when one holds (EUSORT: element-number order), as MAPDL
    lists them."""
    stored = list(s.element_table)
    names = [c.label(i) for i in range(1, 10) if c.label(i)]
    if not names:
        names = stored[:10]
    elif len(names) == 1 and names[0] in ("GRP1", "GRP2", "GRP3", "GRP4", "GRP5"):
        first = 10 * (int(names[0][3]) - 1)
        names = stored[first:first + 10]
    for name in names:
        if name not in s.element_table:
            raise ApdlError(f"no element table column {name!r} (ETABLE)")
    if not names:
        raise ApdlError("the element table is empty (ETABLE first)")
    elements = s.db.elements
    selected = elements.selected
    order = np.argsort(elements.ids, kind="stable")
    if s.element_order is not None:
        first = s.element_order[s.element_order < selected.size]
        order = np.concatenate([first, order[~np.isin(order, first)]])
    order = order[selected[order]]
    s.say("PRETAB element table")
    s.say("    ELEM " + "".join(f"{name:>16}" for name in names))
    for e in order:
        s.say(f"{int(elements.ids[e]):8d} " + "".join(
            f"{float(s.element_table[name][e]) if e < s.element_table[name].size else 0.0:16.6E}"
            for name in names))


@command("PRESOL", POST, 10)
def presol(s: SessionState, c: Call) -> None:
    """PRESOL: MAPDL's element-by-element solution printout is not produced here.  The first
    PRESOL of a run says so (a warning naming file:line: the listing a reader expects in the
    output is missing); later ones are ignored without a word."""
    if "PRESOL" in s.told:
        return
    s.told.add("PRESOL")
    message = ("the element solution printout is not produced here (ETABLE and "
               "PRETAB list element values); this and later PRESOL commands are ignored")
    if s.strict:
        raise c.statement.error(message + " (--strict)")
    s.warn(c.statement.error(message))


COMMANDS = (
    *specs_of(etable, ssum, esort, eusort, pretab, presol),
)
