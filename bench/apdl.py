"""apdl_like: what a 60 s window deck costs on top of the solve, in a warm session.

The twin writes one deck per window (loads and time only) and runs it in a persistent
`apdl_like.Session` on the default spindle mesh.  `window_deck_ms` is parse + apply +
solve of such a deck (median over windows, operators already assembled);
`direct_solve_ms` is the same solve through twin.fem directly (one factorization and 15
backward-Euler steps with identical loads); `overhead_ms` is the difference (target ≤ 2 ms).
"""

from __future__ import annotations

import statistics
import time

import numpy as np


def run(windows: int = 9) -> dict:
    from apdl_like.loadset import LoadSet
    from apdl_like.parser import parse_deck
    from apdl_like.session import Session
    from apdl_like.writer import window_deck
    from twin.fem import AxiMesh, ThermalLoads
    from twin.spindle.model import DEFAULT_MESH_PATH, fem_material
    from twin.spindle.spec import load_spec

    spec = load_spec()
    mesh = AxiMesh.from_msh(DEFAULT_MESH_PATH, interfaces=spec.interfaces())
    materials = {region: fem_material(spec, region) for region in spec.regions}
    session = Session.from_mesh(mesh, materials, T_initial_C=20.0)

    def loads(k: int) -> LoadSet:
        return LoadSet(
            window=k, start_s=60.0 * k,
            heat_generation={"front_rolling_band": 2.0e6 * (1 + 0.01 * k),
                             "rear_rolling_band": 1.2e6, "rotor": 1.5e5, "stator": 2.0e5},
            convection={"coolant": (900.0, 22.0), "housing_outer": (9.0, 24.0),
                        "nose_face": (12.0, 24.0), "air_gap_rotor": (60.0, 30.0),
                        "air_gap_stator": (60.0, 30.0)},
            contact_resistance={"contact_front": 1.2e-4 * (1 + 0.01 * k),
                                "contact_rear": 1.5e-4})

    t0 = time.perf_counter()
    session.run_text(window_deck(loads(0), session.layout), "window_000.inp")
    first_ms = 1e3 * (time.perf_counter() - t0)
    deck_ms, solve_ms, parse_ms = [], [], []
    problem = session.thermal
    for k in range(1, windows + 1):
        ls = loads(k)
        text = window_deck(ls, session.layout)
        t0 = time.perf_counter()
        parse_deck(text, "w.inp")
        parse_ms.append(1e3 * (time.perf_counter() - t0))
        T_start = session.state.solution.temperature.copy()
        t0 = time.perf_counter()
        session.run_text(text, f"window_{k:03d}.inp")
        deck_ms.append(1e3 * (time.perf_counter() - t0))
        direct = ThermalLoads(sources=dict(ls.heat_generation), convection=dict(ls.convection),
                              contact_resistance=dict(ls.contact_resistance))
        t0 = time.perf_counter()
        stepper = problem.transient(direct, ls.dt_s)
        T = T_start
        for _ in range(ls.n_steps):
            T = stepper.step(T)
        solve_ms.append(1e3 * (time.perf_counter() - t0))
        assert np.allclose(T, session.state.solution.temperature, rtol=1e-10, atol=1e-10)
    deck, solve = statistics.median(deck_ms), statistics.median(solve_ms)
    return {
        "mesh_nodes": int(mesh.thermal.p.shape[1]),
        "first_window_ms": round(first_ms, 3),
        "window_deck_ms": round(deck, 3),
        "direct_solve_ms": round(solve, 3),
        "overhead_ms": round(deck - solve, 3),
        "parse_ms": round(statistics.median(parse_ms), 3),
        "target_overhead_ms": 2.0,
    }


if __name__ == "__main__":
    print(run())
