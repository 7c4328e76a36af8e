"""Emulated spindle and run reader: a 30 min run must generate in ≤ 3 s.

`synth_30min_s` is one `synthesize` call at 1 Hz (truth FEM on the fine mesh, 2 s steps,
sensors, faults; the default truth builds its own model with its material factors and
sensor offsets, 0.5 s of it); `suite_s_per_run_minute` is `twin synth --suite` (draw,
synthesize, write the four files per run) over three 20-minute runs, the figure to
multiply by a suite's run-minutes; `model_load_s` is the one-off cost of
building the truth model (mesh read or generated, operators assembled); `write_s` and
`read_run_s` write the CSV and read it back through validation and repairs.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path


def run() -> dict:
    from twin.plant.emulator import synthesize, write_synth
    from twin.plant.scenario import Scenario
    from twin.plant.suite import draw_suite, write_case
    from twin.runs import read_run
    from twin.spindle import SpindleModel

    t0 = time.perf_counter()
    model = SpindleModel.load(size_factor=Scenario().model.size_factor)
    load = time.perf_counter() - t0
    times = []
    for seed in (1, 2, 3):
        t0 = time.perf_counter()
        result = synthesize(speed_rpm=9000, minutes=30, ambient_C=25.3, seed=seed, model=model)
        times.append(time.perf_counter() - t0)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        path, _ = write_synth(result, Path(tmp) / "run.csv")
        write = time.perf_counter() - t0
        t0 = time.perf_counter()
        read_run(path)
        read = time.perf_counter() - t0
        suite = draw_suite(3, suite_seed=1, minutes=20)
        t0 = time.perf_counter()
        for case in suite:
            write_case(case, Path(tmp) / "suite", model)
        per_run_minute = (time.perf_counter() - t0) / (len(suite) * 20)
    return {
        "synth_30min_s": min(times),
        "synth_30min_worst_s": max(times),
        "budget_s": 3.0,
        "within_budget": max(times) <= 3.0,
        "model_load_s": load,
        "truth_dofs": int(model.n_dofs),
        "samples": result.n_samples,
        "write_s": write,
        "read_run_s": read,
        "suite_s_per_run_minute": per_run_minute,
    }


if __name__ == "__main__":
    import json

    print(json.dumps(run(), indent=2))
