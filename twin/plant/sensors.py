"""What the test stand's sensors do to the truth: thermocouple lag, noise, faults.

The truth temperatures are what the metal does; a thermocouple in a bore follows with a
first-order lag (time constant `lag_s`), the logger adds white noise, and some channels
fail (frozen at their first value, dropouts logged as NaN, spikes from interference).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter

from twin.plant.scenario import Faults


def first_order_lag(x: np.ndarray, dt: float, tau: float, y0: np.ndarray | None = None
                    ) -> np.ndarray:
    """Response y of τ·y' + y = x to samples x (constant Δt, x linear between samples).

    Exact for piecewise-linear input: with a = exp(−Δt/τ) and slope m = (x₁ − x₀)/Δt,
    y₁ = x₁ + a·(y₀ − x₀) − m·τ·(1 − a).  Works along axis 0; y starts at `y0`
    (default x[0], a sensor in equilibrium with its surroundings).
    """
    x = np.asarray(x, dtype=float)
    if tau <= 0.0 or x.shape[0] < 2:
        return x.copy()
    a = np.exp(-dt / tau)
    b = tau * (1.0 - a) / dt
    y_start = x[0] if y0 is None else np.asarray(y0, dtype=float)
    # e = y − x obeys e₁ = a·e₀ − b·(x₁ − x₀): a first-order recursion driven by Δx
    drive = -b * np.diff(x, axis=0)
    e0 = (y_start - x[0]) * np.ones_like(x[0])
    e_rest, _ = lfilter([1.0], [1.0, -a], drive, axis=0, zi=a * np.asarray(e0)[None, ...])
    e = np.concatenate([np.asarray(e0)[None, ...], e_rest], axis=0)
    return x + e


def add_noise(rng: np.random.Generator, x: np.ndarray, sigma: float) -> np.ndarray:
    """White Gaussian noise of standard deviation `sigma` (same unit as x)."""
    if sigma <= 0.0:
        return x.copy()
    return x + rng.normal(0.0, sigma, size=x.shape)


def apply_faults(time_s: np.ndarray, columns: dict[str, np.ndarray], faults: Faults
                 ) -> dict[str, np.ndarray]:
    """Stuck channels (frozen at their first value), spikes, then dropouts (NaN).

    Faults on a column that is not recorded are ignored.
    """
    out = {name: values.copy() for name, values in columns.items()}
    for name in faults.stuck:
        if name in out:
            out[name][:] = out[name][0]
    for spike in faults.spikes:
        if spike.sensor in out:
            i = int(np.argmin(np.abs(time_s - spike.time_s)))
            out[spike.sensor][i] += spike.size
    for drop in faults.dropouts:
        if drop.sensor in out:
            out[drop.sensor][(time_s >= drop.start_s) & (time_s <= drop.end_s)] = np.nan
    return out
