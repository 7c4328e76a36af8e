"""Thermal load sets: what a window (or a load step) applies, validated on construction."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np


def _finite(value: float, what: str, name: str) -> float:
    """`value` as a float, ValueError naming `what` of `name` unless finite (the message is
    made on failure only: a loop builds a load set every solver step)."""
    if callable(value):  # a field f(r, z): checked where it is evaluated
        return 0.0
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{what} {name!r} must be finite, got {value!r}")
    return value


@dataclass
class ThermalLoads:
    """One set of thermal loads (held constant over a window of time steps).

    sources             region → volumetric heat W/m³
    convection          boundary → (h W/(m²K), T∞ °C)
    flux                boundary → heat flux into the body W/m²
    (source densities, fluxes, bulk and fixed temperatures may also be fields given as
    functions f(r, z) of numpy arrays, like APDL tabular loads)
    contact_resistance  interface → R m²K/W (interfaces not listed are perfectly bonded
                        at a negligible R; see ThermalProblem.PERFECT_CONTACT_R)
    fixed_temperature   boundary → T °C
    fixed_dofs          optional (dof indices, values °C) for point constraints
    """

    sources: dict[str, float] = field(default_factory=dict)
    convection: dict[str, tuple[float, float]] = field(default_factory=dict)
    flux: dict[str, float] = field(default_factory=dict)
    contact_resistance: dict[str, float] = field(default_factory=dict)
    fixed_temperature: dict[str, float] = field(default_factory=dict)
    fixed_dofs: tuple[np.ndarray, np.ndarray] | None = None

    def __post_init__(self) -> None:
        for name, q in self.sources.items():
            _finite(q, "heat source of region", name)
        for name, hc in self.convection.items():
            h, t_inf = hc
            if not (_finite(h, "film coefficient of boundary", name) >= 0.0):
                raise ValueError(f"film coefficient of boundary {name!r} must be ≥ 0, got {h!r}")
            _finite(t_inf, "bulk temperature of boundary", name)
        for name, q in self.flux.items():
            _finite(q, "heat flux of boundary", name)
        for name, r in self.contact_resistance.items():
            if not (_finite(r, "contact resistance of interface", name) > 0.0):
                raise ValueError(f"contact resistance of interface {name!r} must be > 0, got {r!r}")
        for name, t in self.fixed_temperature.items():
            _finite(t, "fixed temperature of boundary", name)


def field_values(
    value: float | Callable[[np.ndarray, np.ndarray], np.ndarray], points: np.ndarray, what: str
) -> np.ndarray:
    """A constant or a field f(r, z) evaluated at points (2, ...), checked finite."""
    if callable(value):
        out = np.asarray(value(points[0], points[1]), dtype=float)
        out = np.broadcast_to(out, points.shape[1:]).astype(float)
    else:
        out = np.full(points.shape[1:], float(value))
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{what}: load field is not finite")
    return out
