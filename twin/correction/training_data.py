"""From recorded runs to `RunCurves`: the measured curves and the same run simulated.

The paper simulates each training run with the twin under the online ratio correction.
That is the twin loop's job (`twin.loop`, issue 7); the contract expected from it is

    twin.loop.simulate_for_training(run: RecordedRun) -> SimulatedRun

(the run replayed with the `ratio` method).  Until the loop exists, the run is simulated
open loop by the spindle model (`twin.spindle`), i.e. with the nominal values throughout.
A `Simulator` is any callable RecordedRun -> SimulatedRun, so tests and other tools can
plug in their own.
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
    """The twin loop's ratio-corrected replay if it exists, else an open-loop spindle run."""
    try:
        from twin.loop import simulate_for_training  # issue 7 contract
    except ImportError:
        simulate_for_training = None
    if simulate_for_training is not None:
        return simulate_for_training
    return _open_loop_spindle


def _open_loop_spindle(run: object) -> SimulatedRun:
    """Open-loop run of the spindle model (issue 3) at the run's speed and ambient.

    A stand-in until the twin loop exists: the spindle model runs one constant speed, so a
    run whose speed changes is simulated at its first speed (the training runs of the
    paper are constant-speed runs).  Nominal values follow the spindle model's own
    temperature-dependent Eq. 1 / Eq. 4 window by window; they are also the values used.
    """
    from twin.spindle import SpindleModel, simulate

    model = _spindle_model(SpindleModel)
    speed = float(np.asarray(run.speed_rpm)[0])
    ambient = float(np.nanmean(np.asarray(run.ambient_C)))
    coolant = getattr(run, "coolant_C", None)
    coolant_C = None if coolant is None else float(np.nanmean(np.asarray(coolant)))
    minutes = float(run.time_s[-1] - run.time_s[0]) / 60.0
    result = simulate(model, speed, minutes, ambient, coolant_C)
    nominal = np.array([[bc.H_front, bc.H_rear, bc.R_front, bc.R_rear]
                        for bc in result.conditions])
    return SimulatedRun(result.time_s + float(run.time_s[0]), result.sensors_C, nominal,
                        nominal, "open_loop")


_SPINDLE_CACHE: dict[str, object] = {}


def _spindle_model(cls: type) -> object:
    # the model assembles its operators once; every training run shares it
    if "model" not in _SPINDLE_CACHE:
        _SPINDLE_CACHE["model"] = cls.load()
    return _SPINDLE_CACHE["model"]


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
