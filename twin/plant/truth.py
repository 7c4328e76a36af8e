"""The emulated spindle's "truth": how it differs from the twin's nominal model.

A real spindle does not follow the handbook.  The truth factors below are what the twin's
corrections have to discover; each one can be pinned in the scenario TOML, otherwise it
takes a seeded default with the shape the reference paper reports (REFERENCE.md §1,
Table 1: corrections within about ±5–10 % that settle as the spindle reaches balance):

bearing heat   H_true = H_nominal · f_H(t, n).  f_H = 1 + s(n)·[a·(1 − e^(−t/τ_b))
               − b·(1 − e^(−t/τ_r))]: the preload builds up as the balls heat (fast, τ_b
               ~ 1–2 min), then relaxes as the rings expand (slow, τ_r ~ 7–12 min); the
               amplitude grows with speed, s(n) = √(n/9000).  The rear (floating) bearing
               is spring-preloaded, so its swing is smaller.
contact R      R_true = R_nominal · f_R(t): the fit tightens more than Eq. 5 predicts
               (roundness, preload), f_R falling by 5–15 % over ~5–15 min.
coolant        inlet temperature drifts up as the chiller loads, with a small hysteresis
               oscillation; ambient drifts slowly; both as time tables.
X/Y drift      a few µm of radial drift an axisymmetric model cannot produce (asymmetric
               housing, motor cable side), growing like the warm-up.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from twin.plant.scenario import Scenario
from twin.plant.timetable import TimeTable

REFERENCE_SPEED_RPM = 9000.0
TABLE_STEP_S = 10.0


@dataclass(frozen=True)
class TruthTables:
    """Every truth factor as a function of time (s)."""

    H_front: TimeTable
    H_rear: TimeTable
    R_front: TimeTable
    R_rear: TimeTable
    coolant_C: TimeTable
    ambient_C: TimeTable
    x_um: TimeTable
    y_um: TimeTable


def speed_scale(speed_rpm: np.ndarray) -> np.ndarray:
    """Amplitude of the preload swing relative to 9000 rpm (0 at standstill)."""
    return np.sqrt(np.clip(np.asarray(speed_rpm, float) / REFERENCE_SPEED_RPM, 0.0, 2.0))


def preload_factor(t: np.ndarray, speed_rpm: np.ndarray, a: float, b: float, tau_b: float,
                   tau_r: float) -> np.ndarray:
    """1 + s(n)·[a(1 − e^(−t/τ_b)) − b(1 − e^(−t/τ_r))] (see the module doc)."""
    t = np.asarray(t, float)
    swing = a * (1.0 - np.exp(-t / tau_b)) - b * (1.0 - np.exp(-t / tau_r))
    return 1.0 + speed_scale(speed_rpm) * swing


def default_tables(rng: np.random.Generator, duration_s: float,
                   speed_of: Callable[[np.ndarray], np.ndarray],
                   ambient_of: Callable[[np.ndarray], np.ndarray],
                   coolant_C: float) -> TruthTables:
    """Seeded default truth tables sampled every 10 s over the run."""
    t = np.arange(0.0, duration_s + TABLE_STEP_S, TABLE_STEP_S)
    n = speed_of(t)
    u = rng.uniform

    def bearing(scale: float) -> TimeTable:
        a, b = scale * u(0.08, 0.12), scale * u(0.05, 0.09)
        return TimeTable(t, preload_factor(t, n, a, b, u(60.0, 120.0), u(400.0, 700.0)))

    def contact() -> TimeTable:
        depth, tau = u(0.05, 0.15), u(300.0, 900.0)
        tightening = np.minimum(speed_scale(n), 1.0) * (1.0 - np.exp(-t / tau))
        return TimeTable(t, 1.0 - depth * tightening)

    coolant_rise, coolant_tau = u(0.3, 1.2), u(600.0, 1500.0)
    period, phase = u(400.0, 900.0), u(0.0, 2 * np.pi)
    coolant = coolant_C + coolant_rise * (1.0 - np.exp(-t / coolant_tau)) \
        + 0.15 * (np.sin(2 * np.pi * t / period + phase) - np.sin(phase))
    ambient_trend = u(-0.3, 0.8) / max(duration_s, 1.0)
    ambient = ambient_of(t) + ambient_trend * t
    drift = []
    for _ in range(2):
        amplitude = rng.choice([-1.0, 1.0]) * u(1.0, 4.0)
        drift.append(amplitude * speed_scale(n) * (1.0 - np.exp(-t / u(300.0, 900.0))))
    return TruthTables(H_front=bearing(1.0), H_rear=bearing(0.6), R_front=contact(),
                       R_rear=contact(), coolant_C=TimeTable(t, coolant),
                       ambient_C=TimeTable(t, ambient), x_um=TimeTable(t, drift[0]),
                       y_um=TimeTable(t, drift[1]))


def truth_tables(scenario: Scenario, defaults: TruthTables) -> TruthTables:
    """The scenario's tables where given, the defaults elsewhere."""
    def pick(table, default: TimeTable) -> TimeTable:
        return default if table is None else table.table()

    xy = scenario.xy_drift
    return TruthTables(
        H_front=pick(scenario.bearing_heat.front, defaults.H_front),
        H_rear=pick(scenario.bearing_heat.rear, defaults.H_rear),
        R_front=pick(scenario.contact_resistance.front, defaults.R_front),
        R_rear=pick(scenario.contact_resistance.rear, defaults.R_rear),
        coolant_C=pick(scenario.coolant, defaults.coolant_C),
        ambient_C=pick(scenario.ambient, defaults.ambient_C),
        x_um=defaults.x_um if xy is None else TimeTable(xy.time_s, xy.x_um),
        y_um=defaults.y_um if xy is None else TimeTable(xy.time_s, xy.y_um),
    )
