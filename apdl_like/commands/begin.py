"""Begin-level and anywhere commands: processors, titles, *SET, *GET."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import ANY, Call, CommandSpec, Handler, command, ignored, specs_of
from apdl_like.commands.post1 import STRESS_COMPONENTS, sort_extreme
from apdl_like.commands.post26 import get_variable, variable_at
from apdl_like.errors import ApdlError
from apdl_like.expressions import ANGLE_UNIT, element_index
from apdl_like.params import numeric_array, split_target, start_subscripts, store, subscripts

if TYPE_CHECKING:
    from apdl_like.state import SessionState


def _enter(processor: str) -> Handler:
    def enter(s: SessionState, c: Call) -> None:
        if processor == "SOLU" and s.processor != "SOLU":
            s.solution.new_analysis = True  # unless ANTYPE,,REST says otherwise
        s.processor = processor

    return enter


@command("/COM", ANY, 1)
def com(s: SessionState, c: Call) -> None:
    s.say(" " + c.statement.fields[0])  # MAPDL prints comments one column in


@command("/TITLE", ANY, 1)
def title(s: SessionState, c: Call) -> None:
    s.db.title = c.raw(1)


# output controls that archives and MAPDL decks carry; they change nothing here
OUTPUT_CONTROLS = ("/NOPR", "/GOPR", "/NOLIST", "/GO", "/UNITS", "/BATCH", "/VERIFY",
                   "/NERR", "/SHOW", "/CONFIG", "/FILNAME", "/CLEAR", "/GRAPHICS", "/VIEW",
                   "/PNUM", "/NUMBER", "/REPLOT", "/ESHAPE", "/TYPE", "/WINDOW", "/DEVICE",
                   "/PLOPTS", "/TRIAD", "/AUTO", "/DIST", "/FOCUS", "/ANGLE", "/EDGE",
                   "/CONTOUR", "/DSCALE", "/ERASE", "/NOERASE", "/HEADER", "/PAGE", "/FORMAT",
                   "/RGB", "/COLOR", "/PSF", "/PBC", "/PSYMB", "/TRLCY", "/VSCALE", "/GFILE",
                   "/GST", "/GLINE", "/UIS", "/MENU", "/WAIT", "/OUTOPT", "/ZOOM", "/USER",
                   "EPLOT", "NPLOT", "KPLOT", "LPLOT", "APLOT", "GPLOT", "PLESOL",
                   "PLVECT", "PLDISP", "PLPATH", "PLVAR", "NLIST", "ELIST", "KLIST", "LLIST",
                   "ALIST", "DLIST", "SFLIST", "SFELIST", "BFLIST", "BFELIST", "CPLIST",
                   "MPLIST", "ETLIST", "RLIST", "CMLIST",
                   "PRERR", "ANTIME", "ANIM", "SMRTSIZE", "/PMACRO", "/MSTART", "PATH",
                   "PPATH", "PDEF", "PRPATH", "/CLABEL", "CMPL", "PRTIME")


@command("*GET", ANY, 8)
def star_get(s: SessionState, c: Call) -> None:
    """*GET,Par,NODE|ELEM,n,Item1,IT1NUM (TEMP, U X|Y, S X|Y|Z|XY|EQV, LOC X|Y, NUM MAX|MIN,
    COUNT ...), and *GET,Par,SORT,,MAX|MIN|IMAX|IMIN after NSORT.  Par may be an element of
    an array defined by *DIM (`*GET,TN(I),NODE,N,TEMP`), as in MAPDL."""
    try:
        name, subs = split_target(c.raw(1).strip())
    except ApdlError as exc:
        raise ApdlError(f"field 1: {exc}") from None
    value = _get_value(s, c)
    store(s.params, name, subscripts(subs, s.params, s.model_functions) if subs else [],
          [value])


def _get_value(s: SessionState, c: Call) -> float:
    """The value *GET reads (fields 2..5)."""
    entity = c.label(2)
    item, sub = c.label(4), c.label(5)
    db = s.db
    if entity == "VARI" and item == "RTIME":
        return variable_at(s, c.int(3, what="variable"), c.num(5, what="time"))
    if entity == "VARI":
        return get_variable(s, c.int(3, what="variable"), item, sub)
    if entity == "FSUM":
        if s.fsum_heat is None:
            raise ApdlError("FSUM has not been run")
        if item not in ("ITEM", "") or sub not in ("HEAT", ""):
            raise ApdlError("FSUM supports *GET,Par,FSUM,,ITEM,HEAT")
        return s.fsum_heat
    if entity == "SSUM":
        label = c.label(5)
        if item != "ITEM" or label not in s.element_sums:
            raise ApdlError(f"SSUM has no total {label!r} (ETABLE, then SSUM)")
        return s.element_sums[label]
    if entity == "RAD":
        if item != "VFAVG":
            raise ApdlError(f"field 4: RAD supports VFAVG, got {item or '(empty)'!r}")
        if s.radiation.average is None:
            raise ApdlError("VFQUERY has not been run")
        return s.radiation.average
    if entity == "PLNSOL":  # *GET,Par,PLNSOL,0,MAX|MIN of the last PLNSOL
        if s.plot_extremes is None:
            raise ApdlError("PLNSOL has not been run (*GET,,PLNSOL reads the last PLNSOL)")
        shown, extremes = s.plot_extremes
        if extremes is None:
            raise ApdlError(f"PLNSOL,{shown} is not supported for *GET,,PLNSOL (its items are "
                            "NSORT's: TEMP, U,X|Y|SUM, S,X|Y|Z|XY|EQV, LOC,X|Y)")
        if item not in ("MAX", "MIN"):
            raise ApdlError(f"field 4: PLNSOL takes MAX or MIN, got {item or '(empty)'!r}")
        return extremes[0] if item == "MAX" else extremes[1]
    if entity == "SORT":  # *GET,Par,SORT,,MAX|MIN|IMAX|IMIN of the last NSORT
        return sort_extreme(s, item)
    if entity == "ACTIVE":
        if item != "SET" or sub not in ("TIME", "LSTP"):
            raise ApdlError("ACTIVE supports *GET,Par,ACTIVE,0,SET,TIME|LSTP (the result set "
                            "SET read)")
        res = s.result()
        return float(res.time if sub == "TIME" else res.load_step)
    if entity not in ("NODE", "ELEM"):
        raise ApdlError(f"field 2: entity must be NODE, ELEM, ACTIVE, FSUM, SSUM, VARI, RAD, "
                        f"SORT or PLNSOL, got {entity or '(empty)'!r}")
    if item == "COUNT":  # MAPDL's spelling: *GET,Par,NODE,0,COUNT
        item, sub = "NUM", "COUNT"
    if item == "NUM":
        table = db.nodes if entity == "NODE" else db.elements
        ids = table.selected_ids()
        if sub == "COUNT":
            value = float(ids.size)
        elif sub in ("MAX", "MIN"):
            value = float(ids.max() if sub == "MAX" else ids.min()) if ids.size else 0.0
        else:
            raise ApdlError(f"field 5: NUM takes MAX, MIN or COUNT, got {sub or '(empty)'!r}")
    elif entity == "ELEM" and item == "ETAB":  # *GET,Par,ELEM,n,ETAB,Lab
        column = s.element_table.get(sub)
        if column is None:
            raise ApdlError(f"field 5: no element table column {sub or '(empty)'!r} (ETABLE)")
        i = int(db.elements.index(c.int(3, what="element number"))[0])
        if i < 0:
            raise ApdlError(f"element {c.raw(3)} does not exist")
        value = float(column[i])
    elif entity == "ELEM":
        raise ApdlError(f"field 4: ELEM supports NUM and ETAB, got {item or '(empty)'!r}")
    else:
        value = node_item(s, c.int(3, what="node number"), item, sub)
    if not np.isfinite(value):
        raise ApdlError("the requested value is not a finite number")
    return float(value)


def node_item(s: SessionState, n: int, item: str, sub: str) -> float:
    """*GET's and *VGET's NODE items of node n: TEMP, U X|Y, S X|Y|Z|XY|EQV, LOC X|Y|Z."""
    if item == "TEMP":
        return s.nodal_result("TEMP", n)
    if item == "U":
        if sub not in ("X", "Y"):
            raise ApdlError(f"field 5: U takes X or Y, got {sub or '(empty)'!r}")
        return s.nodal_result("U" + sub, n)
    if item == "S":
        if sub not in STRESS_COMPONENTS:
            raise ApdlError(f"field 5: S takes X, Y, Z, XY or EQV, got {sub or '(empty)'!r}")
        return s.nodal_result(STRESS_COMPONENTS[sub], n)
    if item == "LOC":
        if sub not in ("X", "Y", "Z"):
            raise ApdlError(f"field 5: LOC takes X, Y or Z, got {sub or '(empty)'!r}")
        return 0.0 if sub == "Z" else float(s.node_location(n)["XY".index(sub)])
    raise ApdlError(f"field 4: NODE item must be TEMP, U, S, LOC or NUM, got "
                    f"{item or '(empty)'!r}")


@command("*VGET", ANY, 8)
def star_vget(s: SessionState, c: Call) -> None:
    """*VGET,ParR(i),NODE,N,Item,Comp: the item of nodes N, N+1, N+2, ... down the column of
    ParR from row i to its end, one node number a row (*GET's NODE items: TEMP, U, S, LOC;
    NSEL: 1 selected, -1 unselected); a node number that does not exist gives 0, as in MAPDL.
    *VGET,ParR(i),ELEM,E,ETAB,Lab does the same for element table columns.  KLOOP (field 8)
    and *VLEN/*VMASK are not supported."""
    if c.given(8):
        raise ApdlError("field 8 (KLOOP) is not supported: the loop runs on the entity number")
    try:
        name, subs_text = split_target(c.raw(1).strip())
    except ApdlError as exc:
        raise ApdlError(f"field 1: {exc}") from None
    array = numeric_array(s.params, name, 1)
    subs = start_subscripts(subs_text, s.params, s.model_functions)
    rows = array.shape[0] - element_index(name, array, subs)[0]
    entity, item, sub = c.label(2), c.label(4), c.label(5)
    first = c.int(3, 1, what="ENTNUM")
    numbers = range(first, first + rows)
    values = []
    if entity == "NODE":
        nodes = s.db.nodes
        for n in numbers:
            i = int(nodes.index(n)[0])
            if i < 0:
                values.append(0.0)
            elif item == "NSEL":
                values.append(1.0 if nodes.selected[i] else -1.0)
            else:
                values.append(node_item(s, n, item, sub))
    elif entity == "ELEM" and item == "ETAB":
        column = s.element_table.get(sub)
        if column is None:
            raise ApdlError(f"field 5: no element table column {sub or '(empty)'!r} (ETABLE)")
        idx = s.db.elements.index(np.array(list(numbers)))
        values = [float(column[i]) if i >= 0 else 0.0 for i in idx]
    else:
        raise ApdlError(f"field 2: *VGET supports NODE (TEMP, U, S, LOC, NSEL) and ELEM,,ETAB, "
                        f"got {','.join(f for f in (entity, item) if f) or '(empty)'!r}")
    if not all(np.isfinite(values)):
        raise ApdlError("a requested value is not a finite number")
    store(s.params, name, subs, [float(v) for v in values])


@command("*AFUN", ANY, 1)
def star_afun(s: SessionState, c: Call) -> None:
    """*AFUN,RAD|DEG|STAT: the unit of angles in SIN, COS, TAN and of ASIN, ACOS, ATAN,
    ATAN2 in parameter expressions (radians by default, as in MAPDL)."""
    lab = c.label(1, "RAD")
    if lab == "DEG":
        s.model_functions[ANGLE_UNIT] = _radians_per_degree
    elif lab == "RAD":
        s.model_functions.pop(ANGLE_UNIT, None)
    elif lab == "STAT":
        unit = "DEG" if ANGLE_UNIT in s.model_functions else "RAD"
        s.say(f"*AFUN: angles in parameter functions are in {unit}")
    else:
        raise ApdlError(f"field 1 must be RAD, DEG or STAT, got {c.raw(1)!r}")


def _radians_per_degree() -> float:
    return math.pi / 180.0


COMMANDS = (
    *specs_of(com, title, star_get, star_vget, star_afun),
    *(CommandSpec(name, ANY, 0, _enter(processor)) for name, processor in (
        ("/PREP7", "PREP7"), ("/SOLU", "SOLU"), ("/POST1", "POST1"), ("/POST26", "POST26"),
        ("/AUX12", "AUX12"), ("FINISH", "BEGIN"))),
    CommandSpec("/STITLE", ANY, 1, ignored),
    *(CommandSpec(name, ANY, 10, ignored) for name in OUTPUT_CONTROLS),
)
