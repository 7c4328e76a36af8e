"""What the test stand's sensors do to the truth: thermocouple lag, calibration offsets,
noise, faults.

The truth temperatures are what the metal does; a thermocouple in a bore follows with a
first-order lag (time constant `lag_s`, `twin.lag`), reads it off by its calibration
offset, the logger adds white noise, and some channels fail (frozen at their first value,
dropouts logged as NaN, spikes from interference).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from twin.plant.scenario import Faults


def calibrated_reading(offset_C: Mapping[str, float]
                       ) -> Callable[[str, np.ndarray], np.ndarray]:
    """`read(column, metal_C)`: what a channel with the scenario's calibration offsets
    (K, by run column) reads of its metal temperature; a channel without one reads it
    exactly (the very array: a run without offsets stays byte for byte as it was)."""

    def read(column: str, metal_C: np.ndarray) -> np.ndarray:
        offset = offset_C.get(column)
        return metal_C if offset is None else metal_C + offset

    return read


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
