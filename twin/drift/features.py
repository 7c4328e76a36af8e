"""Causal dynamic features of temperatures and speed.

A thermal drift lags the temperatures a sensor sees (heat still flows into parts the
sensors do not see), so besides the temperature rises the features hold first-order-lagged
copies of them at a few time constants, and the speed history through the same filters
(the heat input, where the sensors sit far from the sources).  Every feature at a row
depends on that row and earlier rows of the same file only (causal), so `predict` can run
online.

Feature groups (names in `FeatureSpec.names`):
  rise      T − T_ref                           one per sensor, °C
  lag<τ>    first-order lag of T − T_ref, τ min  one per sensor and time constant, °C
  speed     n/1000 and (n/1000)², krpm, krpm²     (heat ∝ n to n²)
  speed_lag<τ>  their first-order lags
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from twin.lag import first_order_lag

DEFAULT_TAUS_MIN: tuple[float, ...] = (10.0, 30.0, 90.0)
"""Lag time constants (min); the published ridge baseline uses 10/30/90 min (REFERENCE §8)."""

GROUPS = ("rise", "lag", "speed")


@dataclass(frozen=True)
class FeatureSpec:
    """What a model's feature matrix is made of (stored in the model file as JSON)."""

    sensors: tuple[str, ...]
    reference_C: tuple[float, ...]
    taus_min: tuple[float, ...] = DEFAULT_TAUS_MIN
    groups: tuple[str, ...] = GROUPS

    def __post_init__(self) -> None:
        unknown = set(self.groups) - set(GROUPS)
        if unknown:
            raise ValueError(f"unknown feature groups {sorted(unknown)}")
        if len(self.reference_C) != len(self.sensors):
            raise ValueError("one reference temperature per sensor")

    @property
    def uses_speed(self) -> bool:
        return "speed" in self.groups

    @property
    def names(self) -> list[str]:
        out: list[str] = []
        if "rise" in self.groups:
            out += [f"{s}:rise" for s in self.sensors]
        if "lag" in self.groups:
            out += [f"{s}:lag{tau:g}min" for tau in self.taus_min for s in self.sensors]
        if "speed" in self.groups:
            out += ["speed_krpm", "speed_krpm2"]
            out += [f"{n}:lag{tau:g}min" for tau in self.taus_min
                    for n in ("speed_krpm", "speed_krpm2")]
        return out

    def to_json(self) -> dict:
        return {k: list(v) for k, v in asdict(self).items()}

    @classmethod
    def from_json(cls, doc: dict) -> FeatureSpec:
        return cls(sensors=tuple(doc["sensors"]),
                   reference_C=tuple(float(v) for v in doc["reference_C"]),
                   taus_min=tuple(float(v) for v in doc["taus_min"]),
                   groups=tuple(doc["groups"]))


def _lagged(x: np.ndarray, time_s: np.ndarray, taus_s: np.ndarray,
            segment_starts: np.ndarray | None = None) -> np.ndarray:
    """First-order lags of every column of x (n, m) at every τ of `taus_s` (s) → (n, k·m),
    τ-major; each sample is held over the step that ends at it (`twin.lag`), so y[i] uses
    x[0..i] only; y starts at x at the first row of every segment."""
    x = np.asarray(x, dtype=float).reshape(len(time_s), -1)
    y = first_order_lag(x, time_s, np.asarray(taus_s, dtype=float), between="held",
                        segment_starts=segment_starts)
    return y.reshape(len(time_s), -1)


def reference_temperatures(T_C: np.ndarray, n_rows: int = 20) -> np.ndarray:
    """The reference of the rises: the mean of the first rows (a machine at rest)."""
    return np.mean(T_C[: max(1, n_rows)], axis=0)


def dynamic_features(spec: FeatureSpec, time_s: np.ndarray, T_C: np.ndarray,
                     speed_rpm: np.ndarray | None,
                     segment_starts: np.ndarray | None = None) -> np.ndarray:
    """The feature matrix (n, len(spec.names)) for columns T_C of `spec.sensors`."""
    rise = np.asarray(T_C, dtype=float) - np.asarray(spec.reference_C)[None, :]
    taus_s = 60.0 * np.asarray(spec.taus_min)
    blocks = []
    if "rise" in spec.groups:
        blocks.append(rise)
    if "lag" in spec.groups:
        blocks.append(_lagged(rise, time_s, taus_s, segment_starts))
    if "speed" in spec.groups:
        if speed_rpm is None:
            raise ValueError("the features need speed_rpm")
        krpm = np.asarray(speed_rpm, dtype=float)[:, None] / 1000.0
        s = np.hstack([krpm, krpm**2])
        blocks += [s, _lagged(s, time_s, taus_s, segment_starts)]
    return np.hstack(blocks)
