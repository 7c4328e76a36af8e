"""Re-running the window just ended with the speed it really had (a causal state correction).

A window's loads are fixed at its start (causality), so a speed step or a stop inside
window k−1 is missing from its forecast: the twin ends the window with the wrong field
(50 s of changed heat it never saw).  By the start of window k the recorded speed of the
whole window k−1 is known, so a method may re-run that window from its start field with
the recorded speed, step by step, and start window k from the re-run's end field and
read its errors off the re-run instead of the forecast that missed the input.

A run's window 0 whose loads were held (a correction without `loads_follow_rings`) is
re-run the same way (`first_window_at_speed`): they were held at the cold start's
temperatures while the rings warmed, and the re-run's loads follow its own temperatures
every `LOAD_UPDATE_STEPS` (every solver step), as every window's do by default.

One implementation serves every method that does it: the `estimator`
(`twin.estimation.method`, with its analysed factors) and the loop's state correction for
`bpnn` and `ratio` (`twin.loop.replay`, through the window decks; the training fit may ask
for it too, `twin.loop.windowfit.WindowFit.rerun_missed_speed`).  Each passes its own
`advance(speed_rpm, T, n_steps, start_s)`, the solver of one constant-speed stretch; this
module finds the change, the speed of every solver step and the stretches.

    changed = speed_change_s(features, forecast_speed_rpm)   # None: nothing to re-run
    speeds = recorded_step_speeds(features, steps, step_s)
    fields = rerun_window(T_start, start_s, speeds, step_s, advance)   # (steps, n_dofs)
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from twin.correction.features import WindowFeatures, rows_between

LOAD_UPDATE_STEPS = 1
"""A re-run's nominal loads follow its own temperatures every solver step (4 s), as the
spindle's follow its rings, continuously: a stretch is solved step by step, each from the
field the last one ended on (from a cold start the Palmgren heat falls by about a fifth in
the first minute as the oil warms).  Held for 5 steps (20 s), the rule until the emulated
spindle's loads followed its rings every step too, each piece's cold heat read as contact
resistance 6-20 % low in a cold start's first analysis at 12 700-13 500 rpm
(`tests/test_estimation.py`); held for 3 steps still 6-15 %; every step: within 5 %."""

Advance = Callable[[float, np.ndarray, int, float], np.ndarray]
"""(speed_rpm, T at the stretch start, n_steps, stretch start s) → T after each step
(n_steps, n_dofs)."""


def speed_change_s(f: WindowFeatures, forecast_speed_rpm: float) -> float | None:
    """Time (s) of the first recorded speed in the window just ended that differs from the
    speed its forecast ran at (None: no change, or no speed history).  The sample at the
    window's end is the next window's speed (the loop's), not a change inside this one."""
    if f.measured_speed_rpm is None:
        return None
    t = np.asarray(f.measured_time_s, float)
    rows = rows_between(t, f.start_s - f.window_s + 1e-9, f.start_s - 1e-9, with_upto=False)
    moved = np.abs(np.asarray(f.measured_speed_rpm, float)[rows] - forecast_speed_rpm) > 0.5
    return float(t[rows][np.argmax(moved)]) if moved.any() else None


def first_window_at_speed(f: WindowFeatures, forecast_speed_rpm: float) -> bool:
    """Whether the window just ended is a run's window 0 at speed (forecast at
    `forecast_speed_rpm`), which is re-run like a missed speed change: from a cold start
    the rings warm by kelvins in its minute and the Palmgren heat falls by about a fifth
    with the oil's viscosity, while its forecast held the cold value for 60 s; read off
    that forecast, the held heat looks like bearing heat and contact factors 13–32 % low."""
    return f.window == 1 and forecast_speed_rpm > 0


def recorded_step_speeds(f: WindowFeatures, steps: int, step_s: float) -> np.ndarray:
    """The recorded speed (rpm) of each solver step of the window just ended, read at the
    step's midpoint (the last sample at or before it; `f.measured_speed_rpm` required)."""
    start = f.start_s - f.window_s
    mid = start + (np.arange(steps) + 0.5) * step_s
    t = np.asarray(f.measured_time_s, float)
    recorded = np.asarray(f.measured_speed_rpm, float)
    return recorded[np.clip(np.searchsorted(t, mid - 1e-9) - 1, 0, len(t) - 1)]


def speed_stretches(speeds: np.ndarray, max_steps: int | None = None
                    ) -> list[tuple[float, int, int]]:
    """(speed rpm, first step, number of steps) of each run of equal speeds, in order; with
    `max_steps`, a run longer than that is cut into pieces of max_steps from its start."""
    speeds = np.asarray(speeds, float)
    edges = np.flatnonzero(np.abs(np.diff(speeds)) > 0.5) + 1
    bounds = np.r_[0, edges, speeds.size]
    out = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        step = int(b - a) if max_steps is None else int(max_steps)
        out += [(float(speeds[a]), int(i), int(min(step, b - i))) for i in range(a, b, step)]
    return out


def rerun_window(T_start: np.ndarray, start_s: float, speeds: np.ndarray, step_s: float,
                 advance: Advance, max_steps: int | None = LOAD_UPDATE_STEPS) -> np.ndarray:
    """The window re-run from `T_start` (°C per dof, at `start_s`) with `speeds` (one per
    solver step of `step_s`): each stretch of equal speed, in pieces of at most `max_steps`
    (None: whole), solved by `advance` from where the last one ended (`advance` takes its
    loads at the field it is given).  Returns the field after every step, (steps, n_dofs)."""
    out = []
    T = np.asarray(T_start, float)
    for speed, first, n in speed_stretches(speeds, max_steps):
        fields = np.asarray(advance(speed, T, n, start_s + first * step_s), float)
        out.append(fields)
        T = fields[-1]
    return np.vstack(out)
