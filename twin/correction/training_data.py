"""From recorded runs to `RunCurves`: the measured curves and the same run simulated.

The paper simulates each training run with the twin under the online ratio correction.
That is the twin loop's job (`twin.loop`, issue 7); the contract expected from it is

    twin.loop.simulate_for_training(run: RecordedRun) -> SimulatedRun

(the run replayed with the `ratio` method).  A `Simulator` is any callable
RecordedRun -> SimulatedRun, so tests and other tools can plug in their own.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from twin.correction.samples import RunCurves


@dataclass(frozen=True)
class SimulatedRun:
    """A run as the twin simulated it.

    time_s (m,), T_C (m, 5): simulated T1..T5 at the solver steps (run time, s).
    nominal (windows, 4): Eq. 1 / Eq. 4 values per 60 s window (BoundaryValues order).
    used (windows, 4): the values the simulation ran with per window.
    method: how `used` came about ("ratio", "open_loop").
    """

    time_s: np.ndarray
    T_C: np.ndarray
    nominal: np.ndarray
    used: np.ndarray
    method: str


Simulator = Callable[[object], SimulatedRun]


def default_simulator() -> Simulator:
    """The twin loop's replay of a run with the online ratio correction (the paper's way)."""
    from twin.loop import simulate_for_training

    return simulate_for_training


def run_curves(run: object, simulator: Simulator | None = None) -> RunCurves:
    """RunCurves of a `twin.runs.RecordedRun`; samples flagged invalid become NaN."""
    sim = (simulator or default_simulator())(run)
    measured = np.array(run.T_C, dtype=float, copy=True)
    valid = getattr(run, "valid_T", None)
    if valid is not None:
        measured[~np.asarray(valid, dtype=bool)] = np.nan
    return RunCurves(
        name=str(run.name),
        time_s=np.asarray(run.time_s, dtype=float),
        speed_rpm=np.asarray(run.speed_rpm, dtype=float),
        ambient_C=np.asarray(run.ambient_C, dtype=float),
        measured_C=measured,
        sim_time_s=np.asarray(sim.time_s, dtype=float),
        simulated_C=np.asarray(sim.T_C, dtype=float),
        nominal=np.asarray(sim.nominal, dtype=float),
        used=np.asarray(sim.used, dtype=float),
    )
