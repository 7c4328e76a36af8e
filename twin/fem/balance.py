"""The discrete heat balance of a θ-step under fixed loads, W.

With the step (C/Δt)(T⁺ − T) + K T_θ = f, T_θ = θT⁺ + (1 − θ)T, summing every equation
(1ᵀ·) gives the global balance

    stored = sources + flux + fixed_in − convection_out

exactly for the discrete solution: the conduction and contact terms cancel (their rows
sum to zero) and only the film terms and the rows of prescribed dofs remain.  All of it
reduces to a few dot products with vectors prepared once per load set.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class HeatBalance:
    """Balance of one step; built by `ThermalProblem.heat_balance`.

    capacity           C·1, J/K per dof
    film               Σ h M_film·1 over convective boundaries, W/K per dof
    film_load_W        Σ h ∫ T∞ v 2πr ds (the film's sink term)
    fixed_capacity     1_Dᵀ C over the prescribed dofs D (J/K per dof), None without any
    fixed_conductance  1_Dᵀ K (W/K per dof)
    fixed_load_W       Σ_D f
    """

    dt: float
    theta: float
    capacity: np.ndarray
    sources_W: float
    flux_W: float
    film: np.ndarray
    film_load_W: float
    fixed_capacity: np.ndarray | None = None
    fixed_conductance: np.ndarray | None = None
    fixed_load_W: float = 0.0

    def __call__(self, T_old: np.ndarray, T_new: np.ndarray) -> dict[str, float]:
        """Terms of the step T_old → T_new (°C), W.

        `residual_W` is what is left, round-off for an exact linear solve.
        `heat_in_W` = sources + flux, `heat_out_W` = convection out + heat drawn by fixed
        temperatures.
        """
        theta = self.theta
        T_theta = T_new if theta == 1.0 else theta * T_new + (1.0 - theta) * T_old
        dT = T_new - T_old
        stored = float(self.capacity @ dT) / self.dt
        convection_out = float(self.film @ T_theta) - self.film_load_W
        fixed_in = 0.0
        if self.fixed_capacity is not None:
            fixed_in = (
                float(self.fixed_capacity @ dT) / self.dt
                + float(self.fixed_conductance @ T_theta)
                - self.fixed_load_W
            )
        heat_in = self.sources_W + self.flux_W
        return {
            "sources_W": self.sources_W,
            "flux_W": self.flux_W,
            "convection_out_W": convection_out,
            "fixed_in_W": fixed_in,
            "stored_W": stored,
            "heat_in_W": heat_in,
            "heat_out_W": convection_out - fixed_in,
            "residual_W": heat_in + fixed_in - convection_out - stored,
        }
