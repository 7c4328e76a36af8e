"""θ-method time stepping of the heat equation with a fixed Δt and fixed loads.

    (C/Δt + θK) T⁺ = (C/Δt − (1 − θ)K) T + f        θ = 1 backward Euler, ½ Crank–Nicolson

    stepper = problem.transient(loads, dt=4.0)
    for T in stepper.march(T, 15):       # like scikit-fem's ex19 `evolve`
        ...

The problem (`ThermalProblem.transient`) assembles and factorizes; the stepper holds only
what a step needs and never touches the problem's operators.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Protocol

import numpy as np
import scipy.sparse as sp

from twin.fem.balance import HeatBalance


class Solver(Protocol):
    def solve(self, rhs: np.ndarray) -> np.ndarray: ...


class ThermalStepper:
    """Steps of one load set: one back-substitution each.

    solver    factorized C/Δt + θK (prescribed temperatures eliminated)
    explicit  C/Δt − (1 − θ)K, W/K
    load      f, W
    balance   builds the step's `HeatBalance` (on first use only: most loops never ask)
    """

    def __init__(
        self,
        solver: Solver,
        explicit: sp.csr_matrix,
        load: np.ndarray,
        dt: float,
        theta: float,
        balance: Callable[[], HeatBalance],
    ) -> None:
        self.dt, self.theta = dt, theta
        self._solver, self._explicit, self.f = solver, explicit, load
        self._make_balance = balance
        self._balance: HeatBalance | None = None

    @property
    def explicit(self) -> sp.csr_matrix:
        """C/Δt − (1 − θ)K (W/K): what multiplies the old temperature on the right-hand side."""
        return self._explicit

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """(C/Δt + θK)⁻¹ rhs for one (n,) or, without prescribed temperatures, several (n, m)
        right-hand sides (W → K).  Several columns share the factorization: an ensemble of
        tangent-linear perturbations costs one multi-column back-substitution per step."""
        return self._solver.solve(rhs)

    def step(self, T: np.ndarray) -> np.ndarray:
        """Advance one Δt from nodal temperature T (°C)."""
        return self._solver.solve(self._explicit @ T + self.f)

    def march(self, T: np.ndarray, n: int) -> Iterator[np.ndarray]:
        """Yield the temperature after each of `n` steps from T (°C); T is not modified."""
        for _ in range(n):
            T = self.step(T)
            yield T

    def energy_balance(self, T_old: np.ndarray, T_new: np.ndarray) -> dict[str, float]:
        """Heat balance of the step T_old → T_new, W (see `twin.fem.balance`)."""
        if self._balance is None:
            self._balance = self._make_balance()
        return self._balance(T_old, T_new)
