"""The twin's own simulation of a training run (issue 6's sample builder needs it).

The paper builds its training samples from each recorded run and "the same conditions
simulated" by the twin with the online ratio correction; this is that simulation: the
run replayed by the loop with the `ratio` method.
"""

from __future__ import annotations

import numpy as np

from twin.correction.methods import make_corrector
from twin.correction.training_data import SimulatedRun
from twin.loop.replay import replay_method
from twin.loop.runfiles import default_spindle


def simulate_for_training(run) -> SimulatedRun:  # noqa: ANN001 - a twin.runs.RecordedRun
    """Replay `run` with the ratio correction; T1..T5 per solver step and H/R per window.

    The series starts at t = 0 with the uniform initial field the loop starts from.
    """
    result = replay_method(run, default_spindle(), make_corrector("ratio"), keep_fields=False)
    nominal = np.array([list(w.nominal) for w in result.windows])
    used = np.array([list(w.correction.values) for w in result.windows])
    t0 = float(run.time_s[0])
    return SimulatedRun(
        time_s=np.r_[0.0, result.time_s] + t0,
        T_C=np.vstack([np.full((1, 5), result.T_initial_C), result.T_twin_C]),
        nominal=nominal,
        used=used,
        method="ratio",
    )
