"""Time tables: a value given at a few times, read at any time.

`TimeTable` interpolates linearly (scenario tables: factors, coolant, ambient drift);
`StepTable` holds each value until the next time (speed profiles: a commanded speed).
Both hold their end values outside the table.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Self

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class _Breakpoints:
    """Values (any unit) at strictly increasing, finite times `time_s` (s)."""

    time_s: np.ndarray
    values: np.ndarray
    kind: ClassVar[str] = "table"
    """What the table is called in its error messages."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "time_s", np.asarray(self.time_s, dtype=float))
        object.__setattr__(self, "values", np.asarray(self.values, dtype=float))
        time_s, values, what = self.time_s, self.values, self.kind
        if time_s.ndim != 1 or time_s.size == 0:
            raise ValueError(f"{what}: time_s must be a non-empty list")
        if values.shape != time_s.shape:
            raise ValueError(f"{what}: {values.size} values for {time_s.size} times")
        if not (np.isfinite(time_s).all() and np.isfinite(values).all()):
            raise ValueError(f"{what}: times and values must be finite numbers")
        if np.any(np.diff(time_s) <= 0):
            raise ValueError(f"{what}: time_s must be strictly increasing")

    @classmethod
    def constant(cls, value: float) -> Self:
        """The table that is `value` at every time."""
        return cls(np.array([0.0]), np.array([float(value)]))


@dataclass(frozen=True)
class TimeTable(_Breakpoints):
    """Piecewise-linear function of time (s), constant beyond its ends."""

    kind: ClassVar[str] = "time table"

    def __call__(self, t: ArrayLike) -> np.ndarray:
        return np.interp(np.asarray(t, dtype=float), self.time_s, self.values)

    def shifted(self, offset: float) -> TimeTable:
        """The same table with `offset` added to every value."""
        return TimeTable(self.time_s, self.values + offset)


@dataclass(frozen=True)
class StepTable(_Breakpoints):
    """Piecewise-constant function of time: each value holds until the next time."""

    kind: ClassVar[str] = "step table"

    def __call__(self, t: ArrayLike) -> np.ndarray:
        i = np.searchsorted(self.time_s, np.asarray(t, dtype=float), side="right") - 1
        return self.values[np.clip(i, 0, self.values.size - 1)]

    def changes_in(self, t0: float, t1: float) -> np.ndarray:
        """Times in (t0, t1) where the value changes (solver steps should break there)."""
        inside = (self.time_s > t0) & (self.time_s < t1)
        return self.time_s[inside]
