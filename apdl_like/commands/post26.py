"""/POST26 time-history variables (NSOL, ESOL, STORE, PRVAR, *GET,,VARI) and reaction heat
in /POST1 (PRNLD, PRRSOL, FSUM).

A variable is a nodal temperature (NSOL,,,TEMP) or an element's nodal heat flow
(ESOL,,,,HEAT) at every stored time of the last thermal analysis: the substeps of its last
load step and the end of each earlier one.  Variable 1 is TIME.  Element heat flows and
reactions come from the deck-mesh solver (apdl_like.plane_thermal), steady conduction:
element matrices times the temperatures less the element's loads.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import POST, POST26, Call, CommandSpec, command, ignored, specs_of
from apdl_like.errors import ApdlError
from apdl_like.expressions import element_index
from apdl_like.params import numeric_array, split_target, start_subscripts, store

if TYPE_CHECKING:
    from apdl_like.plane_thermal import PlaneThermal, ThermalInputs
    from apdl_like.state import SessionState

MAX_VARIABLE = 200


def thermal_history(s: SessionState) -> tuple[np.ndarray, list[np.ndarray]]:
    """(times, thermal dof vectors) of the stored results of the last thermal analysis."""
    sol = s.solution
    thermal = [r for r in sol.results if r.analysis == "thermal"]
    if not thermal:
        raise ApdlError("there is no thermal result (SOLVE a thermal analysis first)")
    last = thermal[-1]
    if sol.history_times and sol.history_times[-1] == last.time and \
            sol.history_times[0] <= thermal[0].time:
        return np.array(sol.history_times), list(sol.history_temperatures)
    times, temps = [], []
    for r in thermal[:-1]:
        times.append(r.time)
        temps.append(r.temperature)
    if sol.substep_temperatures and sol.substep_times and sol.substep_times[-1] == last.time:
        times += list(sol.substep_times)
        temps += list(sol.substep_temperatures)
    else:
        times.append(last.time)
        temps.append(last.temperature)
    return np.array(times), temps


def plane_solution(s: SessionState) -> tuple[PlaneThermal, ThermalInputs]:
    solver = s.fem.plane_solver
    if solver is None or s.fem.plane_inputs is None:
        raise ApdlError("element heat flows need a thermal solution of the deck's own mesh")
    return solver[1], s.fem.plane_inputs


def _variable(c: Call) -> int:
    n = c.int(1, what="NVAR")
    if not 2 <= n <= MAX_VARIABLE:
        raise ApdlError(f"field 1 (NVAR) must lie in 2..{MAX_VARIABLE} (1 is TIME)")
    return n


@command("NSOL", POST26, 7)
def nsol(s: SessionState, c: Call) -> None:
    """NSOL,NVAR,NODE,TEMP,,Name."""
    nvar = _variable(c)
    i = s.node_index(c.int(2, what="NODE"))
    if c.label(3, "TEMP") != "TEMP":
        raise ApdlError(f"field 3: NSOL supports TEMP, got {c.label(3)!r}")
    times, temps = thermal_history(s)
    model, _ = plane_solution(s)
    dof = model.mesh.node_dof[i]
    if dof < 0:
        raise ApdlError(f"node {c.raw(2)} is not attached to an element")
    s.variables[nvar] = (c.label(5, "TEMP"), times, np.array([T[dof] for T in temps]))


@command("ESOL", POST26, 7)
def esol(s: SessionState, c: Call) -> None:
    """ESOL,NVAR,ELEM,NODE,HEAT,,Name: the element's heat flow at one of its nodes
    (positive out of the element into the node, as FSUM counts it);
    ESOL,NVAR,ELEM,,SMISC,1,Name: a thermal link's HEAT RATE (LINK31..34)."""
    nvar = _variable(c)
    el = s.db.elements
    e = int(el.index(c.int(2, what="ELEM"))[0])
    if e < 0:
        raise ApdlError(f"element {c.raw(2)} does not exist")
    if c.label(4) == "SMISC":
        _link_heat_rate(s, c, nvar, e)
        return
    node = c.int(3, what="NODE")
    if node not in el.nodes[e]:
        raise ApdlError(f"node {node} is not a node of element {c.raw(2)}")
    if c.label(4) != "HEAT":
        raise ApdlError(f"field 4: ESOL supports HEAT, got {c.label(4) or '(empty)'!r}")
    model, inputs = plane_solution(s)
    dof = model.mesh.node_dof[s.node_index(node)]
    times, temps = thermal_history(s)
    # MAPDL's element nodal heat flow, the record FSUM adds up, is positive where heat
    # leaves the element at the node: minus (element matrix × T − element loads).  VM99
    # negates its FSUM at the heated wall to print a positive heat; VM92-94 print the
    # positive heat a link delivers at its cold node J.
    values = np.array([-model.element_heat(inputs, T, e)[dof] for T in temps])
    s.variables[nvar] = (c.label(6, "HEAT"), times, values)


def _link_heat_rate(s: SessionState, c: Call, nvar: int, e: int) -> None:
    if c.int(5, what="component") != 1:
        raise ApdlError("field 5: SMISC supports component 1 (a link's HEAT RATE)")
    model, inputs = plane_solution(s)
    links = model.links
    where = None if links is None else np.nonzero(links.elements == e)[0]
    if where is None or not where.size or links.kind[where[0]] == "mass":
        raise ApdlError(f"element {c.raw(2)}: SMISC,1 is the HEAT RATE of a LINK31..34 "
                        "element")
    times, temps = thermal_history(s)
    k = int(where[0])
    values = np.array([links.heat_rate(T, inputs.kxx, inputs.hf or [])[k] for T in temps])
    s.variables[nvar] = (c.label(6, "SMIS1"), times, values)


@command("INT1", POST26, 10)
def int1(s: SessionState, c: Call) -> None:
    """INT1,IR,IY,IX,,Name,,,FACTA,FACTB,CONST: IR = ∫ FACTA·IY d(FACTB·IX) + CONST over
    the stored points (trapezoidal rule; IX 1 is TIME)."""
    nvar = _variable(c)
    y_name, x_name = c.int(2, what="IY"), c.int(3, 1, what="IX")
    factor_y, factor_x = c.num(8, 1.0, what="FACTA"), c.num(9, 1.0, what="FACTB")
    const = c.num(10, 0.0, what="CONST")
    if y_name not in s.variables:
        raise ApdlError(f"variable {y_name} is not defined (NSOL or ESOL first)")
    _, times, y = s.variables[y_name]
    if x_name == 1:
        x = times
    elif x_name in s.variables:
        x = s.variables[x_name][2]
    else:
        raise ApdlError(f"variable {x_name} is not defined (NSOL or ESOL first)")
    fy, fx = factor_y * np.asarray(y), factor_x * np.asarray(x)
    steps = 0.5 * (fy[1:] + fy[:-1]) * np.diff(fx)
    s.variables[nvar] = (c.label(5, "INT1"), times,
                         const + np.concatenate([[0.0], np.cumsum(steps)]))


def variable_at(s: SessionState, n: int, time: float) -> float:
    """*GET,Par,VARI,n,RTIME,time: the variable at a time, linear between stored points."""
    if n not in s.variables:
        raise ApdlError(f"variable {n} is not defined (NSOL or ESOL first)")
    _, times, values = s.variables[n]
    if not times[0] - 1e-9 * abs(times[-1]) <= time <= times[-1] * (1 + 1e-9):
        raise ApdlError(f"time {time:g} lies outside the stored results "
                        f"({times[0]:g} .. {times[-1]:g})")
    return float(np.interp(time, times, values))


@command("PRVAR", POST26, 6)
def prvar(s: SessionState, c: Call) -> None:
    """PRVAR,NV1,...,NV6: the variables against TIME."""
    chosen = [c.int(i, what="NVAR") for i in range(1, c.count() + 1) if c.given(i)]
    for n in chosen:
        if n not in s.variables:
            raise ApdlError(f"variable {n} is not defined (NSOL or ESOL first)")
    if not chosen:
        return
    times = s.variables[chosen[0]][1]
    s.say("        TIME" + "".join(f"{s.variables[n][0]:>16}" for n in chosen))
    for k, t in enumerate(times):
        s.say(f"{t:12.5G}" + "".join(f"{s.variables[n][2][k]:16.6E}" for n in chosen))


@command("VGET", POST26, 4)
def vget(s: SessionState, c: Call) -> None:
    """VGET,Par(i),IR,TSTRT: variable IR (1: TIME) from its first stored time at or after
    TSTRT (default the first), down the column of the *DIM array Par from row i, until the
    variable or the column ends."""
    if c.given(4):
        raise ApdlError("field 4 (KCPLX) is not supported: variables here are real")
    name, subs_text = split_target(c.raw(1).strip())
    array = numeric_array(s.params, name, 1)
    n = c.int(2, what="IR")
    if n == 1:
        times = thermal_history(s)[0]
        values = times
    elif n in s.variables:
        _, times, values = s.variables[n]
    else:
        raise ApdlError(f"variable {n} is not defined (NSOL or ESOL first)")
    start = int(np.searchsorted(times, c.num(3, float(times[0]), what="TSTRT") -
                                1e-9 * max(abs(float(times[-1])), 1.0)))
    subs = start_subscripts(subs_text, s.params, s.model_functions)
    rows = array.shape[0] - element_index(name, array, subs)[0]
    store(s.params, name, subs, [float(v) for v in values[start:start + rows]])


def get_variable(s: SessionState, n: int, what: str, sub: str) -> float:
    """*GET,Par,VARI,n,EXTREM,VMAX|VMIN|TMAX|TMIN|VLAST."""
    if n not in s.variables:
        raise ApdlError(f"variable {n} is not defined (NSOL or ESOL first)")
    _, times, values = s.variables[n]
    if what != "EXTREM":
        raise ApdlError(f"field 4: VARI supports EXTREM, got {what or '(empty)'!r}")
    k_max, k_min = int(np.argmax(values)), int(np.argmin(values))
    table = {"VMAX": values[k_max], "VMIN": values[k_min], "TMAX": times[k_max],
             "TMIN": times[k_min], "VLAST": values[-1], "TLAST": times[-1]}
    if sub not in table:
        raise ApdlError(f"field 5: EXTREM takes VMAX, VMIN, TMAX, TMIN, VLAST or TLAST, "
                        f"got {sub!r}")
    return float(table[sub])


def reactions(s: SessionState) -> tuple[np.ndarray, np.ndarray]:
    """(node indices with a fixed temperature, their reaction heat flow, W) of the result
    shown in /POST1 (steady conduction with the last solve's loads)."""
    model, inputs = plane_solution(s)
    res = s.result()
    if res.analysis != "thermal":
        raise ApdlError("reaction heats need a thermal result")
    r = model.reaction(inputs, res.temperature)
    fixed = np.nonzero(~np.isnan(s.db.nodes.arrays["d_temp"]) & (model.mesh.node_dof >= 0))[0]
    return fixed, r[model.mesh.node_dof[fixed]]


@command("PRNLD", POST, 6)
def prnld(s: SessionState, c: Call) -> None:
    """PRNLD,HEAT: reaction heat at the selected nodes with a fixed temperature."""
    if c.label(1, "HEAT") not in ("HEAT", "ALL"):
        raise ApdlError(f"field 1: PRNLD supports HEAT, got {c.label(1)!r}")
    _print_reactions(s)


@command("PRRSOL", POST, 1)
def prrsol(s: SessionState, c: Call) -> None:
    """PRRSOL,HEAT (or blank in a thermal analysis): the reaction heat flow at each selected
    node with a fixed temperature and their total, positive into the model (the heat the
    constraint supplies, K·T less the applied loads, as PRNLD prints it here)."""
    if c.label(1, "HEAT") != "HEAT":
        raise ApdlError(f"field 1: PRRSOL supports HEAT (the reaction heat flow of a thermal "
                        f"result), got {c.label(1)!r}")
    _print_reactions(s)


def _print_reactions(s: SessionState) -> None:
    nodes, heat = reactions(s)
    selected = s.db.nodes.selected[nodes]
    s.say("    NODE            HEAT")
    for i, q in zip(nodes[selected], heat[selected], strict=True):
        s.say(f"{int(s.db.nodes.ids[i]):8d} {q:16.6E}")
    s.say(f"   TOTAL {float(heat[selected].sum()):16.6E}")


@command("FSUM", POST, 2)
def fsum(s: SessionState, c: Call) -> None:
    """FSUM: the heat flow of the selected elements summed at the selected nodes
    (*GET,Par,FSUM,,ITEM,HEAT).  MAPDL sums the element nodal heat flows, counted positive
    into the model: a film that heats the model adds, a fixed temperature that takes heat
    out adds; over all elements and nodes it is minus the total reaction heat.  Selected
    SURF151 elements add nothing of their own: their films are in the solid's heat."""
    model, inputs = plane_solution(s)
    res = s.result()
    if res.analysis != "thermal":
        raise ApdlError("FSUM sums heat flows of a thermal result")
    db = s.db
    surface = np.array([db.element_types[int(t)].physics == "surface"
                        for t in db.elements.type], bool)
    chosen = db.elements.selected
    if np.any(chosen & surface) and not np.any(chosen & ~surface):
        raise ApdlError("FSUM of SURF151 elements alone: their film heat is summed by "
                        "ETABLE,Lab,SMISC,2 and SSUM")
    # a SURF151 film is counted with the solid face it lies on (its element heat holds it)
    elements = np.nonzero(chosen & ~surface)[0]
    heat = -model.element_heat(inputs, res.temperature, elements) if elements.size else \
        np.zeros(model.mesh.n_dofs)
    dofs = model.mesh.node_dof[s.db.nodes.selected]
    total = float(heat[np.unique(dofs[dofs >= 0])].sum())
    s.fsum_heat = total
    s.say(f"FSUM: HEAT = {total:.6E}")


COMMANDS = (
    *specs_of(nsol, esol, int1, prvar, vget, prnld, prrsol, fsum),
    CommandSpec("STORE", POST26, 2, ignored),  # variables are computed when defined
)
