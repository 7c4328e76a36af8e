"""Estimator benchmarks (issue 13): ensemble size against accuracy and time; the default
estimator's time per 30 min run and its peak memory.

- per ensemble size (the default: recorded drift assimilated), the default size on
  T1..T5 alone (`assimilate_drift=False`), and the default on the runs without their
  coolant_C column (the inlet then estimated too): the estimator
  replayed through its window decks (what `twin replay` does for the method) on every
  bundled run, warm process: best-of-two wall time and CPU time per run, mean temperature /
  deformation accuracy and band coverage;
- the default (EstimatorConfig()) in a fresh `twin replay --methods estimator` process:
  wall time and peak RSS (imports, model load and all writes included).
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from bench.loop import _cli

ROOT = Path(__file__).resolve().parent.parent
MEMBERS = (16, 24, 32, 48)  # at least parameters + 2 (fourteen estimated by default)


def bundled_runs() -> list[Path]:
    runs = sorted((ROOT / "examples" / "runs").glob("*.csv"))
    return [r for r in runs if not r.name.endswith(".truth.csv")]


def ensemble_table(members: tuple[int, ...] = MEMBERS) -> list[dict]:
    """One row per ensemble size (the default: the recorded drift assimilated), the
    default size on T1..T5 alone (`assimilate_drift=False`), and the default on the runs
    with their coolant inlet left out (`coolant_recorded` false: the inlet estimated)."""
    import dataclasses

    from twin.estimation.method import EnsembleEstimator, EstimatorConfig
    from twin.loop.replay import deck_window_solver, replay_method
    from twin.loop.runfiles import measured_reference, method_accuracy
    from twin.runs import read_run
    from twin.spindle.model import SpindleModel

    model = SpindleModel.load()
    runs = [read_run(p) for p in bundled_runs()]
    unrecorded = [dataclasses.replace(r, coolant_C=None) for r in runs]
    rows = []
    configs = [(EstimatorConfig(members=n), runs) for n in members]
    configs.append((EstimatorConfig(assimilate_drift=False), runs))
    configs.append((EstimatorConfig(), unrecorded))
    for cfg, replayed in configs:
        est = EnsembleEstimator(model, cfg)
        wall, cpu, metrics = [], [], []
        for run in replayed:
            best_wall = best_cpu = float("inf")
            for _ in range(2):
                t, c = time.perf_counter(), time.process_time()
                r = replay_method(run, model, est, solver=deck_window_solver(model),
                                  keep_fields=False)
                best_wall = min(best_wall, time.perf_counter() - t)
                best_cpu = min(best_cpu, time.process_time() - c)
            minutes = run.duration_s / 60.0
            wall.append(best_wall * 30.0 / minutes)
            cpu.append(best_cpu * 30.0 / minutes)
            metrics.append(method_accuracy(r, *measured_reference(run, r.time_s)))

        def mean(key: str, rows: list[dict] = metrics) -> float | None:
            v = [m[key] for m in rows if m[key] is not None]
            return float(np.mean(v)) if v else None

        rows.append({
            "members": cfg.members,
            "assimilate_drift": cfg.assimilate_drift,
            "coolant_recorded": replayed is runs,
            "wall_s_per_30min_run": float(np.mean(wall)),
            "cpu_s_per_30min_run": float(np.mean(cpu)),
            "temperature_accuracy_pct": mean("temperature_accuracy_pct"),
            "deformation_accuracy_pct": mean("deformation_accuracy_pct"),
            "band_coverage_pct": mean("band_coverage_pct"),
        })
        print(f"  {rows[-1]}")
    return rows


def run() -> dict:
    runs = bundled_runs()
    with tempfile.TemporaryDirectory() as tmp:
        args = ("replay", str(runs[0]), "--methods", "estimator", "--snapshots", "none",
                "--quiet")
        pycache = Path(tmp) / "pycache"
        _cli(*args, "--out", str(Path(tmp) / "warm-up"), pycache=pycache)  # compiles
        wall, rss = _cli(*args, "--out", str(Path(tmp) / "out"), pycache=pycache)
    return {
        "runs": [r.name for r in runs],
        "default_fresh_process": {"run": runs[0].name, "wall_s": wall, "peak_rss_mb": rss},
        "ensemble_size": ensemble_table(),
    }
