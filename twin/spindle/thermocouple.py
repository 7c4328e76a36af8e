"""What a thermocouple reads of the metal it sits in: a first-order lag.

A sheathed thermocouple in a bore follows the metal with a time constant τ of a few to
tens of seconds (its mass and the contact conductance), τ dy/dt = x − y.  The twin's field
is the metal; what the test stand logs is y.  The estimator compares its forecast with the
logged samples through this lag and reports T1..T5 as readings (`twin.estimation.method`).
"""

from __future__ import annotations

import numpy as np


def thermocouple_reading(time_s: np.ndarray, metal_C: np.ndarray, lag_s: float,
                         start_C: np.ndarray | None = None) -> np.ndarray:
    """The readings y (rows at `time_s`, s) of metal temperatures x (°C, one row per time,
    sensors in columns) through τ dy/dt = x − y with τ = `lag_s`; y starts at `start_C`
    (None: settled, y = x at the first row).  Exact for x linear between the rows; τ ≤ 0
    reads the metal itself."""
    x = np.asarray(metal_C, float)
    if lag_s <= 0:
        return x.copy()
    y = np.empty_like(x)
    y[0] = x[0] if start_C is None else start_C
    for i in range(1, len(x)):
        h = float(time_s[i] - time_s[i - 1])
        a = np.exp(-h / lag_s)
        # x linear over the step: y⁺ = a·y + (1 − a)·x⁺ − τ(1 − a − h/τ·a)·(x⁺ − x)/h
        slope = (x[i] - x[i - 1]) / h if h > 0 else 0.0
        y[i] = a * y[i - 1] + (1 - a) * x[i] - lag_s * (1 - a) * slope + h * a * slope
    return y
