"""The boundary values the estimator carries, as log-factors on the twin's nominal values.

A parameter φ multiplies one nominal boundary value by e^φ: φ = 0 is the handbook model,
φ = ln 1.3 a 30 % larger value.  Log space keeps every value positive, makes "30 % too
large" and "30 % too small" symmetric, and lets the filter's Gaussian statistics describe
the ±20–40 % uncertainties of REFERENCE.md §7.  Each parameter has a prior spread (the
uncertainty of its correlation), a random walk per window (how fast the true value may
move: the preload of a bearing swings within minutes, a film correlation does not) and hard
bounds (no physical spindle is outside them).

The tangent operators here give, for a mean temperature T̄ after a backward-Euler step,
∂(right-hand side − A(φ)·T̄)/∂φ_i: the heat a unit log-change of each parameter adds at
every node, which is what the ensemble's perturbations are driven by (`twin.estimation.
forecast`).

One parameter is no factor: `coolant_offset`, the coolant inlet's offset from the inlet
the conditions assume (K, additive: an inlet 2 K below is as likely as 2 K above, and 0 K
is no boundary value to take a logarithm of).  It is estimated only on a run that records
no inlet temperature, where the conditions assume the inlet at the ambient
(`twin.estimation.method`, "Coolant inlet").  Nor are the thermocouples' offsets
(`SENSOR_BIASES`, K, additive and observation-only: what each reads above its metal; the
filter adds them where it compares the field with T1..T5; "Thermocouple offsets" there).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from twin.contract import OPERATING_TEMPERATURE_C
from twin.spindle.conditions import FILM_GROUPS, SIDES, BoundaryConditions

if TYPE_CHECKING:
    from twin.fem import ThermalProblem


@dataclass(frozen=True)
class Parameter:
    """One estimated log-factor.

    name       H_front, H_rear (bearing heat), R_front, R_rear (ring/sleeve contact
               resistance), motor (motor loss), film_<group> (FILM_GROUPS film coefficients),
               expansion (every thermal expansion coefficient: the drift's scale),
               sensor_lag (the thermocouples' time constant: what T1..T5 read of the metal),
               coolant_offset (the coolant inlet's offset, K; `OFFSETS`), bias_T1..bias_T5
               (each thermocouple's offset from its metal, K; `SENSOR_BIASES`)
    prior_sd   spread of the prior in log space (0.2 ≈ ±20 %); an offset's in K
    walk_sd    random-walk spread added per 60 s window, log space; an offset's in K
    bounds     (lowest, highest) factor on the nominal value; an offset's in K
    """

    name: str
    prior_sd: float
    walk_sd: float
    bounds: tuple[float, float]

    @property
    def state_bounds(self) -> tuple[float, float]:
        """The bounds as the filter's state holds the parameter: log-factors, or K."""
        if self.name in OFFSETS:
            return self.bounds
        return math.log(self.bounds[0]), math.log(self.bounds[1])


SENSOR_BIASES: tuple[str, ...] = ("bias_T1", "bias_T2", "bias_T3", "bias_T4", "bias_T5")
"""Each thermocouple's additive offset, K: what it reads above the metal at its nominal point
once the lag has settled (calibration, placement).  Observation-only, in T1..T5's order."""

OFFSETS: frozenset[str] = frozenset({"coolant_offset", *SENSOR_BIASES})
"""Additive parameters (K), not log-factors: the coolant inlet's offset from the inlet the
conditions assume and the thermocouples' offsets.  `factors_of` leaves them out;
`apply_factors` takes the coolant offset apart."""


ALL_PARAMETERS: dict[str, Parameter] = {
    p.name: p
    for p in (
        Parameter("H_front", 0.30, 0.030, (0.3, 3.0)),
        Parameter("H_rear", 0.30, 0.030, (0.3, 3.0)),
        Parameter("R_front", 0.40, 0.030, (0.2, 5.0)),
        Parameter("R_rear", 0.40, 0.030, (0.2, 5.0)),
        Parameter("motor", 0.20, 0.010, (0.4, 2.5)),
        Parameter("film_coolant", 0.25, 0.005, (0.3, 3.0)),
        Parameter("film_housing", 0.25, 0.005, (0.3, 3.0)),
        Parameter("film_air_gap", 0.25, 0.005, (0.3, 3.0)),
        Parameter("film_rotor", 0.25, 0.005, (0.3, 3.0)),
        Parameter("expansion", 0.05, 0.002, (0.7, 1.4)),
        Parameter("sensor_lag", 0.45, 0.01, (0.2, 4.0)),
        Parameter("coolant_offset", 2.5, 0.10, (-8.0, 8.0)),
        *(Parameter(name, 0.15, 0.0, (-3.0, 3.0)) for name in SENSOR_BIASES),
    )
}
"""Every candidate.  Prior spreads follow REFERENCE.md §7 (motor ±20–30 %, films ±20–40 %)
and the paper's corrections (bearing heat and contact resistance moving by tens of %);
sensor_lag's spread spans the 4–20 s of sheathed thermocouples around the assumed 10 s;
coolant_offset's 2.5 K a chiller holding the jacket 1–3 K off the room air, either way;
a thermocouple offset's 0.15 K is narrower than real offsets (±0.5–1 K): the data carry a
0.7 K offset well beyond it where speed changes and stops tell it from the factors, and a
wider prior let the offsets stand in for factors where they do not (`twin.estimation.
method`, "Thermocouple offsets"); no walk (an offset does not move within a run)."""

DEFAULT_PARAMETERS: tuple[str, ...] = (
    "H_front", "H_rear", "R_front", "R_rear", "motor", "film_rotor", "film_coolant", "expansion",
    "sensor_lag",
)
"""The estimator's default set; see `twin.estimation.method` for the sensitivity study."""

DRIFT_ONLY: frozenset[str] = frozenset({"expansion"})
"""Parameters no temperature sees: an effective multiplier on every thermal expansion
coefficient, which scales the nose drift and nothing else.  Only the drift measurement
updates it; without one it keeps its prior (and widens the drift band by it)."""

OBSERVATION_ONLY: frozenset[str] = frozenset({"sensor_lag", *SENSOR_BIASES})
"""Parameters of the sensors, not of the spindle: a factor on the thermocouples' assumed
time constant.  It moves no temperature (no boundary value, no tangent column); the filter
applies it where it compares the field with T1..T5 (`twin.estimation.method`)."""

NOT_THERMAL: frozenset[str] = DRIFT_ONLY | OBSERVATION_ONLY
"""The factors that are no thermal boundary condition (left out of the window's loads)."""


def parameters(names: Sequence[str]) -> tuple[Parameter, ...]:
    """The Parameter of each name (ValueError naming an unknown one)."""
    out = []
    for name in names:
        if name not in ALL_PARAMETERS:
            raise ValueError(
                f"unknown estimated parameter {name!r}; choose from {', '.join(ALL_PARAMETERS)}"
            )
        out.append(ALL_PARAMETERS[name])
    return tuple(out)


def factors_of(names: Sequence[str], log_factors: np.ndarray) -> dict[str, float]:
    """{name: e^φ} for every name but the offsets (names not estimated are absent)."""
    return {n: float(math.exp(v)) for n, v in zip(names, np.asarray(log_factors), strict=True)
            if n not in OFFSETS}


def coolant_offset_of(names: Sequence[str], values: np.ndarray) -> float:
    """The estimated coolant inlet offset, K (0 where it is not estimated)."""
    names = tuple(names)
    return float(values[names.index("coolant_offset")]) if "coolant_offset" in names else 0.0


BOUNDARY_VALUES = ("H_front", "H_rear", "R_front", "R_rear")


def apply_factors(bc: BoundaryConditions, factors: dict[str, float],
                  coolant_offset_K: float = 0.0) -> BoundaryConditions:
    """The conditions with every thermal factor applied (bearing heat, contact, motor,
    films; the expansion and sensor-lag factors are no boundary condition and are left
    out), and the coolant inlet moved by `coolant_offset_K` (kept inside the operating
    range every reader accepts, `twin.contract.OPERATING_TEMPERATURE_C`)."""
    values = {v: getattr(bc, v) * factors[v] for v in BOUNDARY_VALUES if v in factors}
    out = bc.scaled({k: v for k, v in factors.items()
                     if k not in BOUNDARY_VALUES and k not in NOT_THERMAL})
    if coolant_offset_K:
        lo, hi = OPERATING_TEMPERATURE_C
        out = out.with_coolant(min(max(bc.coolant_C + coolant_offset_K, lo), hi))
    return out.with_values(**values) if values else out


class TangentOperators:
    """∂(heat balance of a step)/∂φ for each parameter, at the applied conditions.

    For a backward-Euler step (C/Δt + K(φ)) T⁺ = C/Δt T + f(φ), a log-change δφ moves the
    new temperature by (C/Δt + K)⁻¹ G δφ with G = ∂f/∂φ − ∂K/∂φ T⁺, column by column:

        H_side     H · Σ ∫ v dV over the bearing's regions          (heat added, W)
        motor      Σ q ∫ v dV over rotor and stator
        R_side     (1/R) K_side T⁺                                  (K_side: unit interface)
        film_g     Σ_b∈g h_b (∫ v T∞ dA − M_b T⁺)                   (M_b: unit film matrix)
        coolant_offset  Σ_b h_b ∫ v dA over the coolant boundaries    (per K of the inlet)
        expansion, sensor_lag  0                                    (move no temperature)

    Built once per window from the applied conditions; `columns(T)` is cheap (one sparse
    mat-vec per contact and film parameter).
    """

    def __init__(self, problem: ThermalProblem, bc: BoundaryConditions,
                 names: Sequence[str]) -> None:
        n = problem.n_dofs
        self.names = tuple(names)
        self.constant = np.zeros((n, len(self.names)))
        self.linear: list[tuple[int, sp.csr_matrix]] = []
        interfaces = dict(bc.interfaces)
        for i, name in enumerate(self.names):
            if name in ("H_front", "H_rear"):
                side = name.split("_")[1]
                value = getattr(bc, name)
                for region in bc.bearing_regions[side]:
                    self.constant[:, i] += value * problem.source_vector(region)
            elif name == "motor":
                for region, q in bc.motor_heat.items():
                    self.constant[:, i] += q * problem.source_vector(region)
            elif name in ("R_front", "R_rear"):
                side = name.split("_")[1]
                assert side in SIDES
                op = problem.ops.matrix({f"interface:{interfaces[side]}": 1.0})
                self.linear.append((i, -op / getattr(bc, name)))
            elif name.startswith("film_"):
                group = name[len("film_"):]
                op = None
                for b in FILM_GROUPS[group]:
                    if b not in bc.convection:
                        continue
                    h, t_inf = bc.convection[b]
                    self.constant[:, i] += h * t_inf * problem.facet_load(b)
                    term = h * problem.ops.matrix({f"film:{b}": 1.0})
                    op = term if op is None else op + term
                if op is not None:
                    self.linear.append((i, op))
            elif name == "coolant_offset":
                for b in bc.coolant_boundaries:
                    if b in bc.convection:
                        self.constant[:, i] += bc.convection[b][0] * problem.facet_load(b)
            elif name in NOT_THERMAL:
                pass  # no heat: its column stays zero
            else:
                raise ValueError(f"no tangent operator for parameter {name!r}")

    def columns(self, T: np.ndarray) -> np.ndarray:
        """G (n, p) at the new temperature T (°C), W per unit log-factor."""
        G = self.constant.copy()
        for i, op in self.linear:
            G[:, i] -= op @ T
        return G
