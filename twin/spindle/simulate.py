"""The open-loop transient of the spindle at a constant operating point.

    result = simulate(model, speed_rpm=9000, minutes=30, ambient_C=25.3)
    result.keypoints()        # dict of arrays: time_s, T1_C..T5_C, disp_z_um, disp_r_um

Backward Euler with Δt = 4 s from a uniform start at the ambient temperature.  The loads
are the nominal ones (`nominal_conditions`), re-evaluated every `update_every_s` (default:
every step) from the simulated ring and sleeve temperatures T1..T4 at its start: the oil
thins as the bearings warm (less heat) and the fit tightens or loosens (Eq. 5), as on a
real spindle, continuously.  Held longer, the loads jump: held over a 60 s window from the
cold start (the oil at ambient, too much heat), they dropped T1 by 1.8 K in the 4 s after
the first minute at 13 500 rpm.  Pass `update_every_s=None` to hold the cold-start loads
for the whole run.  An update changes only the source vector and the contact terms (a
low-rank update of the factorization of the speed's films); each step costs one
back-substitution and a few dot products (key points, nose drift through the adjoint probe
vectors, energy balance).

Displacements are relative to the start of the run (the thermal drift).  Energy balance of
every step: heat_in (sources) = heat_out (films) + stored, residual in W.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from twin.contract import SENSOR_NAMES, STEP_S
from twin.errors import InputError
from twin.spindle.conditions import (
    BoundaryConditions,
    bearing_values_at,
    check_operating_point,
    nominal_conditions,
)
from twin.spindle.model import SpindleModel


@dataclass
class SimulationResult:
    """Time series and summary of one open-loop run (SI, temperatures in °C)."""

    speed_rpm: float
    ambient_C: float
    coolant_C: float
    dt_s: float
    time_s: np.ndarray  # (n+1,)
    sensors_C: np.ndarray  # (n+1, 5) T1..T5
    disp_z_um: np.ndarray  # (n+1,) nose, axial (towards the tool: positive)
    disp_r_um: np.ndarray  # (n+1,) nose, radial growth
    heat_in_W: np.ndarray  # (n,) per step
    heat_out_W: np.ndarray
    stored_W: np.ndarray
    residual_W: np.ndarray
    max_temperature_C: float
    max_temperature_at_m: tuple[float, float]  # (r, z)
    max_temperature_region: str
    region_mean_C: dict[str, float]
    region_max_C: dict[str, float]
    conditions: list[BoundaryConditions]  # one per load update (the first: cold start)
    final_T: np.ndarray
    fields: list[tuple[float, np.ndarray]] = field(default_factory=list)  # (t, T) snapshots
    wall_time_s: float = 0.0

    @property
    def relative_residual(self) -> np.ndarray:
        """|residual| / heat_in per step."""
        return np.abs(self.residual_W) / np.maximum(self.heat_in_W, 1e-300)

    def keypoints(self) -> dict[str, np.ndarray]:
        out = {"time_s": self.time_s}
        for i, name in enumerate(SENSOR_NAMES):
            out[f"{name}_C"] = self.sensors_C[:, i]
        out["disp_z_um"] = self.disp_z_um
        out["disp_r_um"] = self.disp_r_um
        return out


def simulate(model: SpindleModel, speed_rpm: float, minutes: float, ambient_C: float,
             coolant_C: float | None = None, dt: float = STEP_S, *,
             update_every_s: float | None = STEP_S,
             field_every_s: float | None = None) -> SimulationResult:
    """Open-loop transient at a constant speed (see the module doc).

    `field_every_s`: keep the full temperature field every so many seconds (and at the
    end) in `result.fields`; None keeps none (the fast path).
    """
    spec = model.spec
    check_operating_point(spec, speed_rpm, ambient_C, coolant_C)
    if not (math.isfinite(minutes) and minutes > 0):
        raise InputError(f"minutes must be positive, got {minutes}", column="minutes")
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be positive, got {dt}")
    n_steps = max(1, int(math.ceil(minutes * 60.0 / dt - 1e-9)))
    steps_per_update = n_steps
    if update_every_s is not None:
        if not update_every_s > 0:
            raise ValueError(f"update_every_s must be positive, got {update_every_s}")
        steps_per_update = max(1, int(round(update_every_s / dt)))
    field_every = None
    if field_every_s is not None:
        # an interval past the run's end (inf too) keeps the start and the end only
        field_every = max(1, int(round(min(field_every_s, n_steps * dt) / dt)))

    start = time.perf_counter()
    thermal = model.thermal
    T0 = np.full(model.n_dofs, float(ambient_C))
    T = T0.copy()
    S = model.sensor_matrix
    W = model.probe_vectors

    n = n_steps
    sensors = np.empty((n + 1, S.shape[0]))
    disp = np.empty((2, n + 1))
    energy = np.empty((4, n))
    sensors[0] = S @ T
    disp[:, 0] = 0.0
    fields = [(0.0, T.copy())] if field_every else []
    t_max, dof_max = float(T.max()), int(np.argmax(T))
    conditions: list[BoundaryConditions] = []
    coolant = ambient_C if coolant_C is None else coolant_C

    cold = nominal_conditions(model, speed_rpm, ambient_C, coolant)  # the start, at ambient
    k = 0
    while k < n:
        if not conditions or update_every_s is not None:
            # only the bearing values follow the rings: films and motor loss depend on the
            # speed and the ambient alone (and sharing them keeps a day's updates small)
            bc = cold.with_values(**bearing_values_at(model, speed_rpm, sensors[k])
                                  ) if conditions else cold
            conditions.append(bc)
            loads = bc.to_thermal_loads()
            stepper = thermal.transient(loads, dt=dt, theta=1.0)
        for T_new in stepper.march(T, min(steps_per_update, n - k)):
            eb = stepper.energy_balance(T, T_new)
            energy[:, k] = (eb["heat_in_W"], eb["heat_out_W"], eb["stored_W"], eb["residual_W"])
            T = T_new
            k += 1
            sensors[k] = S @ T
            disp[:, k] = W @ (T - T0)
            m = float(T.max())
            if m > t_max:
                t_max, dof_max = m, int(np.argmax(T))
            if field_every and (k % field_every == 0 or k == n):
                fields.append((k * dt, T.copy()))

    # the hottest point of the whole run (heating is monotone: normally the end state)
    xy = model.dof_coordinates()[:, dof_max]
    region_mean = model.region_mean_C(T)
    region_max = {}
    n_nodes = model.mesh.thermal.p.shape[1]
    for region in spec.regions:
        cells = model.mesh.region(region)
        region_max[region] = float(T[:n_nodes][model.mesh.thermal.t[:, cells]].max())
    return SimulationResult(
        speed_rpm=float(speed_rpm), ambient_C=float(ambient_C), coolant_C=float(coolant),
        dt_s=float(dt), time_s=np.arange(n + 1) * float(dt), sensors_C=sensors,
        disp_z_um=disp[0] * 1e6, disp_r_um=disp[1] * 1e6,
        heat_in_W=energy[0], heat_out_W=energy[1], stored_W=energy[2], residual_W=energy[3],
        max_temperature_C=t_max, max_temperature_at_m=(float(xy[0]), float(xy[1])),
        max_temperature_region=model.dof_region(dof_max, T),
        region_mean_C=region_mean, region_max_C=region_max, conditions=conditions,
        final_T=T, fields=fields, wall_time_s=time.perf_counter() - start,
    )
