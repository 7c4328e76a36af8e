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

An element without the item gets 0, as in MAPDL's table.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import POST, Call, command, specs_of
from apdl_like.commands.post26 import plane_solution
from apdl_like.errors import ApdlError
from apdl_like.model import pair_keys

if TYPE_CHECKING:
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
    if item != "SMISC":
        raise ApdlError(f"field 2: ETABLE supports SMISC, TG and TF, got {item or '(empty)'!r}")
    comp = c.int(3, what="Comp")
    if comp not in (1, 2, 3):
        raise ApdlError("field 3: SMISC supports 1 (a link's HEAT RATE), 2 and 3 (a bar's "
                        "TI, TJ; 2: a SURF151's convection heat rate)")
    values = _smisc(s, comp)
    selected = s.db.elements.selected
    if not np.any(selected & ~np.isnan(values)):
        s.say(f"ETABLE: no selected element has SMISC,{comp}; {lab} is 0")
    s.element_table[lab] = np.where(selected, np.nan_to_num(values), 0.0)


@command("SSUM", POST, 0)
def ssum(s: SessionState, c: Call) -> None:
    """SSUM: each element table column summed over the selected elements."""
    selected = s.db.elements.selected
    s.element_sums = {lab: float(v[selected].sum()) for lab, v in s.element_table.items()
                      if v.size == selected.size}
    for lab, total in s.element_sums.items():
        s.say(f"SSUM: {lab} = {total:.6E}")


COMMANDS = (
    *specs_of(etable, ssum),
)
