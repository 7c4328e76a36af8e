"""The twin loop: replay one recorded run with one correction method.

For each 60 s window k, covering [60k, 60k + 60) s, using only data measured before the
window starts:

    features (speed, ambient, T1..T5 measured and simulated so far, run time)
      → correction (open_loop | ratio | bpnn | estimator) → H_front, H_rear, R_front, R_rear
        (an estimator also sets the analysed start field, motor/film factors and an
        expansion factor that scales the window's drift)
      → window deck (apdl_like) → 15 backward-Euler steps of 4 s in the persistent session
      → T1..T5 and the nose drift per step (probes), fields at the window end

Every method's correction has `loads_follow_rings` (the default of each): its values are
factors on the nominal values at the window's start field, and the deck is 15 load steps
of 4 s, each with the nominal bearing heat and contact resistance at the twin's own ring
and sleeve temperatures at its start times those factors (`_follow_rings`, the same pieces
as a re-run below).  The correction is still set once a window, as the paper sets it; what
follows the rings is the nominal model it multiplies, as the spindle's bearings follow
theirs.  Held for the window instead (`loads_follow_rings=False` on a method), a cold
start's first minute keeps the cold oil's Palmgren heat (a fifth above the warm value at
60 s): on an emulated cold start at 14 200 rpm the twin's T1 overshot by 4.1 K at 60 s
(43.8 °C, the thermocouple read 39.6), the ratio law then cut the heat and ran T1 4.7 K
low at 100 s; following the rings, 0.35 K and 2.1 K.

The temperature state carries over from window to window.  A stop (speed 0) is an
ordinary window: no bearing or motor heat, the twin cools; each value's correction factor
is held through the stop and resumes at the restart (`WindowFeatures.previous_factors`).

Re-run of a missed speed change (methods with `rerun_missed_speed`: `bpnn` and `ratio`;
`open_loop` keeps the forecast, the `estimator` re-runs inside its own analysis).  When the
recorded speed changed inside window k−1, after its loads were fixed, that window is
re-run from its start field with the recorded speed (`twin.correction.rerun`: per speed,
step by step, each with the nominal loads at its own temperatures times the window's
correction factors, as the spindle's loads follow its rings) before window k's correction;
all of it was measured before 60k s.  So is window 0 of a run whose loads were held (not
`loads_follow_rings`) at the cold start's temperatures for 60 s while the rings warmed by
kelvins and the Palmgren heat fell by about a fifth.
Window k then starts from the re-run's end field, and the re-run's key points replace
the forecast's over window k−1 in the history every later window's method reads
(`WindowFeatures.simulated_C`): the trajectory the twin's state followed, not the forecast
that missed the input.  Copied for window k alone, as until 2026-11-27, the history kept
the forecast's end of window k−1 as the start of window k, which the next window's line
reads (its first point): on the nominal model itself, with ideal thermocouples and a new
speed every 28 s, `ratio`'s and `bpnn`'s heat factors wandered by up to 6.5 % (now none).
The reported trajectory of window k−1 stays its forecast (what was known when it
started).  Every stretch is solved through a deck like any
window; together they are `WindowRecord.rerun_deck` (`decks/window_kkk_rerun.inp`): run in
the session from window k−1's start field (the state its own deck started from) they give
the field window k's deck starts from, so the decks reproduce both the reported trajectory
and the carried state.

The run starts from a uniform field at the mean of the first measured T1..T5 (a spindle
at rest has equalised) or, where those spread more than 2 K (a recording that begins
on a warm spindle), from a field fitted to them (`twin.loop.start_field`).  The start field
is the zero of the drift: the recorded drift is taken as measured from the start.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin.contract import STEP_S, STEPS_PER_WINDOW, WINDOW_S, windows_in
from twin.correction.features import (
    BoundaryValues,
    TwinState,
    WindowFeatures,
    correction_factors,
)
from twin.correction.rerun import (
    LOAD_UPDATE_STEPS,
    first_window_at_speed,
    recorded_step_speeds,
    rerun_window,
    speed_change_s,
    speed_stretches,
)
from twin.correction.result import Correction, Corrector
from twin.lag import first_order_lag
from twin.loop.findings import probe_left_out, probe_start_offset_um
from twin.loop.start_field import StartField, start_field
from twin.runs import RecordedRun
from twin.runs.quality import AXIAL_PROBE
from twin.spindle.conditions import BoundaryConditions, nominal_conditions
from twin.spindle.model import SpindleModel

if TYPE_CHECKING:
    from apdl_like.session import Session

FILM_AMBIENT_STEP_K = 0.5
"""The film coefficients see the ambient on this grid (the sink temperature stays exact).

A recorded ambient wanders by its sensor noise from window to window; evaluated exactly,
every window would bring new natural-convection/radiation coefficients and so a new
step-matrix factorization (5 ms of the 10 ms a window costs).  Over 0.5 K those
coefficients change by < 0.3 %, far inside the ±20 % of the correlations."""


@dataclass
class WindowRecord:
    """What one window used and produced."""

    window: int
    start_s: float
    speed_rpm: float
    ambient_C: float
    correction: Correction
    nominal: BoundaryValues
    deck: str | None = None
    rerun_deck: str | None = None
    """The window re-run with its recorded speed (module doc), if the speed changed inside
    it and the method re-runs: run from the window's start field, it ends on the field the
    next window starts from."""
    start_C: np.ndarray | None = None
    """The field (thermal dofs, °C) the window starts from where its deck alone does not
    say it: the estimator's analysed field, the end of a re-run, or the start of a window
    with a re-run deck (which runs from it too); None where the window starts from the
    uniform TUNIF of its deck or from the end of window k−1's deck, and the method states
    no readings (`Correction.readings_start_C`, written beside it).  Written as
    `decks/window_kkk_start.vtu` (`apdl-like run --start`)."""


@dataclass
class MethodReplay:
    """Time series of one method on one run (solver steps, 4 s apart)."""

    method: str
    time_s: np.ndarray
    T_twin_C: np.ndarray  # (k, 5)
    drift_z_um: np.ndarray  # (k,) axial nose drift
    drift_r_um: np.ndarray  # (k,) radial growth at the nose
    windows: list[WindowRecord]
    fields: dict[float, np.ndarray] = field(default_factory=dict)  # window-end T fields
    T_initial_C: float = 20.0
    """The uniform start temperature, °C; where `start_C` is given, its mean."""
    wall_s: float = 0.0
    band_sd: np.ndarray | None = None
    """(k, 6) forecast spread (1 σ) of T1..T5 (°C) and the axial drift (µm), for methods
    with uncertainty (the estimator); None otherwise."""
    start_C: np.ndarray | None = None
    """The non-uniform field (thermal dofs, °C) a warm start begins from
    (`twin.loop.start_field`); None: uniform at `T_initial_C`."""

    @property
    def start_reference_C(self) -> float | np.ndarray:
        """The field the run started from, the zero of its displacements: `start_C`, or
        the uniform `T_initial_C`."""
        return self.T_initial_C if self.start_C is None else self.start_C

    def start_key_points_C(self, model: SpindleModel) -> np.ndarray:
        """T1..T5 of the start field (the metal at the sensor points), °C: a uniform
        start's own temperature (not its interpolation, which may differ in the last bit)."""
        if self.start_C is None:
            return np.full(model.sensor_matrix.shape[0], self.T_initial_C)
        return model.sensor_matrix @ self.start_C


WindowSolver = Callable[..., tuple]
"""(conditions, correction, T_start, start_s, window, n_steps=15, load_step=None, notes=())
→ (T per step (n_steps, n), deck text or None); load_step (i, n) and notes only label the
deck (`apdl_like.writer.window_deck`)."""


def direct_window_solver(model: SpindleModel) -> WindowSolver:
    """Solve a window straight on twin.fem (no deck); the reference for the deck path."""

    def solve(
        bc: BoundaryConditions, corr: Correction, T: np.ndarray, start_s: float, window: int,
        n_steps: int = STEPS_PER_WINDOW, load_step: tuple[int, int] | None = None,
        notes: tuple[str, ...] = (),
    ) -> tuple[np.ndarray, str | None]:
        loads = bc.to_thermal_loads(
            H_front=corr.H_front_W_m3,
            H_rear=corr.H_rear_W_m3,
            R_front=corr.R_front_m2K_W,
            R_rear=corr.R_rear_m2K_W,
        )
        stepper = model.thermal.transient(loads, STEP_S)
        return np.array(list(stepper.march(T, n_steps))), None

    return solve


def spindle_session(model: SpindleModel, base_dir: str | Path | None = None) -> Session:
    """An APDL-like session (`apdl_like.Session`) holding `model`'s mesh, materials and
    contact real sets: the database every window deck runs on (the loop's, and
    `apdl-like run --spindle`'s)."""
    from apdl_like.session import Session

    return Session.from_mesh(
        model.mesh,
        model.materials,
        order=model.order,
        T_ref_C=model.elastic.T_ref,
        base_dir=base_dir,
        thermal=model.thermal,  # adopt the assembled operators: nothing re-assembled
    )


def deck_window_solver(model: SpindleModel, session: Session | None = None) -> WindowSolver:
    """Solve each window through its APDL-like deck in one persistent session.

    The deck (apdl_like.writer) carries the window's loads only; the session holds the
    mesh, materials and assembled operators, so nothing is re-assembled between windows.
    The temperature state is handed in explicitly, so one session serves every method.
    """
    from apdl_like.loadset import LoadSet
    from apdl_like.writer import window_deck

    if session is None:
        session = spindle_session(model)
    # the load step this session solved last: (window, (i, n), its load set).  Load step
    # i + 1 of the same deck then writes only the loads that changed (the others stay
    # set), as a deck of 15 load steps whose bearing loads follow the rings would be
    # written by hand: 24 instead of 54 commands a step (a ring-following method's replay
    # of a 30-min run: 0.47 -> 0.40 s CPU).  Any other call in between resets it.
    last: list = [None]

    def solve(
        bc: BoundaryConditions, corr: Correction, T: np.ndarray, start_s: float, window: int,
        n_steps: int = STEPS_PER_WINDOW, load_step: tuple[int, int] | None = None,
        notes: tuple[str, ...] = (),
    ) -> tuple[np.ndarray, str]:
        loads = bc.to_thermal_loads(
            H_front=corr.H_front_W_m3,
            H_rear=corr.H_rear_W_m3,
            R_front=corr.R_front_m2K_W,
            R_rear=corr.R_rear_m2K_W,
        )
        load_set = LoadSet(
            window=window,
            start_s=start_s,
            dt_s=STEP_S,
            n_steps=n_steps,
            heat_generation=loads.sources,
            convection=loads.convection,
            contact_resistance=loads.contact_resistance,
        )
        # a run's first window starts from a uniform field: the deck says which, so that
        # it runs alone too (a warm start's field is written beside the deck)
        after = None
        if load_step is not None and last[0] is not None:
            k, (i, n), previous = last[0]
            if k == window and load_step == (i + 1, n):
                after = previous
        # a warm start (`twin.loop.start_field`) restarts from the field handed in
        warm_start = start_s == 0.0 and not bool(np.all(T == T[0]))
        deck = window_deck(load_set, session.layout,
                           start_temperature_C=float(T[0]) if start_s == 0.0 and not warm_start
                           else None,
                           from_state=warm_start,
                           load_step=load_step, notes=notes, after=after)
        last[0] = None  # until this deck has run
        steps = session.advance(T, start_s, deck, file=f"window_{window:03d}.inp")
        if load_step is not None:
            last[0] = (window, load_step, load_set)
        return steps, deck

    return solve


def n_windows(run: RecordedRun) -> int:
    """Whole 60 s windows the run covers."""
    return windows_in(run.duration_s)


def check_field_time(run: RecordedRun, time_s: float) -> None:
    """ValueError unless a field at `time_s` lies in the span a replay of `run` solves."""
    span_s = n_windows(run) * WINDOW_S
    if not 0.0 < time_s <= span_s:
        raise ValueError(f"time {time_s:g} s is outside the replayed span (0, {span_s:g}] s")


def twin_conditions(model: SpindleModel, speed_rpm: float, ambient_C: float,
                    coolant_C: float | None, T_sensors_C: np.ndarray) -> BoundaryConditions:
    """The twin's nominal conditions at its own key-point temperatures T1..T5 (°C): the
    nominal model is open loop, it sees its own bearing temperatures only."""
    return nominal_conditions(
        model,
        speed_rpm,
        ambient_C,
        coolant_C,
        T_bearings_C=(float(T_sensors_C[0]), float(T_sensors_C[2])),
        T_sleeves_C=(float(T_sensors_C[1]), float(T_sensors_C[3])),
        film_ambient_C=FILM_AMBIENT_STEP_K * round(ambient_C / FILM_AMBIENT_STEP_K),
    )


def solve_following_rings(model: SpindleModel, solver: WindowSolver, T_start: np.ndarray,
                          start_s: float, window: int, bc: BoundaryConditions,
                          factors: np.ndarray) -> np.ndarray:
    """One window at `bc`'s speed from `T_start` (°C per dof) with the four values as
    `factors` on nominal values that follow the twin's rings every solver step, as a
    replay's windows run (`Correction.loads_follow_rings`; no model-form factors).
    Returns the field after each step (15, n_dofs)."""
    factors = np.asarray(factors, dtype=float)
    held = Correction(*(factors * np.array([bc.H_front, bc.H_rear, bc.R_front, bc.R_rear])))
    steps, _ = _follow_rings(
        model, solver, _WindowRun(T_start, start_s, window, bc, held, {}),
        np.full(STEPS_PER_WINDOW, bc.speed_rpm), factors,
        lambda *a: twin_conditions(model, *a))
    return steps


def replay_method(
    run: RecordedRun,
    model: SpindleModel,
    corrector: Corrector,
    solver: WindowSolver | None = None,
    keep_fields: bool = True,
    on_window: Callable[[int, int], None] | None = None,
    field_at_s: float | None = None,
    start: StartField | None = None,
) -> MethodReplay:
    """Replay `run` with one correction method; see the module doc.

    keep_fields  keep the temperature field at every window end
    field_at_s   instead, stop at the solver step nearest this time and keep that field
    start        the run's start field (`twin.loop.start_field.start_field`, found here
                 if not given: a caller replaying several methods finds it once)
    """
    t_wall = time.perf_counter()
    solver = solver or deck_window_solver(model)
    windows = n_windows(run)
    if windows < 2:
        raise ValueError(f"{run.name}: a replay needs at least two 60 s windows of data")
    field_step = None
    if field_at_s is not None:
        check_field_time(run, field_at_s)
        field_step = max(1, int(round(field_at_s / STEP_S)))  # 1-based solver step
        windows = int(np.ceil(field_step / STEPS_PER_WINDOW))
    initial = start or start_field(model, run)
    T0 = initial.field_C  # the zero of the drift
    T = T0.copy()

    measured_T = run.T_valid_C
    measured_drift = None
    if (run.disp_um is not None and AXIAL_PROBE in run.valid
            and bool(np.any(run.valid[AXIAL_PROBE] & np.isfinite(run.disp_um[:, 2])))
            and not probe_left_out(run, model)):
        # (decided once, from the whole file, as the probe's other rules: a probe with no
        # valid sample is none, for the estimator's choice of what it estimates too)
        # its change since the run start where the probe was not zeroed there
        measured_drift = np.where(run.valid[AXIAL_PROBE],
                                  run.disp_um[:, 2] - probe_start_offset_um(run), np.nan)
    recorded_coolant = None  # the inlet as measured: NaN through a long dropout, which
    if run.coolant_C is not None:  # the quality check holds at its last reading
        recorded_coolant = np.where(run.valid.get("coolant_C", True), run.coolant_C, np.nan)
    n_steps = windows * STEPS_PER_WINDOW
    time_s = STEP_S * np.arange(1, n_steps + 1)
    starts = WINDOW_S * np.arange(windows)
    state = run.before(starts)
    # the samples measured by each window start: a prefix of the run (its times ascend),
    # handed on as views; a boolean mask and its copies over the whole history, as until
    # 2026-11-27, cost each window of a 24-h run up to 86 400 rows a column
    measured_by = np.searchsorted(run.time_s, starts, side="right")
    sim_T = np.empty((n_steps + 1, 5))
    sim_T[0] = model.sensor_matrix @ T
    reported_T = np.empty((n_steps, 5))  # T1..T5 as reported: the metal or the readings
    sim_time = np.r_[0.0, time_s]
    drift = np.empty((n_steps, 2))
    records: list[WindowRecord] = []
    fields: dict[float, np.ndarray] = {}
    previous: BoundaryValues | None = None
    previous_nominal: BoundaryValues | None = None
    band: np.ndarray | None = None
    factors = np.ones(4)  # each value's last correction factor; a stop holds it

    reruns = bool(getattr(corrector, "rerun_missed_speed", False))
    last: _WindowRun | None = None  # what window k−1 ran with, for its re-run

    def conditions(speed: float, ambient: float, coolant: float | None,
                   T_now: np.ndarray) -> BoundaryConditions:
        return twin_conditions(model, speed, ambient, coolant, T_now)

    for k in range(windows):
        start = float(starts[k])
        speed = float(state.speed_rpm[k])
        ambient = float(state.ambient_C[k])
        coolant = None if state.coolant_C is None else float(state.coolant_C[k])
        bc = conditions(speed, ambient, coolant, sim_T[k * STEPS_PER_WINDOW])
        nominal = BoundaryValues(bc.H_front, bc.H_rear, bc.R_front, bc.R_rear)
        upto = slice(0, int(measured_by[k]))
        n_sim = k * STEPS_PER_WINDOW + 1
        features = WindowFeatures(
            window=k,
            start_s=start,
            speed_rpm=speed,
            ambient_C=ambient,
            measured_time_s=run.time_s[upto],
            measured_C=measured_T[upto],
            simulated_time_s=sim_time[:n_sim],
            simulated_C=sim_T[:n_sim],
            nominal=nominal,
            previous=previous or nominal,
            previous_nominal=previous_nominal,
            twin_state=TwinState(T, bc),
            measured_drift_um=None if measured_drift is None else measured_drift[upto],
            measured_speed_rpm=run.speed_rpm[upto],
            previous_factors=tuple(factors),
            coolant_recorded=state.coolant_C is not None,
            measured_coolant_C=None if recorded_coolant is None else recorded_coolant[upto],
        )
        previous_end = T
        if reruns and last is not None and (
                (first_window_at_speed(features, last.bc.speed_rpm)
                 and not last.correction.loads_follow_rings)
                or speed_change_s(features, last.bc.speed_rpm) is not None):
            rerun, records[-1].rerun_deck = _rerun(model, solver, last, features, factors,
                                                   conditions)
            if records[-1].start_C is None and (last.start_s > 0.0 or not initial.uniform):
                # the re-run starts there
                records[-1].start_C = last.T_start.copy()
            # the twin's state is the re-run's: it starts the window, its key points over
            # the window just ended are what the method compares with the measurement
            T = rerun[-1]
            sim_T[n_sim - STEPS_PER_WINDOW:n_sim] = (model.sensor_matrix @ rerun.T).T
            bc = conditions(speed, ambient, coolant, sim_T[n_sim - 1])
            nominal = BoundaryValues(bc.H_front, bc.H_rear, bc.R_front, bc.R_rear)
            features = dataclasses.replace(
                features, simulated_C=sim_T[:n_sim], nominal=nominal,
                previous=previous or nominal, twin_state=TwinState(T, bc))
        corr = corrector.correct(features)
        if corr.state_C is not None:  # an estimator's analysed field
            T = np.asarray(corr.state_C, dtype=float)
        if corr.coolant_C is not None:  # an estimated inlet (the run records none)
            coolant = corr.coolant_C
            bc = bc.with_coolant(coolant)
        thermal_factors = {k: v for k, v in corr.factors.items() if k != "expansion"}
        if thermal_factors:  # model-form factors (motor, film groups) go into the deck's loads
            bc = bc.scaled(thermal_factors)
        # an estimated expansion factor scales every α, hence the whole thermal displacement
        expansion = float(corr.factors.get("expansion", 1.0))
        if corr.band_sd is not None:
            if band is None:
                band = np.full((n_steps, 6), np.nan)
            band[k * STEPS_PER_WINDOW : (k + 1) * STEPS_PER_WINDOW] = corr.band_sd
        last = _WindowRun(T, start, k, bc, corr, thermal_factors)
        if corr.loads_follow_rings:
            # the correction's values as factors on the nominal values at the window's
            # start field, re-applied every LOAD_UPDATE_STEPS at the twin's own temperatures
            at_start = conditions(speed, ambient, coolant, model.sensor_matrix @ T)
            steps, deck = _follow_rings(
                model, solver, last, np.full(STEPS_PER_WINDOW, speed),
                np.asarray(correction_factors(corr.values, BoundaryValues(
                    at_start.H_front, at_start.H_rear, at_start.R_front, at_start.R_rear))),
                conditions)
        else:
            steps, deck = solver(bc, corr, T, start, k)
        start_T = model.sensor_matrix @ T
        T = steps[-1]
        sl = slice(k * STEPS_PER_WINDOW, (k + 1) * STEPS_PER_WINDOW)
        sim_T[sl.start + 1 : sl.stop + 1] = (model.sensor_matrix @ steps.T).T
        reported_T[sl] = _reported(np.vstack([start_T, sim_T[sl.start + 1 : sl.stop + 1]]), corr)
        drift[sl] = 1e6 * expansion * ((steps - T0) @ model.probe_vectors.T)
        # the start field where the decks do not give it (or the readings need stating)
        start_field_C = (None if last.T_start is previous_end and corr.readings_start_C is None
                         and (k > 0 or initial.uniform) else last.T_start.copy())
        records.append(WindowRecord(k, start, speed, ambient, corr, nominal, deck,
                                    start_C=start_field_C))
        if field_step is not None and sl.start < field_step <= sl.stop:
            fields[STEP_S * field_step] = steps[field_step - sl.start - 1].copy()
        elif keep_fields and field_step is None:
            fields[start + WINDOW_S] = T.copy()
        previous, previous_nominal = corr.values, nominal
        factors = correction_factors(corr.values, nominal, fallback=factors)
        if on_window is not None:
            on_window(k + 1, windows)

    return MethodReplay(
        method=corrector.name,
        time_s=time_s,
        T_twin_C=reported_T,
        drift_z_um=drift[:, 0],
        drift_r_um=drift[:, 1],
        windows=records,
        fields=fields,
        T_initial_C=initial.mean_C,
        wall_s=time.perf_counter() - t_wall,
        band_sd=band,
        start_C=None if initial.uniform else initial.field_C,
    )


def _reported(metal_C: np.ndarray, corr: Correction) -> np.ndarray:
    """T1..T5 over a window as reported (metal_C: the window start and its steps): the
    metal at the sensor points, or, for a method that gives the thermocouples' readings at
    the window start, their readings through the method's lag; plus each thermocouple's
    offset where the method states one (`Correction.sensor_offset_C`)."""
    offset = 0.0 if corr.sensor_offset_C is None else np.asarray(corr.sensor_offset_C, float)
    if corr.readings_start_C is None or corr.sensor_lag_s <= 0:
        return metal_C[1:] + offset
    time_s = STEP_S * np.arange(len(metal_C))
    return first_order_lag(metal_C, time_s, corr.sensor_lag_s,
                           corr.readings_start_C)[1:] + offset


@dataclass(frozen=True)
class _WindowRun:
    """What one window ran with: its start field and time, conditions (model-form factors
    applied), correction and model-form factors."""

    T_start: np.ndarray
    start_s: float
    window: int
    bc: BoundaryConditions
    correction: Correction
    thermal_factors: dict


def _rerun(model: SpindleModel, solver: WindowSolver, last: _WindowRun,
           features: WindowFeatures, factors: np.ndarray,
           conditions: Callable[..., BoundaryConditions]) -> tuple[np.ndarray, str | None]:
    """Window k−1 (`last`) re-run with the speed recorded in it (module doc): the fields
    after each step (15, n) and the decks of its stretches as one text (None without decks).
    `features` are window k's (the recorded speed up to its start), `factors` each value's
    correction factor of window k−1 (held through a stop)."""
    return _follow_rings(model, solver, last,
                         recorded_step_speeds(features, STEPS_PER_WINDOW, STEP_S), factors,
                         conditions, rerun=True)


def _follow_rings(model: SpindleModel, solver: WindowSolver, window: _WindowRun,
                  speeds: np.ndarray, factors: np.ndarray,
                  conditions: Callable[..., BoundaryConditions], rerun: bool = False
                  ) -> tuple[np.ndarray, str | None]:
    """`window` solved from its start field with the speed of each solver step `speeds`,
    in pieces of constant speed and at most LOAD_UPDATE_STEPS (`twin.correction.rerun`):
    each piece gets the nominal conditions at its speed and its own starting temperatures,
    times `factors` (the four values') and the window's model-form factors.  Returns the
    fields after each step (steps, n) and the pieces' decks as one text (None without),
    each piece's comments saying where its loads come from (`rerun`: a re-run's)."""
    ambient, coolant = window.bc.ambient_C, window.bc.coolant_C
    decks: list[str] = []
    n_pieces = len(speed_stretches(speeds, max_steps=LOAD_UPDATE_STEPS))
    model_form = ", ".join(f"{k} {v:.4g}" for k, v in sorted(window.thermal_factors.items()))
    estimated_coolant = (() if window.correction.coolant_C is None else (
        f"  coolant inlet {coolant:.4f} C estimated (the run records none; ambient "
        f"{ambient:.4f} C)",))

    def advance(speed: float, T: np.ndarray, n: int, start_s: float) -> np.ndarray:
        # the nominal loads at this piece's own temperatures (they follow the rings every
        # LOAD_UPDATE_STEPS), times the window's correction and model-form factors
        at_sensors = model.sensor_matrix @ T
        bc = conditions(speed, ambient, coolant, at_sensors)
        if window.thermal_factors:
            bc = bc.scaled(window.thermal_factors)
        corr = Correction(*(factors * np.array([bc.H_front, bc.H_rear, bc.R_front, bc.R_rear])))
        rings = at_sensors[:4]  # the same rows' sums (slicing the matrix cost a copy a step)
        notes = (
            f"{'re-run at the recorded speed' if rerun else 'speed'} {speed:g} rpm; bearing "
            "heat and contact resistance follow the rings:",
            f"  nominal at T1..T4 = {' '.join(f'{x:.3f}' for x in rings)} C (the field at "
            f"{start_s:g} s) x the window's factors",
            f"  H front/rear {factors[0]:.4g} {factors[1]:.4g}, R front/rear "
            f"{factors[2]:.4g} {factors[3]:.4g}" + (f"; model-form: {model_form}"
                                                    if model_form else ""),
        ) + estimated_coolant
        steps, deck = solver(bc, corr, T, start_s, window.window, n_steps=n,
                             load_step=(len(decks) + 1, n_pieces), notes=notes)
        if deck is not None:
            decks.append(deck)
        return steps

    fields = rerun_window(window.T_start, window.start_s, speeds, STEP_S, advance)
    return fields, ("".join(decks) if decks else None)


def _array(a: np.ndarray | None) -> dict | None:
    """An array as JSON: float64 values as their exact repr (JSON's floats round-trip)."""
    if a is None:
        return None
    a = np.asarray(a, dtype=float)
    return {"shape": list(a.shape), "values": a.ravel().tolist()}


def _from_array(d: dict | None) -> np.ndarray | None:
    return None if d is None else np.array(d["values"], dtype=float).reshape(d["shape"])


def method_replay_to_json(r: MethodReplay) -> str:
    """`r` as JSON text, every value exact (NaN as JSON's NaN token): what a replay done in
    another process sends back (twin.loop.runfiles), without pickling."""
    def window(w: WindowRecord) -> dict:
        c = w.correction
        return {
            "window": w.window, "start_s": w.start_s, "speed_rpm": w.speed_rpm,
            "ambient_C": w.ambient_C, "nominal": list(w.nominal), "deck": w.deck,
            "rerun_deck": w.rerun_deck, "start_C": _array(w.start_C),
            "correction": {
                "values": list(c.values), "C_H": list(c.C_H), "C_C": list(c.C_C),
                "factors": dict(c.factors), "state_C": _array(c.state_C),
                "band_sd": _array(c.band_sd), "sensor_lag_s": c.sensor_lag_s,
                "readings_start_C": _array(c.readings_start_C),
                "sensor_offset_C": _array(c.sensor_offset_C),
                "loads_follow_rings": c.loads_follow_rings, "coolant_C": c.coolant_C,
            },
        }

    return json.dumps({
        "method": r.method, "time_s": _array(r.time_s), "T_twin_C": _array(r.T_twin_C),
        "drift_z_um": _array(r.drift_z_um), "drift_r_um": _array(r.drift_r_um),
        "windows": [window(w) for w in r.windows],
        "fields": [[t, _array(T)] for t, T in r.fields.items()],
        "T_initial_C": r.T_initial_C, "wall_s": r.wall_s, "band_sd": _array(r.band_sd),
        "start_C": _array(r.start_C),
    })


def method_replay_from_json(text: str) -> MethodReplay:
    """The inverse of `method_replay_to_json`."""
    d = json.loads(text)

    def window(w: dict) -> WindowRecord:
        c = w["correction"]
        correction = Correction(
            *c["values"], C_H=tuple(c["C_H"]), C_C=tuple(c["C_C"]), factors=c["factors"],
            state_C=_from_array(c["state_C"]), band_sd=_from_array(c["band_sd"]),
            readings_start_C=_from_array(c["readings_start_C"]),
            sensor_lag_s=c["sensor_lag_s"], sensor_offset_C=_from_array(c.get("sensor_offset_C")),
            loads_follow_rings=c["loads_follow_rings"],
            coolant_C=c.get("coolant_C"))
        return WindowRecord(w["window"], w["start_s"], w["speed_rpm"], w["ambient_C"],
                            correction, BoundaryValues(*w["nominal"]), w["deck"],
                            w["rerun_deck"], _from_array(w["start_C"]))

    return MethodReplay(
        method=d["method"], time_s=_from_array(d["time_s"]), T_twin_C=_from_array(d["T_twin_C"]),
        drift_z_um=_from_array(d["drift_z_um"]), drift_r_um=_from_array(d["drift_r_um"]),
        windows=[window(w) for w in d["windows"]],
        fields={t: _from_array(T) for t, T in d["fields"]},
        T_initial_C=d["T_initial_C"], wall_s=d["wall_s"], band_sd=_from_array(d["band_sd"]),
        start_C=_from_array(d["start_C"]),
    )
