"""Benchmark of the reference spindle: model build and the 30 min open-loop run.

`run()` returns timings in seconds; the open-loop run (9000 rpm, 25.3 °C,
30 min, 4 s steps, loads re-evaluated every step, no field output) has a target of ≤ 1 s.
"""

from __future__ import annotations

import time


def run(repeats: int = 3) -> dict:
    """Timings (s): model load, best-of-`repeats` 30 min open-loop run, per step."""
    from twin.spindle import SpindleModel, simulate

    t0 = time.perf_counter()
    model = SpindleModel.load()
    load_s = time.perf_counter() - t0
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = simulate(model, 9000.0, 30.0, 25.3)
        runs.append(time.perf_counter() - t0)
    best = min(runs)
    steps = result.time_s.size - 1
    return {
        "spindle_model_load_s": load_s,
        "spindle_open_loop_30min_s": best,
        "spindle_open_loop_step_ms": 1e3 * best / steps,
        "spindle_open_loop_target_s": 1.0,
        "spindle_open_loop_ok": bool(best <= 1.0),
        "spindle_dofs": int(model.n_dofs),
        "spindle_max_temperature_C": result.max_temperature_C,
        "spindle_nose_drift_um": float(result.disp_z_um[-1]),
    }


if __name__ == "__main__":
    import json

    print(json.dumps(run(), indent=2))
