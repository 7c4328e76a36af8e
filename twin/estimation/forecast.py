"""Forecast of one window for the ensemble: the mean by the FEM, the members tangent-linear.

The mean runs the window's backward-Euler steps with the mean log-factors, exactly as the
window deck does.  A member differs from the mean by δT (field) and δφ (log-factors); to
first order in δφ it moves as

    (C/Δt + K(φ̄)) δT⁺ = C/Δt δT + G(T̄⁺) δφ          (G: `TangentOperators.columns`)

so every member reuses one factorization and all N members cost one multi-column
back-substitution per member step (the film and contact parameters would otherwise need one
factorization per member and window).  The neglected second-order terms are the product of
two small perturbations (δφ·δT); with ±30 % factors they change the spread by a few %,
far less than the spread's own sampling error with N ≈ 20–40 members.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from twin.correction.rerun import LOAD_UPDATE_STEPS
from twin.estimation.ensemble import Ensemble
from twin.estimation.parameters import TangentOperators

if TYPE_CHECKING:
    import scipy.sparse as sp

    from twin.fem import ThermalStepper


@dataclass
class WindowForecast:
    """What the ensemble predicts over one window: the mean at every solver step (1..s), the
    members' anomalies at the member steps (0..b: window start and every member step)."""

    sensors_mean_C: np.ndarray  # (s, 5) T1..T5 of the mean
    drift_mean_um: np.ndarray  # (s,) drift_vector_um @ T of the mean (no reference removed)
    sensors_anomalies_C: np.ndarray  # (b + 1, 5, N)
    drift_anomalies_um: np.ndarray  # (b + 1, N) axial nose drift of the members − mean
    end: Ensemble  # field and log-factors at the window end (before any update)
    drift_start_um: float = 0.0  # drift_vector_um @ T of the mean at the window start

    @property
    def substeps(self) -> int:
        """Solver steps per member step."""
        return len(self.drift_mean_um) // (len(self.drift_anomalies_um) - 1)

    def drift_mean_at_members(self) -> np.ndarray:
        """(b + 1,) the mean's drift_vector_um @ T at the window start and every member step."""
        return np.r_[self.drift_start_um, self.drift_mean_um[self.substeps - 1::self.substeps]]

    def spread_at_steps(self, drift_anomalies_um: np.ndarray | None = None
                        ) -> tuple[np.ndarray, np.ndarray]:
        """Member variance of T1..T5 (s, 5) and of the drift (s,) at every solver step,
        linear between member steps (drift anomalies (b + 1, N) other than the field's may
        be given: the estimator's include the expansion factor)."""
        n = self.sensors_anomalies_C.shape[-1]
        var_T = np.sum(self.sensors_anomalies_C**2, axis=-1) / (n - 1)
        d_anom = self.drift_anomalies_um if drift_anomalies_um is None else drift_anomalies_um
        var_d = np.sum(d_anom**2, axis=-1) / (n - 1)
        s, b = len(self.drift_mean_um), len(var_d) - 1
        at = np.arange(1, s + 1) * b / s
        grid = np.arange(b + 1)
        T = np.column_stack([np.interp(at, grid, var_T[:, j]) for j in range(var_T.shape[1])])
        return T, np.interp(at, grid, var_d)


def forecast_window(
    mean_stepper: ThermalStepper,  # the mean's loads, solver Δt
    member_stepper: ThermalStepper,  # the same loads with Δt × substeps
    substeps: int,
    tangent: TangentOperators,
    ensemble: Ensemble,
    sensor_matrix: sp.csr_matrix,  # (5, n)
    drift_vector_um: np.ndarray,
    steps: int,
    stepper_at: Callable[[np.ndarray], ThermalStepper] | None = None,
    update_steps: int = LOAD_UPDATE_STEPS,
) -> WindowForecast:
    """Advance the ensemble `steps` solver steps; log-factors are constant over the window.

    With `stepper_at`, the mean's loads follow its own field: every `update_steps` solver
    steps after the first stretch, its stepper is `stepper_at(T)` at the field reached (the
    nominal bearing heat and contact resistance at the rings' temperatures, as the window's
    deck takes them); the members keep `member_stepper`.

    The members step `substeps` solver steps at a time (backward Euler with the longer
    step): their anomalies are driven by slow parameter errors, and one multi-column solve
    per member step instead of per solver step is what keeps the filter within a few
    seconds per run.  The tangent columns are taken at the mean's field of the same time.
    """
    if steps % substeps:
        raise ValueError(f"{steps} solver steps do not split into member steps of {substeps}")
    T = ensemble.field_mean
    D = ensemble.field_anomalies
    dphi = ensemble.log_factor_anomalies
    n_sensors = sensor_matrix.shape[0]
    blocks = steps // substeps
    s_mean = np.empty((steps, n_sensors))
    d_mean = np.empty(steps)
    s_anom = np.empty((blocks + 1, n_sensors, ensemble.size))
    d_anom = np.empty((blocks + 1, ensemble.size))
    s_anom[0] = sensor_matrix @ D
    d_anom[0] = drift_vector_um @ D
    d_start = float(drift_vector_um @ T)
    explicit = member_stepper.explicit
    for i in range(steps):
        if stepper_at is not None and i > 0 and i % update_steps == 0:
            mean_stepper = stepper_at(T)
        T = mean_stepper.step(T)
        s_mean[i] = sensor_matrix @ T
        d_mean[i] = drift_vector_um @ T
        if (i + 1) % substeps == 0:
            b = (i + 1) // substeps
            D = member_stepper.solve(explicit @ D + tangent.columns(T) @ dphi)
            s_anom[b] = sensor_matrix @ D
            d_anom[b] = drift_vector_um @ D
    end = Ensemble(T, D, ensemble.log_factor_mean.copy(), dphi.copy())
    return WindowForecast(s_mean, d_mean, s_anom, d_anom, end, d_start)
