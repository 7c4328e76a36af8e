"""Sensitivity and observability of the candidate log-factors, with the twin model itself.

For a run at constant speed from a cold start, the Jacobian J of the sensor trajectories
(T1..T5 every 60 s) with respect to each log-factor φ_i (forward differences of δφ = 0.05
on the nominal FEM run) says how strongly the thermocouples see a parameter; scaled by the
observation error σ, the singular values of J/σ say how many independent combinations the
data pin down (a singular value below 1 is a direction the data cannot tell from noise), and
the singular vectors which parameters are confounded.  The axial nose drift's sensitivity
says which parameters matter for the deformation the twin must predict.

The coolant inlet's offset (`coolant_offset`, additive) is differenced by δ K instead: its
sensitivities are per K.  For it the report also gives the cosine of its column with every
other and the RMS of its column left after a least-squares fit by all the others: what no
combination of them can stand in for (`twin.estimation.method`, "Coolant inlet").
A thermocouple's offset (`bias_T1`..`bias_T5`) moves no temperature: its column is 1 K
per K on its own sensor at every sample, 0 elsewhere and on the drift; it is studied only
where named (the default: every other candidate).

    python -m twin.estimation.sensitivity [--speed 9000] [--minutes 30] [--sigma 0.1]
                                          [--names H_front,…,coolant_offset]
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from twin.contract import STEP_S
from twin.estimation.parameters import ALL_PARAMETERS, OFFSETS, SENSOR_BIASES, apply_factors

CANDIDATES: tuple[str, ...] = tuple(n for n in ALL_PARAMETERS if n not in SENSOR_BIASES)
"""The study's default: every candidate but the thermocouples' offsets."""

if TYPE_CHECKING:
    from twin.spindle.conditions import BoundaryConditions
    from twin.spindle.model import SpindleModel


@dataclass(frozen=True)
class Sensitivity:
    """J (times, 5, p) K per unit log-factor, the drift's (times, p) µm, and the names."""

    time_s: np.ndarray
    sensors_K: np.ndarray
    drift_um: np.ndarray
    names: tuple[str, ...]

    def scaled_jacobian(self, sigma_C: float) -> np.ndarray:
        """(times·5, p): J stacked over times and sensors, divided by the observation error."""
        return self.sensors_K.reshape(-1, len(self.names)) / sigma_C

    def singular_values(self, sigma_C: float) -> tuple[np.ndarray, np.ndarray]:
        """Singular values (descending) and right singular vectors (rows) of J/σ."""
        _, s, vt = np.linalg.svd(self.scaled_jacobian(sigma_C), full_matrices=False)
        return s, vt


def sensor_trajectories(model: SpindleModel, bc: BoundaryConditions, steps: int, dt_s: float,
                        every: int) -> tuple[np.ndarray, np.ndarray]:
    """T1..T5 (k, 5) and the axial drift (k,) µm every `every` steps of a run at fixed loads,
    from a uniform field at the ambient."""
    stepper = model.thermal.transient(bc.to_thermal_loads(), dt_s)
    T0 = np.full(model.n_dofs, bc.ambient_C)
    T = T0.copy()
    sensors, drift = [], []
    for i in range(1, steps + 1):
        T = stepper.step(T)
        if i % every == 0:
            sensors.append(model.sensor_matrix @ T)
            drift.append(1e6 * model.probe_vectors[0] @ (T - T0))
    return np.array(sensors), np.array(drift)


def trajectory_sensitivity(
    model: SpindleModel,
    speed_rpm: float = 9000.0,
    ambient_C: float = 25.0,
    minutes: float = 30.0,
    names: Sequence[str] = CANDIDATES,
    delta: float = 0.05,
    dt_s: float = STEP_S,
) -> Sensitivity:
    """Forward-difference sensitivities of T1..T5 and the drift every 60 s (module doc)."""
    from twin.spindle import nominal_conditions

    bc = nominal_conditions(model, speed_rpm, ambient_C)
    steps = int(round(minutes * 60.0 / dt_s))
    every = int(round(60.0 / dt_s))
    base_T, base_d = sensor_trajectories(model, bc, steps, dt_s, every)
    J = np.empty(base_T.shape + (len(names),))
    Jd = np.empty(base_d.shape + (len(names),))
    for i, name in enumerate(names):
        if name in SENSOR_BIASES:  # read on its own sensor only: 1 K per K
            J[..., i] = 0.0
            J[:, SENSOR_BIASES.index(name), i] = 1.0
            Jd[..., i] = 0.0
            continue
        # an offset (K) moves by `delta` K: its sensitivity is per K
        moved = (apply_factors(bc, {}, coolant_offset_K=delta) if name in OFFSETS
                 else apply_factors(bc, {name: np.exp(delta)}))
        T, d = sensor_trajectories(model, moved, steps, dt_s, every)
        J[..., i] = (T - base_T) / delta
        Jd[..., i] = (d - base_d) / delta
    time_s = 60.0 * np.arange(1, len(base_d) + 1)
    return Sensitivity(time_s, J, Jd, tuple(names))


def report(sens: Sensitivity, sigma_C: float) -> str:
    """A plain-text table: per-parameter sensitivities, singular values and vectors."""
    lines = [f"{'parameter':14s}" + "".join(f"{f'T{i}':>8s}" for i in range(1, 6))
             + f"{'drift':>9s}   (max over the run, K resp. µm per unit log-factor; an "
             "offset's per K)"]
    for i, name in enumerate(sens.names):
        peak = np.max(np.abs(sens.sensors_K[..., i]), axis=0)
        lines.append(f"{name:14s}" + "".join(f"{v:8.2f}" for v in peak)
                     + f"{np.max(np.abs(sens.drift_um[:, i])):9.2f}")
    s, vt = sens.singular_values(sigma_C)
    lines.append(f"singular values of J/σ (σ = {sigma_C} K): "
                 + " ".join(f"{v:.3g}" for v in s))
    for k in range(len(s)):
        top = np.argsort(-np.abs(vt[k]))[:3]
        lines.append(f"  v{k + 1} ({s[k]:.3g}): " + ", ".join(
            f"{vt[k, j]:+.2f} {sens.names[j]}" for j in top))
    J = sens.scaled_jacobian(1.0)
    for i, name in enumerate(sens.names):
        if name not in OFFSETS or len(sens.names) < 2:
            continue
        col = J[:, i]
        norms = np.linalg.norm(J, axis=0)
        cos = (J.T @ col) / np.where(norms > 0, norms * np.linalg.norm(col), 1.0)
        others = np.delete(J, i, axis=1)
        left = col - others @ np.linalg.lstsq(others, col, rcond=None)[0]
        lines.append(f"{name}: cos with " + ", ".join(
            f"{n} {c:+.2f}" for n, c in zip(sens.names, cos, strict=True) if n != name))
        lines.append(f"  RMS {np.sqrt(np.mean(col**2)):.3f} K per K, left after all others "
                     f"{np.sqrt(np.mean(left**2)):.3f}")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> None:
    from twin.spindle import SpindleModel

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speed", type=float, default=9000.0)
    parser.add_argument("--minutes", type=float, default=30.0)
    parser.add_argument("--sigma", type=float, default=0.1)
    parser.add_argument("--names", default=",".join(CANDIDATES),
                        help="comma-separated parameters (default: every candidate but the "
                             "thermocouples' offsets)")
    args = parser.parse_args(argv)
    sens = trajectory_sensitivity(SpindleModel.load(), args.speed, minutes=args.minutes,
                                  names=tuple(args.names.split(",")))
    print(report(sens, args.sigma))


if __name__ == "__main__":
    main()
