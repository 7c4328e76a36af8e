"""/POST1: result sets, nodal listings and nodal sorts."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import ANY, POST, Call, command, specs_of
from apdl_like.commands.post26 import thermal_history
from apdl_like.errors import ApdlError
from apdl_like.state import StepResult

if TYPE_CHECKING:
    from apdl_like.state import SessionState


@command("SET", POST, 5)
def set_(s: SessionState, c: Call) -> None:
    if not s.solution.results:
        raise ApdlError("there are no results (SOLVE first)")
    results = s.solution.results
    kind = results[-1].analysis  # the results file of the last analysis
    steps = [i for i, r in enumerate(results) if r.analysis == kind]
    s.solution.post_result = None
    if c.given(5) and not c.given(1):
        s.solution.post_result = _at_time(s, c.num(5, what="TIME"))
        return
    what = c.label(1, "LAST")
    if what in ("LAST", ""):
        s.solution.post_index = steps[-1]
    elif what == "FIRST":
        s.solution.post_index = steps[0]
    else:
        step = c.int(1, what="LSTEP")
        match = [i for i in steps if results[i].load_step == step]
        if not match:
            raise ApdlError(f"load step {step} does not exist (1..{len(steps)})")
        s.solution.post_index = match[0]


def _at_time(s: SessionState, time_s: float) -> StepResult:
    """SET,,,,,TIME: the thermal result at a time, linearly interpolated between the two
    stored times around it (MAPDL's rule), the first or last beyond them."""
    mesh = s.fem.plane
    if mesh is None:
        raise ApdlError("SET by TIME reads the thermal results of a deck's own mesh")
    times, temps = thermal_history(s)
    k = int(np.searchsorted(times, time_s))
    if k == 0 or k == times.size:
        T = temps[min(k, times.size - 1)]
    else:
        w = (time_s - times[k - 1]) / (times[k] - times[k - 1])
        T = (1.0 - w) * temps[k - 1] + w * temps[k]
    step = next(r.load_step for r in s.solution.results
                if r.analysis == "thermal" and r.time >= min(time_s, times[-1]))
    return StepResult(step, time_s, "thermal", T, nodal_temperature=mesh.nodal(T))


STRESS_COMPONENTS = {"X": "SX", "Y": "SY", "Z": "SZ", "XY": "SXY", "EQV": "SEQV"}  # S,Comp
_ITEMS = {
    ("TEMP", ""): ["TEMP"],
    ("U", "X"): ["UX"], ("U", "Y"): ["UY"], ("U", "COMP"): ["UX", "UY"], ("U", ""): ["UX", "UY"],
    ("S", "COMP"): ["SX", "SY", "SZ", "SXY"], ("S", ""): ["SX", "SY", "SZ", "SXY"],
    ("S", "X"): ["SX"], ("S", "Y"): ["SY"], ("S", "Z"): ["SZ"], ("S", "XY"): ["SXY"],
    ("S", "EQV"): ["SEQV"], ("S", "PRIN"): ["SEQV"],
}


@command("PRNSOL", POST, 2)
def prnsol(s: SessionState, c: Call) -> None:
    key = (c.label(1, "TEMP"), c.label(2))
    items = _ITEMS.get(key)
    if items is None:
        raise ApdlError(f"PRNSOL supports TEMP, U,X|Y|COMP and S,X|Y|Z|XY|COMP|EQV, got "
                        f"{','.join(k for k in key if k)!r}")
    res = s.result()
    nodes = s.db.nodes
    sel = np.nonzero(nodes.selected)[0]
    columns = []
    for item in items:
        if item == "TEMP":
            columns.append(res.nodal_temperature[sel])
        elif not res.nodal_structural:
            raise ApdlError(f"{item} needs a structural result (the current one is thermal)")
        else:
            columns.append(res.nodal_structural[item][sel])
    s.say(f"PRNSOL load step {res.load_step}, time {res.time:g}")
    s.say("    NODE " + "".join(f"{item:>16}" for item in items))
    for j, i in enumerate(sel):
        values = [col[j] for col in columns]
        if all(np.isnan(v) for v in values):
            continue
        s.say(f"{int(nodes.ids[i]):8d} " + "".join(f"{v:16.6E}" for v in values))


def _nodal_values(s: SessionState, item: str, comp: str) -> np.ndarray:
    """NSORT's item at every node (NaN where a node has none): TEMP, U X|Y|SUM,
    S X|Y|Z|XY|EQV from the current result set, LOC X|Y in the active system."""
    if item == "LOC" and comp in ("X", "Y"):
        return np.asarray(s.db.active_system.from_global(s.db.nodes.xy))[:, "XY".index(comp)]
    res = s.result()
    if item == "TEMP" and comp == "":
        return res.nodal_temperature
    if item == "U" and comp in ("X", "Y", "SUM") or item == "S" and comp in STRESS_COMPONENTS:
        if not res.nodal_structural:
            raise ApdlError(f"{item},{comp} needs a structural result (the current one is "
                            "thermal)")
        ux, uy = res.nodal_structural["UX"], res.nodal_structural["UY"]
        if item == "U":
            return {"X": ux, "Y": uy, "SUM": np.hypot(ux, uy)}[comp]
        return res.nodal_structural[STRESS_COMPONENTS[comp]]
    raise ApdlError(f"NSORT supports TEMP, U,X|Y|SUM, S,X|Y|Z|XY|EQV and LOC,X|Y, got "
                    f"{','.join(k for k in (item, comp) if k) or '(empty)'!r}")


@command("PLNSOL", ANY, 5)
def plnsol(s: SessionState, c: Call) -> None:
    """PLNSOL,Item,Comp: no plot is drawn; in /POST1 the largest and smallest value over the
    selected nodes are kept for *GET,Par,PLNSOL,0,MAX|MIN, as MAPDL keeps them from its plot
    (NSORT's items; another item is accepted, as a plot command, and *GET then says it has
    none).  Elsewhere it is ignored, as before (a plot command)."""
    if s.processor != "POST1":
        return
    item, comp = c.label(1, "TEMP"), c.label(2)
    name = ",".join(k for k in (item, comp) if k)
    s.result()  # no results: said as such, not as an item PLNSOL cannot give
    try:
        values = _nodal_values(s, item, comp)
    except ApdlError:
        s.plot_extremes = (name, None)
        return
    nodes = s.db.nodes
    shown = values[nodes.selected & np.isfinite(values)]
    if shown.size == 0:
        raise ApdlError("no selected node has the item to plot")
    s.plot_extremes = (name, (float(shown.max()), float(shown.min())))


@command("NSORT", POST, 6)
def nsort(s: SessionState, c: Call) -> None:
    """NSORT,Item,Comp,ORDER,KABS,NUMB,SEL: the selected nodes sorted by a nodal value
    (ORDER 0 descending, 1 ascending; KABS 1 sorts |value|), for *GET,,SORT and, with
    SEL = SELECT, reselecting the first NUMB nodes of the sort."""
    nodes = s.db.nodes
    selected = nodes.selected  # first: it merges the nodes just added into the arrays
    values = _nodal_values(s, c.label(1), c.label(2))
    rows = np.nonzero(selected & np.isfinite(values))[0]
    if rows.size == 0:
        raise ApdlError("no selected node has the item to sort")
    rows, keys = sorted_rows(c, nodes.ids, rows, values)
    s.last_sort = ("NSORT", nodes.ids[rows].astype(float), keys.astype(float))
    selection = c.label(6)
    if selection == "SELECT":
        mask = np.zeros_like(nodes.selected)
        mask[rows] = True
        nodes.selected = mask
    elif selection:
        raise ApdlError(f"field 6 (SEL) must be SELECT or blank, got {selection!r}")


def sorted_rows(c: Call, ids: np.ndarray, rows: np.ndarray, values: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """NSORT's and ESORT's sort of `rows` (indices into `ids` and `values`) by fields 3..5:
    ORDER (0 descending, 1 ascending), KABS (1: by |value|), NUMB (the first NUMB kept);
    equal keys keep the lower number first.  The rows and their keys, in sorted order."""
    order = c.int_in(3, 0, 1, 0, "ORDER")
    by_abs = c.int_in(4, 0, 1, 0, "KABS")
    rows = rows[np.argsort(ids[rows], kind="stable")]
    keys = np.abs(values[rows]) if by_abs else values[rows]
    ranked = np.argsort(keys if order else -keys, kind="stable")
    count = c.int_in(5, 1, rows.size, rows.size, "NUMB") if c.given(5) else rows.size
    return rows[ranked][:count], keys[ranked][:count]


@command("NUSORT", POST, 0)
def nusort(s: SessionState, c: Call) -> None:
    """NUSORT: the nodes back in node-number order.  Listings here are always in that
    order, and *GET,,SORT keeps reading the last sort, as MAPDL's "last sort" does."""


def sort_extreme(s: SessionState, item: str) -> float:
    """*GET,Par,SORT,,MAX|MIN|IMAX|IMIN: the largest or smallest sort key of the last
    NSORT or ESORT (|value| with KABS = 1), or the node or element holding it (the lower
    number on a tie)."""
    if s.last_sort is None:
        raise ApdlError("no NSORT or ESORT has been run (*GET,,SORT reads the last sort)")
    _, ids, keys = s.last_sort
    if item not in ("MAX", "MIN", "IMAX", "IMIN"):
        raise ApdlError(f"field 4: SORT supports MAX, MIN, IMAX and IMIN, got "
                        f"{item or '(empty)'!r}")
    extreme = keys.max() if item.endswith("MAX") else keys.min()
    if not item.startswith("I"):
        return float(extreme)
    return float(ids[keys == extreme].min())


COMMANDS = (
    *specs_of(set_, prnsol, plnsol, nsort, nusort),
)
