"""Begin-level and anywhere commands: processors, titles, *SET, *GET."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import ANY, Call, CommandSpec, Handler, command, ignored, specs_of
from apdl_like.commands.post1 import STRESS_COMPONENTS, sort_extreme
from apdl_like.commands.post26 import get_variable, variable_at
from apdl_like.errors import ApdlError
from apdl_like.expressions import is_parameter_name

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
                   "EPLOT", "NPLOT", "KPLOT", "LPLOT", "APLOT", "GPLOT", "PLNSOL", "PLESOL",
                   "PLVECT", "PLDISP", "PLPATH", "PLVAR", "NLIST", "ELIST", "KLIST", "LLIST",
                   "ALIST", "DLIST", "SFLIST", "SFELIST", "BFLIST", "BFELIST", "CPLIST",
                   "MPLIST", "ETLIST", "RLIST", "CMLIST", "PRETAB", "PRESOL", "PRRSOL",
                   "PRERR", "ANTIME", "ANIM", "SMRTSIZE", "/PMACRO", "/MSTART", "PATH",
                   "PPATH", "PDEF", "PRPATH", "/CLABEL", "CMPL", "PRTIME")


@command("*GET", ANY, 8)
def star_get(s: SessionState, c: Call) -> None:
    """*GET,Par,NODE|ELEM,n,Item1,IT1NUM (TEMP, U X|Y, S X|Y|Z|XY|EQV, LOC X|Y, NUM MAX|MIN,
    COUNT ...), and *GET,Par,SORT,,MAX|MIN|IMAX|IMIN after NSORT."""
    name = c.raw(1).upper()
    if not is_parameter_name(name):
        raise ApdlError(f"field 1: {c.raw(1)!r} is not a valid parameter name")
    entity = c.label(2)
    item, sub = c.label(4), c.label(5)
    db = s.db
    if entity == "VARI" and item == "RTIME":
        s.params[name] = variable_at(s, c.int(3, what="variable"), c.num(5, what="time"))
        return
    if entity == "VARI":
        s.params[name] = get_variable(s, c.int(3, what="variable"), item, sub)
        return
    if entity == "FSUM":
        if s.fsum_heat is None:
            raise ApdlError("FSUM has not been run")
        if item not in ("ITEM", "") or sub not in ("HEAT", ""):
            raise ApdlError("FSUM supports *GET,Par,FSUM,,ITEM,HEAT")
        s.params[name] = s.fsum_heat
        return
    if entity == "SSUM":
        label = c.label(5)
        if item != "ITEM" or label not in s.element_sums:
            raise ApdlError(f"SSUM has no total {label!r} (ETABLE, then SSUM)")
        s.params[name] = s.element_sums[label]
        return
    if entity == "RAD":
        if item != "VFAVG":
            raise ApdlError(f"field 4: RAD supports VFAVG, got {item or '(empty)'!r}")
        if s.radiation.average is None:
            raise ApdlError("VFQUERY has not been run")
        s.params[name] = s.radiation.average
        return
    if entity == "SORT":  # *GET,Par,SORT,,MAX|MIN|IMAX|IMIN of the last NSORT
        s.params[name] = sort_extreme(s, item)
        return
    if entity == "ACTIVE":
        if item != "SET" or sub not in ("TIME", "LSTP"):
            raise ApdlError("ACTIVE supports *GET,Par,ACTIVE,0,SET,TIME|LSTP (the result set "
                            "SET read)")
        res = s.result()
        s.params[name] = float(res.time if sub == "TIME" else res.load_step)
        return
    if entity not in ("NODE", "ELEM"):
        raise ApdlError(f"field 2: entity must be NODE, ELEM, ACTIVE, FSUM, SSUM, VARI, RAD or "
                        f"SORT, got {entity or '(empty)'!r}")
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
        n = c.int(3, what="node number")
        if item == "TEMP":
            value = s.nodal_result("TEMP", n)
        elif item == "U":
            if sub not in ("X", "Y"):
                raise ApdlError(f"field 5: U takes X or Y, got {sub or '(empty)'!r}")
            value = s.nodal_result("U" + sub, n)
        elif item == "S":
            if sub not in STRESS_COMPONENTS:
                raise ApdlError(f"field 5: S takes X, Y, Z, XY or EQV, got {sub or '(empty)'!r}")
            value = s.nodal_result(STRESS_COMPONENTS[sub], n)
        elif item == "LOC":
            if sub not in ("X", "Y", "Z"):
                raise ApdlError(f"field 5: LOC takes X, Y or Z, got {sub or '(empty)'!r}")
            value = 0.0 if sub == "Z" else float(s.node_location(n)["XY".index(sub)])
        else:
            raise ApdlError(f"field 4: NODE item must be TEMP, U, S, LOC or NUM, got "
                            f"{item or '(empty)'!r}")
    if not np.isfinite(value):
        raise ApdlError("the requested value is not a finite number")
    s.params[name] = float(value)


COMMANDS = (
    *specs_of(com, title, star_get),
    *(CommandSpec(name, ANY, 0, _enter(processor)) for name, processor in (
        ("/PREP7", "PREP7"), ("/SOLU", "SOLU"), ("/POST1", "POST1"), ("/POST26", "POST26"),
        ("/AUX12", "AUX12"), ("FINISH", "BEGIN"))),
    CommandSpec("/STITLE", ANY, 1, ignored),
    *(CommandSpec(name, ANY, 10, ignored) for name in OUTPUT_CONTROLS),
)
