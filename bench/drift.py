"""Cost of the data-driven drift models on the bundled real data (examples/real/).

Targets (issue 15): `twin drift fit` ≤ 60 s — the whole fit: sensor ranking, the
time-blocked validation of every method, the final fit of the chosen one — and predict
≤ 2 s for 11k rows.  Wall and CPU time are both recorded: on a machine shared with other
work the wall time includes waiting for a core.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

import numpy as np

DATA = Path(__file__).resolve().parent.parent / "examples" / "real" / "train.csv"
TARGETS = [f"ch{i}_um" for i in range(1, 6)]
PREDICT_ROWS = 11_000


Result = TypeVar("Result")


def _timed(func: Callable[[], Result]) -> tuple[Result, float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    out = func()
    return out, time.perf_counter() - wall, time.process_time() - cpu


def run() -> dict:
    from twin.drift.data import read_drift_data
    from twin.drift.model import fit_drift_model

    data = read_drift_data([DATA], targets=TARGETS)
    model, fit_wall, fit_cpu = _timed(lambda: fit_drift_model(data, seed=0))
    # 11k rows: the data followed by its first part again, as one continuous record
    n = data.n_samples
    rows = np.arange(PREDICT_ROWS) % n
    dt = float(np.median(np.diff(data.time_s)))
    time_s = np.arange(PREDICT_ROWS) * dt
    columns = [data.sensors.index(s) for s in model.spec.sensors]
    T = data.T_C[rows][:, columns]
    speed = data.speed_rpm[rows]
    _, predict_wall, predict_cpu = _timed(lambda: model.predict_arrays(time_s, T, speed))
    return {"rows": n, "chosen": model.method, "fit_wall_s": fit_wall, "fit_cpu_s": fit_cpu,
            "fit_target_s": 60.0, "predict_rows": PREDICT_ROWS,
            "predict_wall_s": predict_wall, "predict_cpu_s": predict_cpu,
            "predict_target_s": 2.0,
            "validation_mean_rmse_um": {k: v["mean_rmse_um"] for k, v in
                                        model.metadata["validation"]["methods"].items()}}
