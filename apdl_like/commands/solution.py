"""/SOLU: analysis type, time stepping, LDREAD and SOLVE."""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import LOADS, SOLU, Call, CommandSpec, command, ignored, specs_of
from apdl_like.errors import ApdlError
from apdl_like.solve import solve_structural, solve_thermal

if TYPE_CHECKING:
    from apdl_like.state import SessionState


# load-step options (ANTYPE to TINTP): MAPDL accepts them in /PREP7 too
@command("ANTYPE", LOADS, 4)
def antype(s: SessionState, c: Call) -> None:
    kind = c.label(1)
    status = c.label(2, "NEW")
    aliases = {"0": "STATIC", "STATIC": "STATIC", "4": "TRANS", "TRANS": "TRANS",
               "TRANSIENT": "TRANS", "": ""}
    if kind not in aliases:
        raise ApdlError(f"field 1: analysis type must be STATIC or TRANS, got {kind!r}")
    if status not in ("NEW", "REST", "RESTART"):
        raise ApdlError(f"field 2: status must be NEW or REST, got {status!r}")
    settings = s.db.settings
    if aliases[kind]:
        settings.antype = aliases[kind]
    elif status == "NEW":
        raise ApdlError("field 1 (analysis type) is required for a new analysis")
    if status == "NEW":
        s.solution.fresh_start = True
        s.solution.new_analysis = True
        settings.time = None
    elif c.given(3) or c.given(4):
        raise ApdlError("a restart at a chosen load step or substep (fields 3-4, LDSTEP, "
                        "SUBSTEP) is not supported; leave them empty to continue from the "
                        "last solution of this run")
    elif not s.solution.results and s.solution.temperature is None and not s.record_only:
        # MAPDL restarts from the files of an earlier run (Jobname.rdb, .Rnnn); here the
        # state lives in the session only, so that run has to be part of this one
        raise ApdlError(f"{status} (restart): no previous solution in this run to "
                        "continue from; restarting from another run's files (.rdb, .Rnnn) "
                        "is not supported: /INPUT the deck that solves it first, in the "
                        "same run, or give the state with apdl-like run --spindle --start "
                        "FILE.vtu")
    else:
        s.solution.fresh_start = False
        s.solution.new_analysis = False


@command("TIME", LOADS, 1)
def time(s: SessionState, c: Call) -> None:
    t = c.num(1, what="TIME")
    if t < 0.0:
        raise ApdlError(f"TIME must be ≥ 0, got {t!r}")
    s.db.settings.time = t
    s.note_load(c)


@command("DELTIM", LOADS, 4)
def deltim(s: SessionState, c: Call) -> None:
    """DELTIM,DTIME,DTMIN,DTMAX: the (first) substep and, with AUTOTS, its bounds."""
    dt = c.num(1, what="DTIME")
    if not dt > 0.0:
        raise ApdlError(f"DTIME must be positive, got {dt!r}")
    settings = s.db.settings
    settings.deltim, settings.nsubst = dt, None
    settings.dtmin = c.num(2, what="DTMIN") if c.given(2) else None
    settings.dtmax = c.num(3, what="DTMAX") if c.given(3) else None
    if settings.dtmin is not None and not 0.0 < settings.dtmin <= dt:
        raise ApdlError(f"DTMIN must lie in (0, DTIME], got {settings.dtmin!r}")
    if settings.dtmax is not None and settings.dtmax < dt:
        raise ApdlError(f"DTMAX must be ≥ DTIME, got {settings.dtmax!r}")


@command("NSUBST", LOADS, 4)
def nsubst(s: SessionState, c: Call) -> None:
    """NSUBST,NSBSTP,NSBMX,NSBMN: substeps and, with AUTOTS, their bounds."""
    n = c.int(1, what="NSBSTP")
    if not 1 <= n <= 100_000:
        raise ApdlError(f"NSBSTP must lie in 1..100000, got {n}")
    settings = s.db.settings
    settings.nsubst, settings.deltim = n, None
    nmax = c.int(2, what="NSBMX") if c.given(2) else None
    nmin = c.int(3, what="NSBMN") if c.given(3) else None
    if nmax is not None and not n <= nmax <= 1_000_000:
        raise ApdlError(f"NSBMX must lie in NSBSTP..1000000, got {nmax}")
    if nmin is not None and not 1 <= nmin <= n:
        raise ApdlError(f"NSBMN must lie in 1..NSBSTP, got {nmin}")
    settings.nsub_max, settings.nsub_min = nmax, nmin


@command("KBC", LOADS, 1)
def kbc(s: SessionState, c: Call) -> None:
    key = c.int(1, 0, what="KEY")
    if key not in (0, 1):
        raise ApdlError(f"KEY must be 0 (ramped) or 1 (stepped), got {key}")
    s.db.settings.kbc = key


@command("TIMINT", LOADS, 2)
def timint(s: SessionState, c: Call) -> None:
    key = c.label(1, "ON")
    if key not in ("ON", "OFF", "1", "0"):
        raise ApdlError(f"field 1 must be ON or OFF, got {key!r}")
    s.db.settings.timint = key in ("ON", "1")


@command("OUTRES", LOADS, 3)
def outres(s: SessionState, c: Call) -> None:
    s.db.settings.outres = c.label(2, "ALL")


@command("AUTOTS", LOADS, 1)
def autots(s: SessionState, c: Call) -> None:
    """AUTOTS,ON|OFF (blank: ON): time steps chosen by an error estimate within bounds."""
    key = c.label(1, "ON")
    if key not in ("ON", "OFF", "1", "0", "PROG"):
        raise ApdlError(f"field 1 must be ON or OFF, got {key!r}")
    s.db.settings.autots = key in ("ON", "1", "PROG")


@command("TINTP", LOADS, 6)
def tintp(s: SessionState, c: Call) -> None:
    """TINTP,,,,THETA: the transient integration parameter (1 backward Euler, 0.5 CN)."""
    if c.given(4):
        theta = c.num(4, what="THETA")
        if not 0.5 <= theta <= 1.0:
            raise ApdlError(f"THETA must lie in [0.5, 1], got {theta!r}")
        s.db.settings.theta = theta


# FULL is the only method here
# steps are uniform, as DELTIM/NSUBST ask


@command("LDREAD", SOLU, 8)
def ldread(s: SessionState, c: Call) -> None:
    """LDREAD,TEMP[,LSTEP]: the session's thermal result as body temperatures.

    The file fields are accepted and ignored: results stay in the session (no .rth file).
    """
    if c.label(1) != "TEMP":
        raise ApdlError(f"field 1: LDREAD supports TEMP only, got {c.label(1) or '(empty)'!r}")
    thermal = [r for r in s.solution.results if r.analysis == "thermal"]
    if not thermal:
        raise ApdlError("there is no thermal result to read (solve the thermal analysis first)")
    if c.given(2) and c.label(2) != "LAST":
        step = c.int(2, what="LSTEP")
        match = [r for r in thermal if r.load_step == step]
        if not match:
            raise ApdlError(f"load step {step} has no thermal result")
        chosen = match[0]
    else:
        chosen = thermal[-1]
    s.solution.body_temperature = chosen
    s.note_load(c)


@command("SOLVE", SOLU, 0)
def solve(s: SessionState, c: Call) -> None:
    s.budget.unsolved = None
    physics = {s.db.element_types[t].physics for t in s.db.elements.type_numbers()
               if t in s.db.element_types}
    # SURF151 only carries loads; thermal links and masses join a thermal model
    types = physics - {"surface", "line"} or ({"thermal"} if "line" in physics else set())
    if s.record_only:
        from apdl_like.loadset import record_solve

        s.recorded_solves.append(record_solve(s))
        return
    if "unsupported" in types:
        types = {"unsupported"}
        solve_thermal(s)  # raises the message naming the element type to redefine
    if len(types) != 1:
        raise ApdlError("the model mixes thermal and structural elements" if types else
                        "the model has no elements to solve")
    kind = "thermal" if types == {"thermal"} else "structural"
    sol = s.solution
    if sol.new_analysis:
        # a new analysis writes a new results file: earlier load steps of this physics go
        sol.results = [r for r in sol.results if r.analysis != kind]
        sol.new_analysis = False
    result = solve_thermal(s) if kind == "thermal" else solve_structural(s)
    result.load_step = 1 + sum(r.analysis == kind for r in sol.results)
    sol.results.append(result)
    sol.post_index = -1
    sol.post_result = None
    s.say(f"load step {result.load_step}: {result.analysis} solution at time {result.time:g}")


def _load_state(s: SessionState) -> dict:
    """What a load step file holds: the loads on nodes, elements and faces, and the
    load-step options."""
    db = s.db
    return copy.deepcopy({
        "nodes": {k: v for k, v in db.nodes.arrays.items() if k != "selected"},
        "elements": {k: v for k, v in db.elements.arrays.items() if k != "selected"},
        "faces": db.faces, "settings": db.settings, "real_sets": db.real_sets,
        "node_ids": db.nodes.ids, "element_ids": db.elements.ids})


@command("LSWRITE", LOADS, 2)
def lswrite(s: SessionState, c: Call) -> None:
    """LSWRITE,LSNUM: the current loads and options as load step LSNUM (in memory)."""
    steps = s.load_steps
    num = c.int_in(1, 1, 9999, max(steps, default=0) + 1, what="LSNUM")
    steps[num] = _load_state(s)
    s.budget.unsolved = None  # written loads are solved by LSSOLVE


def _restore(s: SessionState, num: int) -> None:
    saved = s.load_steps.get(num)
    if saved is None:
        raise ApdlError(f"load step {num} was never written (LSWRITE)")
    db = s.db
    if not (np.array_equal(saved["node_ids"], db.nodes.ids) and
            np.array_equal(saved["element_ids"], db.elements.ids)):
        raise ApdlError(f"the mesh changed since load step {num} was written")
    saved = copy.deepcopy(saved)
    db.nodes.arrays.update(saved["nodes"])
    db.elements.arrays.update(saved["elements"])
    db.faces, db.settings, db.real_sets = saved["faces"], saved["settings"], saved["real_sets"]


@command("LSREAD", LOADS, 2)
def lsread(s: SessionState, c: Call) -> None:
    """LSREAD,LSNUM: make load step LSNUM's loads and options the current ones."""
    _restore(s, c.int(1, 1, what="LSNUM"))


@command("LSSOLVE", SOLU, 3)
def lssolve(s: SessionState, c: Call) -> None:
    """LSSOLVE,LSMIN,LSMAX,LSINC: read and solve load steps in turn."""
    first = c.int(1, what="LSMIN")
    last = c.int(2, first, what="LSMAX")
    step = c.int(3, 1, what="LSINC")
    if step < 1:
        raise ApdlError("field 3 (LSINC) must be ≥ 1")
    for num in range(first, last + 1, step):
        _restore(s, num)
        solve(s, c)


COMMANDS = (
    *specs_of(lswrite, lsread, lssolve, antype, time, deltim, nsubst, kbc, timint, outres, autots,
              tintp, ldread, solve),
    CommandSpec("TRNOPT", LOADS, 8, ignored),
    # solver and output options: the direct solve and its listing need none of them
    *(CommandSpec(name, LOADS, 10, ignored) for name in (
        "OUTPR", "EQSLV", "NEQIT", "CNVTOL", "NROPT", "LNSRCH", "PRED", "ERESX", "RESCONTRL",
        "NCNV", "SOLCONTROL", "THOPT")),
)
