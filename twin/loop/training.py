"""The twin's own simulations of a training run, for the networks' sample builder.

`simulate_for_training` (the default): the run replayed with the offline window fit
(`twin.loop.windowfit`), once on the fit itself and `DRIVEN_PASSES` times driven by values
scattered around it; each pass carries the fitted values per window (the targets).

`simulate_with_ratio` (the paper's way, `twin train --targets ratio`): the run replayed
with the online ratio correction; the targets then come from Eq. 2/5/6 on fitted curves.

`training_simulator(rule, spindle)` picks one of them for a `TargetRule`, bound to one
spindle model for every run; `twin.correction` takes the simulator as an argument
(`run_curves(run, simulator)`) and never imports the loop.
"""

from __future__ import annotations

import functools

import numpy as np

from twin.correction.methods import make_corrector
from twin.correction.training_data import SimulatedRun, Simulator
from twin.loop.replay import MethodReplay, replay_method
from twin.loop.target_rules import TargetRule
from twin.loop.windowfit import WindowFit

DRIVEN_PASSES = (0.05, 0.05)
"""drive_spread of the extra passes per run (seeds 1, 2, …): see `WindowFit`."""


def simulate_for_training(run, model) -> list[SimulatedRun]:  # noqa: ANN001
    """The run (a `twin.runs.RecordedRun`) replayed on `model` (a `SpindleModel`) with the
    window fit: one exact pass, then the driven passes."""
    out = []
    for seed, spread in enumerate((0.0, *DRIVEN_PASSES)):
        fit = WindowFit(run, model, drive_spread=spread, seed=seed)
        result = replay_method(run, model, fit, keep_fields=False)
        out.append(_simulated(run, result, np.array(fit.fitted)))
    return out


def simulate_with_ratio(run, model) -> list[SimulatedRun]:  # noqa: ANN001
    """The run replayed on `model` with the online ratio correction (the paper's training
    simulation)."""
    result = replay_method(run, model, make_corrector("ratio"), keep_fields=False)
    return [_simulated(run, result, None)]


def training_simulator(rule: TargetRule | str = TargetRule.FIT, spindle=None) -> Simulator:  # noqa: ANN001
    """The twin's simulation of a training run for a target rule, on `spindle` (a loaded
    `SpindleModel`; None: the bundled reference spindle, loaded here once for every run).
    The simulator keeps the name of the simulation it runs (the model file records it)."""
    simulators = {TargetRule.FIT: simulate_for_training, TargetRule.RATIO: simulate_with_ratio}
    try:
        simulate = simulators[TargetRule(rule)]
    except ValueError:
        rules = ", ".join(r.value for r in TargetRule)
        raise ValueError(f"unknown target rule {rule!r}; expected one of {rules}") from None
    if spindle is None:
        from twin.spindle.model import SpindleModel

        spindle = SpindleModel.load()
    return functools.update_wrapper(functools.partial(simulate, model=spindle), simulate)


def _simulated(run, result: MethodReplay, fitted: np.ndarray | None) -> SimulatedRun:  # noqa: ANN001
    # the series starts at t = 0 with the uniform initial field the loop starts from
    t0 = float(run.time_s[0])
    return SimulatedRun(
        time_s=np.r_[0.0, result.time_s] + t0,
        T_C=np.vstack([np.full((1, 5), result.T_initial_C), result.T_twin_C]),
        nominal=np.array([list(w.nominal) for w in result.windows]),
        used=np.array([list(w.correction.values) for w in result.windows]),
        method=result.method,
        fitted=fitted,
    )
