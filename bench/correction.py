"""Cost of the correction: training the four networks and one bpnn/ratio window.

`bpnn_replay_cpu_ms_per_window`: CPU time per window of a whole bpnn replay through the
window decks (loop, correction, deck solve) on the bundled speed-step run with its first
30 s cut off, so its two steps (600 s and 1200 s in the file) fall inside windows 9 and
19: with the re-run of those windows (`twin.correction.rerun`, the default) and without.

Targets (issue 6): training ≤ 60 s for the paper's data volume (20 runs of 30 min, samples
every 60 s plus every 20 s over the first 10 min: 1000 samples), inference ≤ 1 ms per
window.  The samples come from the lumped test plant (twin/correction/toy_plant.py), so
the figures measure the machinery, not the accuracy of the twin.
"""

from __future__ import annotations

import dataclasses
import time
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from twin.correction.samples import SampleSet


def _samples(n_runs: int = 20) -> SampleSet:
    from twin.correction.samples import SampleSet, build_samples, open_loop_curves
    from twin.correction.toy_plant import ToyPlant

    plant = ToyPlant()
    sets = []
    for i, speed in enumerate(np.linspace(6000.0, 13000.0, n_runs)):
        rng = np.random.default_rng(i)
        ambient = 24.0 + 2.0 * rng.random()
        t = np.arange(0, 1801, 2.0)
        H, R = plant.nominal_heat_W_m3(speed), plant.nominal_resistance_m2K_W(speed)
        factor = 1 + 0.1 * (speed - 9000) / 4000
        T = plant.simulate(t, speed, ambient, H * factor, R * [1.2, 0.9])
        T += rng.normal(0, 0.05, T.shape)
        ts = np.arange(0, 1801, 4.0)
        Ts = plant.simulate(ts, speed, ambient, H, R)
        sets.append(build_samples(open_loop_curves(
            f"r{speed:.0f}", t, np.full(t.size, speed), np.full(t.size, ambient), T, ts, Ts,
            np.r_[H, R])))
    samples = SampleSet.concatenate(sets)
    # the anchored networks need an anchor and their own inputs: the lumped plant has no
    # ratio-law chain, so the nominal value stands in for the anchor and the paper's inputs
    # for the anchored ones (same shapes, same cost; these figures time the machinery)
    return dataclasses.replace(samples, anchors={o: x[:, 5] for o, x in samples.inputs.items()},
                               anchored_inputs=samples.inputs)


def replay_cpu_ms_per_window(repeats: int = 3) -> dict:
    """CPU ms per window of a bpnn replay (deck solver) with and without the re-run, and
    how many windows were re-run (module doc)."""
    from pathlib import Path

    from twin.correction.methods import BpnnCorrection
    from twin.correction.modelfile import load_model
    from twin.loop.replay import deck_window_solver, replay_method
    from twin.runs.run import read_table, run_from_table
    from twin.spindle.model import SpindleModel

    root = Path(__file__).resolve().parent.parent
    table = read_table(root / "examples" / "runs" / "spindle_steps_faults_30min.csv")
    keep = table.columns["time_s"] >= 30.0
    table = dataclasses.replace(
        table, rows=table.rows[keep],
        columns={k: (v[keep] - 30.0 if k == "time_s" else v[keep])
                 for k, v in table.columns.items()})
    run = run_from_table(table)
    spindle = SpindleModel.load()
    network = load_model(root / "examples" / "correction_model.safetensors")
    out = {}
    for rerun in (True, False):
        solver = deck_window_solver(spindle)
        best = float("inf")
        for _ in range(repeats):
            start = time.process_time()
            r = replay_method(run, spindle, BpnnCorrection(network, rerun_missed_speed=rerun),
                              solver=solver, keep_fields=False)
            best = min(best, time.process_time() - start)
        key = "with_rerun" if rerun else "without_rerun"
        out[key] = 1e3 * best / len(r.windows)
        if rerun:
            out["rerun_windows"] = sum(w.rerun_deck is not None for w in r.windows)
            out["windows"] = len(r.windows)
    return out


def run() -> dict:
    from twin.correction import BoundaryValues, WindowFeatures, make_corrector
    from twin.correction.network import DEFAULT, PAPER
    from twin.correction.training import train_model

    start = time.perf_counter()
    samples = _samples()
    sample_s = time.perf_counter() - start
    result = train_model(samples, config=DEFAULT, epochs=5000, seed=0)
    paper = train_model(samples, config=PAPER, epochs=5000, seed=0)

    t = np.arange(0, 1741, 1.0)
    T = 25.0 + 5.0 * (1 - np.exp(-t / 600.0))[:, None] * np.ones(5)
    nominal = BoundaryValues(1.6e6, 0.9e6, 1e-4, 1.2e-4)
    f = WindowFeatures(29, 1740.0, 9000.0, 25.0, t, T, t[::4], T[::4] - 0.1, nominal, nominal)
    timings = {}
    for name in ("bpnn", "ratio"):
        method = make_corrector(name, result.model if name == "bpnn" else None)
        method.correct(f)
        n = 200
        start = time.perf_counter()
        for _ in range(n):
            method.correct(f)
        timings[name] = (time.perf_counter() - start) / n * 1e3
    return {
        "samples": len(samples),
        "sample_building_s": sample_s,
        "training_default_s": result.seconds,
        "training_paper_s": paper.seconds,
        "training_target_s": 60.0,
        "r2_default": result.r2_table(),
        "bpnn_window_ms": timings["bpnn"],
        "ratio_window_ms": timings["ratio"],
        "inference_target_ms": 1.0,
        "bpnn_replay_cpu_ms_per_window": replay_cpu_ms_per_window(),
    }


if __name__ == "__main__":
    import json

    print(json.dumps(run(), indent=2))
