"""From recorded runs to `RunCurves`: the measured curves and the same run simulated.

Simulating a training run is the twin loop's job, so the simulator is an argument here
(this package never imports `twin.loop`):

    run_curves(run, twin.loop.training.training_simulator("fit"))   # or "ratio"

A `Simulator` is any callable RecordedRun -> list[SimulatedRun] (one entry per simulated
pass), so tests and other tools can plug in their own.
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
    method: how `used` came about ("fit", "ratio", "open_loop").
    fitted (windows, 4): the window fit's values, the training targets (None: no fit).
    anchors (windows, 4), anchored_inputs (windows, 4, 6): the ratio-law anchor and the
    anchored networks' input rows the simulation saw at each window start (None: not
    recorded).
    """

    time_s: np.ndarray
    T_C: np.ndarray
    nominal: np.ndarray
    used: np.ndarray
    method: str
    fitted: np.ndarray | None = None
    anchors: np.ndarray | None = None
    anchored_inputs: np.ndarray | None = None


Simulator = Callable[[object], list[SimulatedRun]]


def run_curves(run: object, simulator: Simulator) -> list[RunCurves]:
    """RunCurves of a `twin.runs.RecordedRun`, one per pass `simulator` makes of it;
    invalid samples → NaN."""
    return [_curves(run, sim) for sim in simulator(run)]


def _curves(run: object, sim: SimulatedRun) -> RunCurves:
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
        fitted=None if sim.fitted is None else np.asarray(sim.fitted, dtype=float),
        anchors=sim.anchors,
        anchored_inputs=sim.anchored_inputs,
    )
