"""A long recorded run: does a window late in a shift cost what one at its start costs?

Users replay whole shifts (8 h and more at 1 Hz).  A window's correction reads the
measured history up to its start; read by whole-history masks, each window's cost grew
with the run (a 24-h replay's last windows masked 86 400 rows several times each, until
2026-11-27).  This case emulates a 4-h run at 1 Hz (a 20-min cycle of 9000 rpm, 12 000
rpm and a stop, T1 stuck throughout, so `bpnn` reads the front bearing through its sleeve
every window: `WindowFeatures.with_dead_rings_read_through_sleeves`) and replays it with
`bpnn` in this process, timing every window:

    window_start_ms   median over the second and third cycles (windows 20–59; the first
                      is the cold start)
    window_end_ms     median over the last two cycles (the same speeds and stop)
    end_over_start    their ratio: about 1 where no per-window work grows with the run

each as wall and as CPU time (`time.process_time`: compare CPU on a loaded machine), and
the replay's total.  `cpu_outside_solver` is the CPU of a window less its deck solves:
the features and the correction, where the history is read (a 24-h run's last windows:
5.8 ms against 2.0 ms at its start before 2026-11-27, 2.0 against 2.0 after, on a run
without a dead sensor).  A machine whose load changes during the run moves every ratio;
the solver-free one least.  `synth_s` is the emulation of the run (not the figure under test).
The replay keeps no fields and writes nothing: the outputs are linear in the run and
measured by `bench.replay_cli` on a short one.

`python -m bench.long_run [--hours H]` prints the figures as JSON.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
MODEL = ROOT / "examples" / "correction_model.safetensors"
METHOD = "bpnn"
HOURS = 4.0
CYCLE = ((9000.0, 480.0), (12000.0, 480.0), (0.0, 240.0))
"""(speed rpm, seconds) in turn: 20 min, so that the windows compared at the start and at
the end of the run have the same speeds, speed changes and stop."""
SCENARIO = '[faults]\nstuck = ["T1"]\n'
SAMPLE = 40
"""Windows per median: two cycles."""


def _run(folder: Path, hours: float) -> tuple[Path, float]:
    """The emulated run's CSV in `folder` and the seconds its emulation took."""
    from twin.plant.emulator import synthesize, write_synth
    from twin.plant.profile import SpeedProfile
    from twin.plant.scenario import parse_scenario
    from twin.plant.timetable import StepTable

    lengths = [length for _, length in CYCLE]
    cycles = int(np.ceil(hours * 3600.0 / sum(lengths)))
    steps = np.cumsum([0.0] + lengths * cycles)[:-1]
    speeds = [speed for speed, _ in CYCLE] * cycles
    t0 = time.perf_counter()
    result = synthesize(minutes=hours * 60.0, ambient_C=22.0, seed=7,
                        profile=SpeedProfile(StepTable(steps.tolist(), speeds)),
                        scenario=parse_scenario(SCENARIO, "long_run.toml"))
    path, _ = write_synth(result, folder / "long_run.csv")
    return path, time.perf_counter() - t0


def _medians(per_window_ms: np.ndarray) -> dict[str, float]:
    start = float(np.median(per_window_ms[SAMPLE // 2:SAMPLE // 2 + SAMPLE]))
    end = float(np.median(per_window_ms[-SAMPLE:]))
    return {"window_start_ms": round(start, 3), "window_end_ms": round(end, 3),
            "end_over_start": round(end / start, 3)}


def run(hours: float = HOURS) -> dict:
    from twin.correction.methods import make_corrector
    from twin.loop.replay import deck_window_solver, replay_method
    from twin.runs import read_run
    from twin.spindle.model import SpindleModel

    with tempfile.TemporaryDirectory() as tmp:
        path, synth_s = _run(Path(tmp), hours)
        model = SpindleModel.load()
        run = read_run(path, max_speed_rpm=model.spec.spindle.max_speed_rpm)
    corrector = make_corrector(METHOD, str(MODEL), spindle=model)
    stamps = [(time.perf_counter(), time.process_time())]
    in_solver = [0.0]  # CPU seconds in the deck solver so far
    solver_cpu = [0.0]
    deck_solver = deck_window_solver(model)

    def solver(*args: object, **kwargs: object) -> tuple:
        t = time.process_time()
        try:
            return deck_solver(*args, **kwargs)
        finally:
            in_solver[0] += time.process_time() - t

    def told(_done: int, _total: int) -> None:
        stamps.append((time.perf_counter(), time.process_time()))
        solver_cpu.append(in_solver[0])

    replay_method(run, model, corrector, solver=solver, keep_fields=False, on_window=told)
    clock = np.array(stamps)
    per_window = 1e3 * np.diff(clock, axis=0)
    outside = per_window[:, 1] - 1e3 * np.diff(solver_cpu)
    return {
        "run": f"{hours:g} h at 1 Hz, 8 min 9000 rpm, 8 min 12 000 rpm, 4 min stopped, "
               "T1 stuck",
        "method": METHOD,
        "windows": int(per_window.shape[0]),
        "replay_wall_s": round(float(clock[-1, 0] - clock[0, 0]), 3),
        "replay_cpu_s": round(float(clock[-1, 1] - clock[0, 1]), 3),
        "wall": _medians(per_window[:, 0]),
        "cpu": _medians(per_window[:, 1]),
        "cpu_outside_solver": _medians(outside),
        "synth_s": round(synth_s, 3),
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, default=HOURS)
    print(json.dumps(run(parser.parse_args().hours), indent=2))
