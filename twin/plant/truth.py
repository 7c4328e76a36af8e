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
X/Y drift      a few µm of radial drift an axisymmetric model cannot produce: the housing
               is stiffer on the motor-cable side, so the warm-up tilts the nose.  It is
               a property of this spindle, the same in every run: a fixed linear response
               to the true temperature rises at T1..T5 (`XY_GAIN_UM_PER_K`) through a
               120 s first-order lag, scaled per run by U(0.9, 1.1) (clamping, fixture).
               So X/Y can be learned from the temperatures, as on a real machine
               (`twin drift`), but not from the axisymmetric FEM.  A scenario's
               [xy_drift] table replaces it with a prescribed time series.

Model-form error (REFERENCE.md §7): what the four corrected values cannot express.  With
no scenario table, each is a constant drawn once per run (`default_model_form`):

    =====================  ==========================  ==================================
    factor                 default (uniform)           applies to
    =====================  ==========================  ==================================
    motor_heat             0.85 – 1.15  (±15 %)        motor loss, rotor and stator
    film.coolant           0.75 – 1.25  (±25 %)        jacket channels
    film.housing           0.75 – 1.25                 outer housing, mount
    film.air_gap           0.75 – 1.25                 rotor and stator gap faces
    film.rotor             0.75 – 1.25                 rotor/shaft ends, nose, internal air
    material.conductivity  0.95 – 1.05  (±5 %)         every material's k (and Eq. 4's k)
    material.expansion     0.97 – 1.03  (±3 %)         every material's α (and Eq. 5's α)
    sensors.placement_mm   1.0 mm (scenario default)   each thermocouple's point
    =====================  ==========================  ==================================

The spread follows the published uncertainty of each input (catalogue motor efficiency
±20–30 %, film correlations ±20–40 %, material data ±5–10 %) taken at about two thirds,
so a default run is a plausible spindle rather than a worst case.  A stop (speed 0) has
no bearing or motor heat and standstill film coefficients whatever the factors.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from twin.contract import OPERATING_TEMPERATURE_C
from twin.lag import first_order_lag
from twin.plant.scenario import AmbientTable, CoolantTable, FactorTable, Scenario
from twin.plant.timetable import TimeTable
from twin.spindle.conditions import FILM_GROUPS, film_group

# X/Y response of the emulated spindle, µm per K of rise at (T1, T2, T3, T4, T5): the front
# ring's warm-up tilts the nose towards +x and the housing's pulls it back; the rear ring
# and front sleeve push +y.  With typical rises (T1 10–15 K, T5 2–4 K) it gives a few µm,
# the size the previous seeded tables had.
XY_GAIN_UM_PER_K = np.array([[0.22, 0.0, 0.05, 0.0, -0.35],
                             [0.0, 0.10, 0.12, 0.0, -0.10]])
XY_LAG_S = 120.0

REFERENCE_SPEED_RPM = 9000.0
TABLE_STEP_S = 10.0


DEFAULT_FORM_RANGES: dict[str, tuple[float, float]] = {
    "motor_heat": (0.85, 1.15),
    "film": (0.75, 1.25),
    "conductivity": (0.95, 1.05),
    "expansion": (0.97, 1.03),
}
"""Uniform ranges of the default model-form factors (see the module doc)."""


@dataclass(frozen=True)
class ModelForm:
    """Model-form error of the truth: factors the twin's corrections do not estimate.

    motor_heat, film[group]: multipliers as functions of time (s); conductivity,
    expansion: constant multipliers on every material; sensor_offsets_mm: name → (Δr, Δz)
    of each thermocouple from its nominal point (set by the emulator, which knows the
    solid).
    """

    motor_heat: TimeTable = field(default_factory=lambda: TimeTable.constant(1.0))
    film: Mapping[str, TimeTable] = field(
        default_factory=lambda: {g: TimeTable.constant(1.0) for g in FILM_GROUPS})
    conductivity: float = 1.0
    expansion: float = 1.0
    sensor_offsets_mm: Mapping[str, tuple[float, float]] = field(default_factory=dict)

    def film_factor(self, boundary: str, t_s: float) -> float:
        """Multiplier on the film coefficient of a spec boundary at time t_s."""
        group = film_group(boundary)
        if group is None:
            raise ValueError(f"boundary {boundary!r} belongs to no film group")
        return float(self.film[group](t_s))


@dataclass(frozen=True)
class TruthTables:
    """Every truth factor as a function of time (s)."""

    H_front: TimeTable
    H_rear: TimeTable
    R_front: TimeTable
    R_rear: TimeTable
    coolant_C: TimeTable
    ambient_C: TimeTable
    x_um: TimeTable | None  # None: the spindle's own response to its temperatures
    y_um: TimeTable | None
    form: ModelForm = field(default_factory=ModelForm)
    xy_gain_scale: tuple[float, float] = (1.0, 1.0)  # per-run scale of XY_GAIN_UM_PER_K


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
    # the drift stays in the range the twin models: a run started at its edge (--ambient
    # -40) drifted out and the truth's own nominal model refused it, naming no option
    coolant, ambient = (np.clip(x, *OPERATING_TEMPERATURE_C) for x in (coolant, ambient))
    # Per-run X/Y gain scales.  The three draws per axis replay those of the earlier
    # random X/Y tables (sign, amplitude, time constant), so every seeded run keeps its
    # bearing and contact tables, which are drawn after these: the amplitude's uniform
    # becomes the scale, the other two are spent.
    xy_scale = []
    for _ in range(2):
        rng.choice([-1.0, 1.0])
        xy_scale.append(0.9 + 0.2 * (u(1.0, 4.0) - 1.0) / 3.0)
        u(300.0, 900.0)
    return TruthTables(H_front=bearing(1.0), H_rear=bearing(0.6), R_front=contact(),
                       R_rear=contact(), coolant_C=TimeTable(t, coolant),
                       ambient_C=TimeTable(t, ambient), x_um=None, y_um=None,
                       xy_gain_scale=(xy_scale[0], xy_scale[1]))


def xy_drift_um(time_s: np.ndarray, sensors_C: np.ndarray,
                gain_scale: tuple[float, float]) -> np.ndarray:
    """(2, n) true X/Y nose drift in µm from the true T1..T5 history (n, 5) in °C.

    The response to each sensor's rise since the start, lagged by `XY_LAG_S` (the tilt
    follows the housing, which warms more slowly than the bearing rings).
    """
    rise = np.asarray(sensors_C, float) - np.asarray(sensors_C, float)[0]
    lagged = first_order_lag(rise, time_s, XY_LAG_S)
    return np.asarray(gain_scale, float)[:, None] * (XY_GAIN_UM_PER_K @ lagged.T)


def default_model_form(rng: np.random.Generator) -> ModelForm:
    """Seeded default model-form factors, constant over the run (`DEFAULT_FORM_RANGES`)."""
    r = DEFAULT_FORM_RANGES
    motor = TimeTable.constant(rng.uniform(*r["motor_heat"]))
    film = {g: TimeTable.constant(rng.uniform(*r["film"])) for g in FILM_GROUPS}
    return ModelForm(motor_heat=motor, film=film,
                     conductivity=float(rng.uniform(*r["conductivity"])),
                     expansion=float(rng.uniform(*r["expansion"])))


def sensor_offsets_mm(rng: np.random.Generator, placement_mm: float,
                      sensors: Mapping[str, tuple[float, float]],
                      inside: Callable[[float, float], bool]) -> dict[str, tuple[float, float]]:
    """(Δr, Δz) mm per thermocouple, uniform over the disk of radius `placement_mm`.

    An offset that would leave the solid (`inside(r_mm, z_mm)` false) is drawn again; after
    50 misses (a sensor on a thin wall) the offset is halved until the point is inside.
    Always draws the same number of random numbers per sensor, so one sensor's fate does
    not reshuffle the others.
    """
    out = {}
    for name, (r, z) in sensors.items():
        tries = rng.uniform(size=(50, 2))
        radius = placement_mm * np.sqrt(tries[:, 0])
        angle = 2.0 * math.pi * tries[:, 1]
        offsets = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
        hit = next((o for o in offsets if r + o[0] >= 0 and inside(r + o[0], z + o[1])), None)
        if hit is None:
            hit = offsets[0]
            while not (r + hit[0] >= 0 and inside(r + hit[0], z + hit[1])):
                hit = 0.5 * hit
        out[name] = (float(hit[0]), float(hit[1]))
    return out


def truth_tables(scenario: Scenario, defaults: TruthTables) -> TruthTables:
    """The scenario's tables where given, the defaults elsewhere."""
    def pick(table: FactorTable | CoolantTable | AmbientTable | None,
             default: TimeTable) -> TimeTable:
        return default if table is None else table.table()

    xy = scenario.xy_drift
    d = defaults.form
    material = scenario.material
    form = ModelForm(
        motor_heat=pick(scenario.motor_heat, d.motor_heat),
        film={g: pick(getattr(scenario.film, g), d.film[g]) for g in FILM_GROUPS},
        conductivity=d.conductivity if material.conductivity is None else material.conductivity,
        expansion=d.expansion if material.expansion is None else material.expansion,
        sensor_offsets_mm=d.sensor_offsets_mm,
    )
    return TruthTables(
        H_front=pick(scenario.bearing_heat.front, defaults.H_front),
        H_rear=pick(scenario.bearing_heat.rear, defaults.H_rear),
        R_front=pick(scenario.contact_resistance.front, defaults.R_front),
        R_rear=pick(scenario.contact_resistance.rear, defaults.R_rear),
        coolant_C=pick(scenario.coolant, defaults.coolant_C),
        ambient_C=pick(scenario.ambient, defaults.ambient_C),
        x_um=defaults.x_um if xy is None else TimeTable(xy.time_s, xy.x_um),
        y_um=defaults.y_um if xy is None else TimeTable(xy.time_s, xy.y_um),
        form=form,
        xy_gain_scale=defaults.xy_gain_scale,
    )
