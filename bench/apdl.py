"""apdl_like: what a 60 s window deck costs on top of its solve, in a warm session.

The twin writes one deck per window (loads and time only) and runs it with
`Session.advance` in a persistent session on the default spindle model, as the replay does
(nominal loads of a 9000 rpm run: 8 heated regions, 12 convective boundaries, 2 contact
interfaces).  Per window (median over windows, operators already assembled):

    write_ms         `window_deck` (the deck text from the load set)
    advance_ms       `Session.advance`: parse + dispatch + solve
    parse_ms         parsing alone (part of advance_ms)
    solve_ms         the same solve through twin.fem directly: one factorization and 15
                     backward-Euler steps with identical loads
    deck_overhead_ms write_ms + advance_ms - solve_ms: what the deck path adds
    overhead_ratio   deck_overhead_ms / solve_ms (issue 11 target: at most 0.5)

`python -m bench.apdl` prints the figures as JSON.
"""

from __future__ import annotations

import json
import statistics
import time

import numpy as np


def run(windows: int = 15) -> dict:
    from apdl_like.loadset import LoadSet
    from apdl_like.parser import parse_deck
    from apdl_like.session import Session
    from apdl_like.writer import window_deck
    from twin.contract import STEP_S, STEPS_PER_WINDOW
    from twin.fem import ThermalLoads
    from twin.loop.replay import nominal_conditions
    from twin.spindle.model import SpindleModel

    model = SpindleModel.load()
    session = Session.from_mesh(model.mesh, model.materials, order=model.order,
                                T_ref_C=model.elastic.T_ref, thermal=model.thermal)

    def loads(k: int) -> LoadSet:
        T_bearing = 25.0 + 0.5 * k
        bc = nominal_conditions(model, 9000.0, 22.0, None,
                                T_bearings_C=(T_bearing, T_bearing),
                                T_sleeves_C=(T_bearing - 1.0, T_bearing - 1.0),
                                film_ambient_C=22.0)
        th = bc.to_thermal_loads(H_front=bc.H_front, H_rear=bc.H_rear, R_front=bc.R_front,
                                 R_rear=bc.R_rear)
        return LoadSet(window=k, start_s=60.0 * k, dt_s=STEP_S, n_steps=STEPS_PER_WINDOW,
                       heat_generation=th.sources, convection=th.convection,
                       contact_resistance=th.contact_resistance)

    n_dofs = model.n_dofs
    t0 = time.process_time()
    T = session.advance(np.full(n_dofs, 20.0), 0.0, window_deck(loads(0), session.layout))[-1]
    first_ms = 1e3 * (time.process_time() - t0)
    problem = model.thermal
    write_ms, advance_ms, parse_ms, solve_ms = [], [], [], []
    for k in range(1, windows + 1):
        ls = loads(k)
        t0 = time.process_time()
        text = window_deck(ls, session.layout)
        write_ms.append(1e3 * (time.process_time() - t0))
        t0 = time.process_time()
        parse_deck(text, "w.inp")
        parse_ms.append(1e3 * (time.process_time() - t0))
        T_start = T
        t0 = time.process_time()
        steps = session.advance(T_start, ls.start_s, text, f"window_{k:03d}.inp")
        advance_ms.append(1e3 * (time.process_time() - t0))
        direct = ThermalLoads(sources=dict(ls.heat_generation), convection=dict(ls.convection),
                              contact_resistance=dict(ls.contact_resistance))
        t0 = time.process_time()
        stepper = problem.transient(direct, ls.dt_s)
        T_direct = T_start
        for _ in range(ls.n_steps):
            T_direct = stepper.step(T_direct)
        solve_ms.append(1e3 * (time.process_time() - t0))
        if not np.allclose(T_direct, steps[-1], rtol=1e-10, atol=1e-10):
            raise AssertionError("the deck path and the direct solve disagree")
        T = steps[-1]
    write, advance, solve = (statistics.median(v) for v in (write_ms, advance_ms, solve_ms))
    overhead = write + advance - solve
    return {
        "mesh_nodes": int(n_dofs),
        "windows": windows,
        "first_window_ms": round(first_ms, 3),
        "write_ms": round(write, 3),
        "parse_ms": round(statistics.median(parse_ms), 3),
        "advance_ms": round(advance, 3),
        "solve_ms": round(solve, 3),
        "deck_overhead_ms": round(overhead, 3),
        "overhead_ratio": round(overhead / solve, 3),
        "target_overhead_ratio": 0.5,
    }


if __name__ == "__main__":
    print(json.dumps(run(), indent=2))
