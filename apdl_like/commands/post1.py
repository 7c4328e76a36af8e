"""/POST1: result sets and nodal listings."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import POST, Call, command, specs_of
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


COMMANDS = (
    *specs_of(set_, prnsol),
)
