"""The first-order lag τ·y' + y = x, sampled: the one implementation in the twin.

Three parts of the twin lag a signal this way, and all call `first_order_lag`:
  - a thermocouple in a bore follows its metal with a time constant of a few to tens of
    seconds (its mass and the contact conductance): the emulator's recorded T1..T5
    (`twin.plant.emulator`) and the estimator's readings (`twin.estimation.method`,
    `twin.loop.replay`); the emulated X/Y tilt follows the housing (`twin.plant.truth`).
    The input is linear between rows (the field between time steps);
  - the drift models' lagged features (`twin.drift.features`): a causal filter of logged
    samples, each held over the step that ends at it, restarted at every file's start.

The module sits at the top of the package and imports numpy and scipy only, so the
plant, the estimator and the drift models share it without depending on each other
(`twin.drift` must not import `twin.plant`).

Over a step h = t₁ − t₀, with w = 1 − exp(−h/τ) the weight of the new sample,
    y₁ = y₀ + w·(x₁ − y₀) − c·(x₁ − x₀)
exactly: c = 0 for x held at x₁ over the step, c = τ·w/h − (1 − w) for x linear over it
(the ramp within the step lags by less than its end value; c → 0 as h → 0, so a jump of
x in no time does not move y).  One recursion, two ways to run it:
  - constant steps and the linear form as a linear filter (scipy.signal.lfilter: the
    emulator's truth over long runs, many columns);
  - otherwise row by row.  The held form always runs so: the drift models were fitted on
    its exact rounding, and their network fits are chaotic in it (run as a filter, the
    features of examples/real moved by 1e-13 and a refit's validation RMSE by up to
    0.4 µm on a probe), so the drift features stay bit for bit what they were.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from scipy.signal import lfilter

CONSTANT_STEP_RTOL = 1e-9
"""Steps equal to this relative tolerance count as constant (the filter then uses their
mean: a change of exp(−h/τ) far below the rounding of any logged value)."""


def first_order_lag(x: np.ndarray, time_s: np.ndarray, tau_s: float,
                    start: np.ndarray | float | None = None, *,
                    between: Literal["linear", "held"] = "linear",
                    segment_starts: np.ndarray | None = None) -> np.ndarray:
    """The response y of τ·y' + y = x to samples x at times `time_s` (s), τ = `tau_s` (s).

    x: (n, ...) along axis 0, any unit; y has its shape and unit.  `between`: "linear"
    (exact for x linear between rows) or "held" (exact for x held at each row's value
    over the step that ends at it: y[i] = y[i−1] + (1 − exp(−Δt/τ))·(x[i] − y[i−1])).
    y starts at `start` (None: settled, y = x at the first row).  `segment_starts`: rows
    where the signal starts anew (separate records): y = x there.  τ ≤ 0: y = x.
    """
    x = np.asarray(x, dtype=float)
    time_s = np.asarray(time_s, dtype=float)
    if time_s.shape != x.shape[:1]:
        raise ValueError(f"time_s has {time_s.shape} rows, x {x.shape[:1]}")
    if between not in ("linear", "held"):
        raise ValueError(f"between must be 'linear' or 'held', not {between!r}")
    if tau_s <= 0.0 or x.shape[0] == 0:
        return x.copy()
    bounds = {0, x.shape[0]}
    if segment_starts is not None:
        bounds |= {int(i) for i in np.asarray(segment_starts, dtype=np.int64)}
    bounds_sorted = sorted(bounds)
    y = np.empty_like(x)
    for k, (lo, hi) in enumerate(zip(bounds_sorted[:-1], bounds_sorted[1:], strict=True)):
        y[lo] = x[lo] if start is None or k > 0 else start
        _record(x[lo:hi], time_s[lo:hi], float(tau_s), between, y[lo:hi])
    return y


def _record(x: np.ndarray, time_s: np.ndarray, tau_s: float, between: str,
            y: np.ndarray) -> None:
    """Fill y[1:] of one record from y[0] (rows of x at `time_s`)."""
    if x.shape[0] < 2:
        return
    h = np.diff(time_s)
    constant = between == "linear" and np.ptp(h) <= CONSTANT_STEP_RTOL * abs(h[0])
    if constant:
        h = np.full(1, h.mean())
    w = -np.expm1(-h / tau_s)
    trailing = (1,) * (x.ndim - 1)
    if between == "held":
        w = w.reshape(-1, *trailing)
        for i in range(1, x.shape[0]):
            y[i] = y[i - 1] + w[i - 1] * (x[i] - y[i - 1])
        return
    ramp = np.divide(tau_s * w, h, out=np.ones_like(h), where=h != 0) - (1.0 - w)
    drive = np.diff(x, axis=0) * ramp.reshape(-1, *trailing)
    if constant:
        # y₁ = (1 − w)·y₀ + (w·x₁ − c·Δx)
        y[1:], _ = lfilter([1.0], [1.0, w[0] - 1.0], w[0] * x[1:] - drive, axis=0,
                           zi=(1.0 - w[0]) * y[:1])
        return
    w = w.reshape(-1, *trailing)
    for i in range(1, x.shape[0]):
        y[i] = y[i - 1] + w[i - 1] * (x[i] - y[i - 1]) - drive[i - 1]
