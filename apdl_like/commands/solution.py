"""/SOLU: analysis type, time stepping, LDREAD and SOLVE."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.commands import SOLU, Call, command
from apdl_like.errors import ApdlError
from apdl_like.solve import solve_structural, solve_thermal

if TYPE_CHECKING:
    from apdl_like.session import Session


@command("ANTYPE", SOLU, 4)
def antype(s: Session, c: Call) -> None:
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
        s.fresh_start = True
        settings.time = None
    elif not s.results and s.state is None and s.solve_enabled:
        raise ApdlError("ANTYPE,,REST: there is no previous solution to continue from")
    else:
        s.fresh_start = False


@command("TIME", SOLU, 1)
def time(s: Session, c: Call) -> None:
    t = c.num(1, what="TIME")
    if t < 0.0:
        raise ApdlError(f"TIME must be ≥ 0, got {t!r}")
    s.db.settings.time = t
    s.note_load(c)


@command("DELTIM", SOLU, 4)
def deltim(s: Session, c: Call) -> None:
    dt = c.num(1, what="DTIME")
    if not dt > 0.0:
        raise ApdlError(f"DTIME must be positive, got {dt!r}")
    s.db.settings.deltim = dt
    s.db.settings.nsubst = None


@command("NSUBST", SOLU, 4)
def nsubst(s: Session, c: Call) -> None:
    n = c.int(1, what="NSBSTP")
    if not 1 <= n <= 100_000:
        raise ApdlError(f"NSBSTP must lie in 1..100000, got {n}")
    s.db.settings.nsubst = n
    s.db.settings.deltim = None


@command("KBC", SOLU, 1)
def kbc(s: Session, c: Call) -> None:
    key = c.int(1, 0, what="KEY")
    if key not in (0, 1):
        raise ApdlError(f"KEY must be 0 (ramped) or 1 (stepped), got {key}")
    s.db.settings.kbc = key


@command("TIMINT", SOLU, 2)
def timint(s: Session, c: Call) -> None:
    key = c.label(1, "ON")
    if key not in ("ON", "OFF", "1", "0"):
        raise ApdlError(f"field 1 must be ON or OFF, got {key!r}")
    s.db.settings.timint = key in ("ON", "1")


@command("OUTRES", SOLU, 3)
def outres(s: Session, c: Call) -> None:
    s.db.settings.outres = c.label(2, "ALL")


command("TRNOPT", SOLU, 8)(lambda s, c: None)  # FULL is the only method here
command("AUTOTS", SOLU, 1)(lambda s, c: None)  # steps are uniform, as DELTIM/NSUBST ask


@command("LDREAD", SOLU, 8)
def ldread(s: Session, c: Call) -> None:
    """LDREAD,TEMP[,LSTEP]: the session's thermal result as body temperatures.

    The file fields are accepted and ignored: results stay in the session (no .rth file).
    """
    if c.label(1) != "TEMP":
        raise ApdlError(f"field 1: LDREAD supports TEMP only, got {c.label(1) or '(empty)'!r}")
    thermal = [r for r in s.results if r.analysis == "thermal"]
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
    s.body_temperature = chosen.temperature.copy()
    s.note_load(c)


@command("SOLVE", SOLU, 0)
def solve(s: Session, c: Call) -> None:
    s.unsolved = None
    types = {s.db.element_types[int(t)].physics for t in np.unique(s.db.elements.type)
             if int(t) in s.db.element_types}
    if not s.solve_enabled:
        from apdl_like.loadset import record_solve

        s.recorded_solves.append(record_solve(s))
        return
    if "unsupported" in types:
        types = {"unsupported"}
        solve_thermal(s)  # raises the message naming the element type to redefine
    if len(types) != 1:
        raise ApdlError("the model mixes thermal and structural elements" if types else
                        "the model has no elements to solve")
    result = solve_thermal(s) if types == {"thermal"} else solve_structural(s)
    s.results.append(result)
    s.post_index = -1
    s.say(f"load step {result.load_step}: {result.analysis} solution at time {result.time:g}")
