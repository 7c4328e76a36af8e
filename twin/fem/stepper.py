"""θ-method time stepping of the heat equation C dT/dt + K T = f.

    (C/Δt + θK₁) T₁ = (C/Δt − (1 − θ)K₀) T₀ + θ f₁ + (1 − θ) f₀
    θ = 1 backward Euler, ½ Crank–Nicolson; index 0 the start of the step, 1 its end

`ThermalStepper` is the form for fixed operators and loads (K₀ = K₁, f₀ = f₁): the left
side is factorized once and a step is one back-substitution::

    stepper = problem.transient(loads, dt=4.0)
    for T in stepper.march(T, 15):       # like scikit-fem's ex19 `evolve`
        ...

The problem (`ThermalProblem.transient`) assembles and factorizes; the stepper holds only
what a step needs and never touches the problem's operators.

`theta_step` is the general form, for a system assembled by the caller at each end of the
step: loads that change in time, and k(T), ρc(T) by Picard iteration (`picard`).
`march_to` strings such steps from t0 to t1, at a fixed Δt or with the step size chosen
from a step-doubling estimate of the local error, bisected when it is too large
(`StepControl`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import NamedTuple, Protocol

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


PICARD_TOLERANCE = 1e-8
"""Picard iteration stops when no temperature changed by more than this × (1 + max |T|)."""
PICARD_ITERATIONS = 200
MAX_SUBSTEPS = 200_000


class SteppingError(RuntimeError):
    """A time integration that cannot finish: Picard iteration not converging, or more
    substeps than `MAX_SUBSTEPS` (the caller names the problem it was solving)."""


class ThetaSystem(NamedTuple):
    """C dT/dt + K T = f at one state: K conductance (W/K), C capacity (J/K), f load (W)."""

    K: sp.csr_matrix
    C: sp.csr_matrix
    f: np.ndarray


def picard(update: Callable[[np.ndarray], np.ndarray], T0: np.ndarray,
           iterate: bool = True) -> np.ndarray:
    """The fixed point T = update(T) from T0 (°C), or one update when not `iterate` (a
    linear problem); converged when the largest change is at most `PICARD_TOLERANCE` ×
    (1 + max |T|)."""
    T = T0
    for _ in range(PICARD_ITERATIONS if iterate else 1):
        T_new = update(T)
        change = float(np.max(np.abs(T_new - T))) if T.size else 0.0
        T = T_new
        if not iterate or change <= PICARD_TOLERANCE * (1.0 + float(np.max(np.abs(T)))):
            return T
    raise SteppingError(f"did not converge in {PICARD_ITERATIONS} Picard iterations")


def theta_step(
    T: np.ndarray,
    dt: float,
    theta: float,
    start: ThetaSystem,
    end_at: Callable[[np.ndarray], ThetaSystem],
    solve: Callable[[sp.csr_matrix, np.ndarray], np.ndarray],
    iterate: bool,
    capacity: Callable[[np.ndarray], sp.csr_matrix] | None = None,
) -> np.ndarray:
    """One θ-step of Δt (s) from T (°C): `start` is the system at the start of the step,
    `end_at(T₁)` the system at its end assembled at temperature T₁, `solve(A, rhs)` solves
    with the prescribed temperatures of the end.  With `iterate` (properties depending on
    T) the end is re-assembled at each Picard iterate and C is the mean of both ends'.
    `capacity(T₁)`, when given, is the step's C (J/K) instead: e.g. an enthalpy secant
    (H(T₁) − H(T)) / (T₁ − T), so a step across a phase change takes in its latent heat."""
    K0, C0, f0 = start

    def update(T1: np.ndarray) -> np.ndarray:
        K1, C1, f1 = end_at(T1)
        if capacity is not None:
            C = capacity(T1)
        else:
            C = 0.5 * (C0 + C1) if iterate else C0
        A = C / dt + theta * K1
        rhs = C @ T / dt - (1.0 - theta) * (K0 @ T) + theta * f1 + (1.0 - theta) * f0
        return solve(A.tocsr(), rhs)

    return picard(update, T, iterate)


OPEN_UP_FACTOR = 3.0
"""The most a substep may grow over the previous one under `StepControl`: MAPDL's
OPNCONTROL,OPENUPFACTOR default for thermal analyses."""


BISECTION_RATIO = 2.0
"""Under `StepControl` a substep whose error estimate exceeds this × the tolerance is redone
at half the size (time step bisection); within it the estimate only predicts the next size."""


@dataclass(frozen=True)
class StepControl:
    """Automatic time stepping as MAPDL's AUTOTS documents it: time step *prediction*
    (each next size from the last step's response) and *bisection* (a substep redone with
    half the size).  The response measured is the step-doubling estimate of the substep's
    local error (one step of h against two of h/2, the largest nodal difference), against
    `tolerance` × the temperature range of the problem: `scale` (°C, what its loads and
    start span) or, when wider, the range its temperatures have reached in the substeps
    kept so far (a heat-driven rise), and at least 1 °C.  A smooth response grows the
    size, at most `growth` times a step; a substep whose estimate exceeds
    `BISECTION_RATIO` × the tolerance, or whose iteration does not converge, is bisected.
    Sizes stay within [dt_min, dt_max] (s)."""

    dt_min: float
    dt_max: float
    tolerance: float
    scale: float = 1.0
    growth: float = OPEN_UP_FACTOR


def _next_size(h: float, remaining: float, dt_min: float) -> float:
    """The next substep from the predicted size `h` so that the substeps land on the load
    step's end: the rest in one substep when it fits, in two equal ones when it is less than
    two (rather than a sliver after a full one), unless a half would be below dt_min."""
    if remaining <= h:
        return remaining
    if remaining < 2.0 * h and 0.5 * remaining >= dt_min:
        return 0.5 * remaining
    return h


def march_to(
    step: Callable[[np.ndarray, float, float, float], np.ndarray],
    T0: np.ndarray,
    t0: float,
    t1: float,
    dt: float,
    control: StepControl | None = None,
) -> tuple[list[float], list[np.ndarray]]:
    """Steps from time t0 to t1 (s): `step(T, t, t_next, h)` advances T by h = t_next − t.
    Without `control` every step is `dt` (the last one shortened to land on t1).  With it
    the first substep is `dt` (DELTIM's DTIME is "the starting time substep": bisected only
    when it does not converge), each substep is taken as one step of h and two of h/2 (the
    two halves are kept), and their difference, the local error estimate, predicts the next
    h or bisects the substep (`StepControl`); at dt_min a substep is kept as it is, or, when
    it does not converge, the `SteppingError` goes out.  Returns the end time and
    temperature of every step; the last time is t1 exactly."""
    times: list[float] = []
    temps: list[np.ndarray] = []
    t, T = t0, T0
    h = dt
    low = float(np.min(T0)) if T0.size else 0.0
    high = float(np.max(T0)) if T0.size else 0.0
    while t < t1 - 1e-12 * max(1.0, abs(t1)):
        if len(times) >= MAX_SUBSTEPS:
            raise SteppingError(f"more than {MAX_SUBSTEPS} substeps in one load step")
        if control is None:
            h = min(h, t1 - t)
            T = step(T, t, t + h, h)
            t += h
            times.append(t)
            temps.append(T)
            continue
        h = _next_size(h, t1 - t, control.dt_min)
        at_min = h <= control.dt_min * (1 + 1e-9)
        try:
            full = step(T, t, t + h, h)
            half = step(T, t, t + 0.5 * h, 0.5 * h)
            half = step(half, t + 0.5 * h, t + h, 0.5 * h)
        except SteppingError:
            if at_min:
                raise
            h = max(control.dt_min, 0.5 * h)  # bisection
            continue
        error = float(np.max(np.abs(full - half))) if half.size else 0.0
        tolerance = control.tolerance * max(control.scale, high - low, 1.0)
        if error > BISECTION_RATIO * tolerance and times and not at_min:
            h = max(control.dt_min, 0.5 * h)  # bisection
            continue
        if half.size:
            low, high = min(low, float(np.min(half))), max(high, float(np.max(half)))
        t += h
        T = half  # the more accurate of the two
        times.append(t)
        temps.append(T)
        # local error ∝ h² (θ = 1) or h³ (θ = ½): the square root is the cautious guess
        factor = control.growth if error == 0.0 else 0.9 * np.sqrt(tolerance / error)
        h = min(control.dt_max, max(control.dt_min, h * min(control.growth, factor)))
    if times:
        times[-1] = t1
    return times, temps
