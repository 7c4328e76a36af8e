"""The temperature field a replay starts from.

A recording that begins on a spindle at rest finds it equalised: the replay starts from a
uniform field at the mean of the first measured T1..T5, as it always has.  One that begins
on a warm spindle (the logger started mid-shift, or after a first warm-up) does not: the
rings read kelvins above the housing, and the shaft, which no thermocouple sees, is warmer
still.  Started uniform at the readings' mean, the twin then warms the rings again from too
low and the shaft from far too low: on twelve recordings cut 15 and 30 min into emulated
70-min runs (probe zeroed at the cut), the estimator's deformation accuracy was 90.7 %
median and −17 % worst, the ratio law's −10 % median.

So where the first valid readings spread more than `WARM_START_SPREAD_K`, the start field is
fitted to them among fields the spindle itself produces (`start_field`).  By linearity
(loads held at their values at the readings' ring temperatures) a history's field is the
ambient plus the response to each heat source (front bearing, rear bearing, motor) plus the
inlet's (a coolant off the ambient).  The histories:
    warming   τ minutes at the speed recorded at the start, from a uniform field at the
              ambient, τ = 1 … `WARMING_MINUTES` (the recording begins running);
    cooling   stopped for τ minutes after `COOLING_AFTER_MINUTES` at
              `RESTING_SPEED_FRACTION` of the top speed, τ = 0, 20, 40 s, 1 …
              `COOLING_MINUTES` min (it begins in a pause, maybe just after the stop);
and for each τ the start is  T = T_ambient + b + Σ a_j R_j(τ) + R_inlet(τ),  the level b and
the sources' scales a_j ≥ 0 fitted by bounded least squares to the valid readings (within
`READING_SD_K`), the scales drawn towards a common one (`SCALE_SD`) and that towards the
history's nominal heat (`COMMON_SCALE_SD`); the τ whose fit costs least (readings and
scales together: the readings alone barely tell the first minutes of a pause apart) is
taken.  Free scales take up a speed, a load or a bearing other than the history assumes
(one common scale left T1..T5 up to 1.5 K off on a run whose rear bearing ran hot); the
history's shape gives the unseen shaft its share.  Measured on those twelve recordings: the
estimator's temperature accuracy 99.60 / 97.75 → 99.76 / 99.58 % (median / worst), its
deformation 90.7 / −17 → 93.7 / 78.6 %, ratio's deformation median −10 → 77 %; a replay
that knew the whole history (the uncut run, scored from the cut) gives the estimator
deformation 91.6 % median.  On 18 recordings cut from a suite not used to design it
(README, "A recording that begins on a warm spindle"): 99.46 / 98.92 → 99.85 / 99.34 %
and 84.5 / 15.2 → 92.0 / 18.7 % (the history known: 89.9 % deformation median).
Only the readings at the start are read (causal), and the fit is the same for every
method: it is the twin's initial condition, not a correction.

The nose drift is the change from the start field (the probe is taken as zeroed at the
start, `probe_start_offset_um`), so a non-uniform start moves no drift by itself.  The
first window's deck then restarts from this field (`decks/window_000_start.vtu`) instead
of a uniform TUNIF.  quality.json tells it (`warm_start`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from twin.fem.loads import ThermalLoads
from twin.fem.stepper import ThermalStepper
from twin.runs.run import RecordedRun
from twin.spindle.conditions import BoundaryConditions, nominal_conditions
from twin.spindle.model import SpindleModel

WARM_START_SPREAD_K = 2.0
"""First valid readings spreading more than this (K, largest − smallest) start the replay
from a fitted field; within it the spindle is taken as at rest (uniform).  Emulated cold
starts spread 0.49 K at most over 92 suite and sweep runs without calibration offsets
(noise, slow thermocouples), and 0.66 K at most (median 0.44) over 96 suite runs with the
suites' offsets of ±0.3 K; the warm starts measured 4 K and more (recorded from 10 min
into a run or from a pause).  Not 1 K: a stand's thermocouples may be further off than the
suites', and five offsets of ±0.5 K (1 σ) spread more than 1 K in about half of all
cold starts, more than 2 K in about one in twenty; one thermocouple 1.5 K off on a spindle
at rest was fitted as a motor-heated rotor 8–20 K above it, its open-loop drift
0.35–0.82 µm off instead of 0.26."""

SOURCES = ("front bearing", "rear bearing", "motor")
"""The heat sources whose responses a start is fitted with, in `StartField.scales`' order."""

MIN_READINGS = 4
"""Valid first readings a fitted start needs (a level and three scales)."""
READING_SD_K = 0.3
"""How closely the fitted field's T1..T5 should follow the readings, K (the twin's own
model-form error at the sensors, not their noise)."""
SCALE_SD = 0.5
"""How far one source's scale may stray from the others' without cost."""
COMMON_SCALE_SD = 1.0
"""How far the sources' common scale may stray from the history's nominal heat (1) without
cost: free, a pause was fitted as 90 min of cooling from 36 times the heat, or 2 min from
three times the bearings' (a shaft 28 K too hot), within hundredths of a kelvin at T1..T5."""

WARMING_MINUTES = 120
COOLING_AFTER_MINUTES = 60
COOLING_MINUTES = 90
PRE_RUN_STEP_S = 20.0
"""Backward Euler step of the family's pre-runs, s (a start field, not a window: the
snapshots' shape matters, not their 4 s detail)."""
RESTING_SPEED_FRACTION = 0.6
"""A recording that begins with the spindle stopped assumes it ran at this share of its
top speed before (9000 rpm for the reference spindle)."""


@dataclass(frozen=True)
class StartField:
    """A replay's start field (°C per thermal dof) and how it was found.

    uniform    at rest: the mean of the first readings everywhere
    history    the history fitted ("at rest", "warming 23 min at 9000 rpm", ...)
    level_C    b of the fit: the offset from the ambient (at rest: the uniform temperature)
    scales     a_j of the `SOURCES` (none at rest)
    misfit_K   RMS of the field's T1..T5 against the valid readings
    """

    field_C: np.ndarray
    uniform: bool
    history: str
    level_C: float
    scales: tuple[float, ...]
    misfit_K: float

    @property
    def mean_C(self) -> float:
        """The uniform start temperature, or the fitted field's mean over the dofs."""
        return float(self.field_C[0]) if self.uniform else float(np.mean(self.field_C))


def start_field(model: SpindleModel, run: RecordedRun) -> StartField:
    """The field `run`'s replay starts from (see the module doc)."""
    first = run.before(np.array([run.time_s[0]]))  # what was measured at the start
    readings = first.T_valid_C[0]  # T1..T5, NaN where invalid
    valid = np.isfinite(readings)
    ambient = float(first.ambient_C[0])
    # at rest: the mean of the valid readings (the ambient where none is valid)
    T_uniform = float(np.nanmean(readings)) if valid.any() else ambient
    spread = float(np.ptp(readings[valid])) if valid.sum() >= 2 else 0.0
    if valid.sum() < MIN_READINGS or spread <= WARM_START_SPREAD_K:
        field = np.full(model.n_dofs, T_uniform)
        misfit = float(np.sqrt(np.mean((readings[valid] - T_uniform) ** 2))) if valid.any() \
            else 0.0
        return StartField(field, True, "at rest", T_uniform, (), misfit)

    coolant = ambient if first.coolant_C is None else float(first.coolant_C[0])
    speed = float(first.speed_rpm[0])
    S = model.sensor_matrix[valid]
    y = readings[valid]
    best: tuple[float, str, np.ndarray, list[np.ndarray]] | None = None
    for history, responses, sink in _family(model, speed, ambient, coolant, readings):
        x, cost = _fit(np.column_stack([S @ r for r in responses]), y - S @ sink)
        # the history whose fit costs least, the scales counted with the readings: the
        # readings alone told histories apart by hundredths of a kelvin (0.14 to 0.24 K
        # RMS over the first minutes of a pause), whatever scales they took (3.0, 0.8, 2.4
        # won over 0.8, 1.0, 0.8: a shaft 28 K too hot)
        if best is None or cost < best[0]:
            best = (cost, history, x, [*responses, sink])
    _, history, x, parts = best
    field = x[0] + sum(a * r for a, r in zip(x[1:], parts[:-1], strict=True)) + parts[-1]
    misfit = float(np.sqrt(np.mean((S @ field - y) ** 2)))
    return StartField(field, False, history, float(x[0]), tuple(float(a) for a in x[1:]),
                      misfit)


def _fit(columns: np.ndarray, readings: np.ndarray) -> tuple[np.ndarray, float]:
    """([b, a_1..a_m], cost): level and source scales (≥ 0) of the start field from the sources'
    responses at the sensors `columns` (n, m) and the readings less the sinks' share,
    the scales drawn towards a common one (`SCALE_SD`: each source may be off its nominal
    value, but five readings do not pin three scales and a level freely) and that towards
    the nominal (`COMMON_SCALE_SD`), and the least squares' cost (half the weighted sum of
    squares: readings and scales)."""
    # here, not with the module: a cold start (every replay imports this) loaded it for
    # nothing, 9 MB of a replay's peak memory
    from scipy.optimize import lsq_linear

    n, m = columns.shape
    # unknowns [b, a_1..a_m, a_common]: readings within READING_SD_K, a_j − a_common ≈ 0,
    # a_common ≈ 1
    A = np.zeros((n + m + 1, m + 2))
    A[:n, 0] = 1.0 / READING_SD_K
    A[:n, 1:m + 1] = columns / READING_SD_K
    A[n:n + m, 1:m + 1] = np.eye(m) / SCALE_SD
    A[n:n + m, m + 1] = -1.0 / SCALE_SD
    A[n + m, m + 1] = 1.0 / COMMON_SCALE_SD
    rhs = np.r_[readings / READING_SD_K, np.zeros(m), 1.0 / COMMON_SCALE_SD]
    lower = np.r_[-np.inf, np.zeros(m + 1)]
    solution = lsq_linear(A, rhs, bounds=(lower, np.full(m + 2, np.inf)), method="bvls")
    return solution.x[:m + 1], float(solution.cost)


def _family(model: SpindleModel, speed_rpm: float, ambient_C: float, coolant_C: float,
            readings_C: np.ndarray) -> Iterator[tuple[str, list[np.ndarray], np.ndarray]]:
    """(history, the sources' rise fields, the sinks' field) for every member of the
    family a start is fitted among (module doc).  By linearity (loads held at their
    values at the readings' ring temperatures) a history's field is the ambient plus
    each source's response plus the inlet's (a coolant off the ambient): the sources
    are the front and rear bearing and the motor."""
    running = speed_rpm > 0.0
    ran_rpm = speed_rpm if running else RESTING_SPEED_FRACTION * model.spec.spindle.max_speed_rpm
    rings = readings_C[[0, 2]]
    sleeves = readings_C[[1, 3]]
    ok = np.all(np.isfinite(np.r_[rings, sleeves]))
    bc = nominal_conditions(model, ran_rpm, ambient_C, coolant_C,
                            T_bearings_C=tuple(rings) if ok else None,
                            T_sleeves_C=tuple(sleeves) if ok else None)
    per_minute = int(round(60.0 / PRE_RUN_STEP_S))
    zero = np.zeros(model.n_dofs)

    def stepper(conditions: BoundaryConditions, sources: dict[str, float],
                inlet_K: float) -> ThermalStepper:
        loads = conditions.to_thermal_loads()
        rise = ThermalLoads(
            sources=sources,
            convection={b: (h, inlet_K if b in conditions.coolant_boundaries else 0.0)
                        for b, (h, _) in loads.convection.items()},
            contact_resistance=loads.contact_resistance)
        return model.thermal.transient(rise, dt=PRE_RUN_STEP_S)

    front = {r: bc.H_front for r in bc.bearing_regions["front"]}
    rear = {r: bc.H_rear for r in bc.bearing_regions["rear"]}
    # in the order of SOURCES
    running_steppers = [stepper(bc, src, 0.0) for src in (front, rear, dict(bc.motor_heat))]
    inlet_K = coolant_C - ambient_C
    running_sink = stepper(bc, {}, inlet_K)
    fields = [zero] * len(SOURCES)
    sink_rise = zero
    for minute in range(1, (WARMING_MINUTES if running else COOLING_AFTER_MINUTES) + 1):
        fields = [_advance(st, T, per_minute) for st, T in zip(running_steppers, fields,
                                                               strict=True)]
        sink_rise = _advance(running_sink, sink_rise, per_minute)
        if running:
            yield f"warming {minute} min at {speed_rpm:.0f} rpm", fields, ambient_C + sink_rise
    if running:
        return
    stopped = nominal_conditions(model, 0.0, ambient_C, coolant_C)
    resting = stepper(stopped, {}, 0.0)
    resting_sink = stepper(stopped, {}, inlet_K)
    after = f"after {COOLING_AFTER_MINUTES} min at {ran_rpm:.0f} rpm"
    # the first minute step by step, from the moment of the stop: a logger started seconds
    # after it finds the rings still at their running temperatures, which a minute's cooling
    # cannot meet but with sources scaled up several times (a 108 °C field for a 48 °C one)
    for pre_run_step in range(per_minute):
        yield (f"stopped {pre_run_step * PRE_RUN_STEP_S:.0f} s {after}", fields,
               ambient_C + sink_rise)
        fields = [_advance(resting, T, 1) for T in fields]
        sink_rise = _advance(resting_sink, sink_rise, 1)
    for minute in range(1, COOLING_MINUTES + 1):
        if minute > 1:
            fields = [_advance(resting, T, per_minute) for T in fields]
            sink_rise = _advance(resting_sink, sink_rise, per_minute)
        yield f"stopped {minute} min {after}", fields, ambient_C + sink_rise


def _advance(stepper: ThermalStepper, T: np.ndarray, n: int) -> np.ndarray:
    *_, last = stepper.march(T, n)
    return last
