"""What a correction method returns for one window (`Correction`) and the method protocol.

A `Correction` unpacks like the 4-tuple (H_front, H_rear, R_front, R_rear) and also carries
the factors C_H and C_C on the previous window's values carried to this window's nominal
level, for `corrections.csv`.  An
estimator (`twin.estimation`) may also set model-form factors (motor loss, film groups), the
analysed field the window starts from, and the spread of its forecast.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from twin.correction.features import BoundaryValues, WindowFeatures, correction_factors


@dataclass(frozen=True)
class Correction:
    """Boundary values for one window (W/m³, m²K/W) and their factors on the previous window."""

    H_front_W_m3: float
    H_rear_W_m3: float
    R_front_m2K_W: float
    R_rear_m2K_W: float
    C_H: tuple[float, float] = (1.0, 1.0)
    """(front, rear) heat of this window / heat of the previous window."""
    C_C: tuple[float, float] = (1.0, 1.0)
    """(front, rear) resistance of this window / resistance of the previous window."""
    factors: Mapping[str, float] = field(default_factory=dict)
    """Further estimated multipliers on nominal values: `motor` (motor loss),
    `film_<group>` (twin.spindle.conditions.FILM_GROUPS) and `expansion` (every thermal
    expansion coefficient).  The loop applies the thermal ones to the window's conditions
    (so they are in the deck) and scales the window's displacements by `expansion`;
    corrections.csv lists them all."""
    state_C: np.ndarray | None = field(default=None, repr=False, compare=False)
    """The analysed temperature field (°C per dof) the window starts from; None: the loop's
    own field, carried over from the previous window."""
    band_sd: np.ndarray | None = field(default=None, repr=False, compare=False)
    """(steps, 6) forecast spread (1 σ) at each solver step of the window: T1..T5 in °C
    (measurement noise included) and the axial nose drift in µm; None: no uncertainty."""
    readings_start_C: np.ndarray | None = field(default=None, repr=False, compare=False)
    """(5,) what T1..T5's thermocouples read at the window start, °C: the loop then reports
    T1..T5 as the readings of the window's metal temperatures at their points through the
    first-order lag `sensor_lag_s` (`twin.lag`).  None: the metal."""
    sensor_lag_s: float = 0.0
    """The thermocouples' time constant, s (a method that estimates it; 0: not estimated)."""
    sensor_offset_C: np.ndarray | None = field(default=None, repr=False, compare=False)
    """(5,) what each thermocouple reads above its metal once its lag has settled, K
    (calibration, placement; a method that estimates it): added to T1..T5 as reported
    (with `readings_start_C`: to the readings).  None: no offset."""
    loads_follow_rings: bool = False
    """The window's bearing heat and contact resistance follow the twin's own ring and
    sleeve temperatures every solver step (`twin.correction.rerun.LOAD_UPDATE_STEPS`), as the
    spindle's do: the values above are then factors on the nominal values at the window's
    start field, re-applied to the nominal values at each piece's start (every method's
    default, `twin.loop.replay`).  False: the values held for the whole window, the paper's
    literal per-window boundary conditions (one load step per deck)."""
    coolant_C: float | None = None
    """The coolant inlet temperature the method estimated for the window, °C (the
    estimator, on a run that records none): the loop runs the window's deck with it.
    None: the recorded inlet, or the ambient where the run records none."""

    @property
    def values(self) -> BoundaryValues:
        return BoundaryValues(
            self.H_front_W_m3, self.H_rear_W_m3, self.R_front_m2K_W, self.R_rear_m2K_W
        )

    def __iter__(self) -> Iterator[float]:
        return iter(self.values)

    @classmethod
    def relative_to(
        cls, values: BoundaryValues | np.ndarray, previous: BoundaryValues, **extra: object
    ) -> Correction:
        """These values with C_H, C_C on `previous` (1 where that was 0: a stop);
        `extra`: factors, state_C, band_sd, readings_start_C, sensor_lag_s,
        sensor_offset_C, coolant_C.
        The methods give the previous window's values carried to this window's nominal
        level (`WindowFeatures.carried_previous`), the H' and R' of Eq. 3 and Eq. 6: a
        speed change moves the nominal heat, not the correction (on the previous values
        themselves every method, open loop too, showed C_H 1.82 at a speed step)."""
        v = [float(x) for x in values]
        c = [float(x) for x in correction_factors(v, previous)]
        return cls(*v, C_H=(c[0], c[1]), C_C=(c[2], c[3]), **extra)


class Corrector(Protocol):
    """Anything that turns a window's features into its four boundary values."""

    name: str

    def correct(self, features: WindowFeatures) -> Correction: ...
