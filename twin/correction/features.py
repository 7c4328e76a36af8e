"""What a correction method sees of one window, and the network input vectors built from it.

Window k covers [60k, 60k + 60) s.  Causality: everything here was measured (or simulated
by the twin) at or before the window start; a method's output is a forecast of the
boundary values for the window to come.

Sensor columns follow the recorded-run schema: T1 front-bearing outer ring, T2 front
sleeve, T3 rear-bearing outer ring, T4 rear sleeve, T5 housing (REFERENCE.md §1).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from twin.contract import WINDOW_S

BEARINGS: tuple[str, ...] = ("front", "rear")
RING_SENSOR = {"front": 0, "rear": 2}
"""Column of the bearing's outer-ring key point (T1 front, T3 rear)."""
SLEEVE_SENSOR = {"front": 1, "rear": 3}
"""Column of the sleeve sensor next to the ring (T2 front, T4 rear)."""

OUTPUTS: tuple[str, ...] = ("heat_front", "heat_rear", "resistance_front", "resistance_rear")
"""The four networks / corrected values, in BoundaryValues order."""

HIDDEN_SIZES = {"heat": 10, "resistance": 12}
"""Hidden neurons of the paper's networks: heat 6-10-1, contact resistance 6-12-1."""

INPUT_NAMES = {
    "heat": (
        "speed_rpm",
        "ambient_C",
        "measured_ring_C",
        "simulated_ring_C",
        "run_time_s",
        "nominal_heat_W_m3",
    ),
    "resistance": (
        "speed_rpm",
        "ambient_C",
        "measured_ring_to_sleeve_C",
        "simulated_ring_to_sleeve_C",
        "run_time_s",
        "nominal_resistance_m2K_W",
    ),
}
"""Six inputs per network (the paper's choice).  The heat networks see the ring (key-point)
temperature; the resistance networks see the ring-to-sleeve drop, which carries the
contact-resistance signal."""

ANCHORED_INPUT_NAMES = {
    "heat": (
        "speed_rpm",
        "anchor_log_factor",
        "ring_level_error_per_rise",
        "ring_rise_error_per_rise",
        "run_time_s",
        "drop_level_error_per_drop",
    ),
    "resistance": (
        "speed_rpm",
        "anchor_log_factor",
        "drop_level_error_per_drop",
        "drop_rise_error_per_drop",
        "run_time_s",
        "ring_level_error_per_rise",
    ),
}
"""Six inputs per network of the anchored configuration (`twin.correction.network.ANCHORED`),
which learns a log-correction on the ratio-law value (the anchor).  Errors are measured
minus simulated key point (ring, or ring-to-sleeve drop) from a line through the last
window: the level the ratio law also reads, and the *rate* (rise over the window), which it
does not (a speed step or a lagging correction shows there first).  Both are relative:
divided by the twin's own ring rise over ambient (heat) or ring-to-sleeve drop (resistance),
at least `RELATIVE_ERROR_FLOOR_C`, as the ratio law's Eq. 2 and Eq. 6 divide.  The anchor's
log factor on nominal says where the ratio law stands; the sixth input is the level error of
the bearing's other key-point signal (the drop for a heat network, the ring for a resistance
network), which tells a heat error from a resistance error.  See
`WindowFeatures.anchored_inputs`.

Why not the network's own previous log-correction (the sixth input until the model of
2026-11-22): in training it is the previous window's look-ahead fit (or the anchor, or a
random scatter), a near copy of the target, and the networks learnt to repeat it (gain
0.88–0.94).  In closed loop they read their own output there instead, an integrator that
no measurement checks: on suite 31337 run 8 the rear resistance walked 1.5 → 5 → 0.2 of its
nominal value over 25 min while T4 ran 3 K off."""

RELATIVE_ERROR_FLOOR_C = 0.5
"""Least divisor (K) of the anchored networks' relative errors: ten times a thermocouple's
noise, as `twin.correction.formulas.RatioGuards.total`, so a rise or drop of the size of the
noise (the run's first seconds, a stop) does not blow the error up.

Why relative: the drop across a contact is heat flux × resistance, so a change δ of log R
moves it by about δ × drop.  With the error in kelvin, a network's gain on log R per window
is its weight × the drop: the bundled networks had learnt 0.53 per K on runs where the
front drop is 2–11 K, and at ≥ 14 000 rpm (drop 6–9 K) that closed loop exceeded the gain of
2 at which a per-window correction overshoots by more than it corrects.  Front resistance
and, through T1, the anchor's front heat then swung window by window (T1 ±1–2 K on suite
31337 runs 4 and 8 and suite 90210 run 3, where the ratio law alone held it within
0.3 K).  Per unit of the drop, the same error means the same δ at any speed, as in Eq. 6."""

SLEEVE_RISE_SHARE = 0.5
"""Where a ring sensor is dead, its sleeve's error is divided by the sleeve's rise over
ambient in the twin, but by no less than this share of the ring's
(`WindowFeatures.with_dead_rings_read_through_sleeves`): the bearing's share of the sleeve's
rise is its ring's share less the contact drop, and a sleeve on the cooling jacket rises
far less over ambient than that (or falls below it).  With the share, a heat error moves
the stand-in by at most twice the sleeve's heat sensitivity over the ring's rise."""

TARGET_UNITS = {"heat": "W/m³", "resistance": "m²K/W"}


def kind_of(output: str) -> str:
    """'heat' or 'resistance' for an output name such as 'heat_front'."""
    return output.split("_", 1)[0]


def bearing_of(output: str) -> str:
    """'front' or 'rear' for an output name such as 'heat_front'."""
    return output.split("_", 1)[1]


class BoundaryValues(NamedTuple):
    """The four corrected boundary values of one window."""

    H_front_W_m3: float
    H_rear_W_m3: float
    R_front_m2K_W: float
    R_rear_m2K_W: float


class TwinState(NamedTuple):
    """The twin's own state at a window start, for methods that re-simulate the window.

    Only the offline window fit that builds training targets (`twin.loop.windowfit`) uses
    it; the online methods see nothing but the measured and simulated key points.
    """

    field_C: np.ndarray
    """Temperature per degree of freedom of the twin's mesh, °C."""
    conditions: object
    """The window's nominal `twin.spindle.BoundaryConditions`."""


@dataclass(frozen=True)
class WindowFeatures:
    """Inputs of one correction step (window `window`, starting at `start_s`).

    measured_time_s (n,), measured_C (n, 5): the recorded T1..T5 up to the window start
    (later samples, if passed, are ignored: causality).  NaN marks a missing sample.
    simulated_time_s (m,), simulated_C (m, 5): the twin's own T1..T5 at its solver steps up
    to the window start (m may be 0 or 1 before the first window).
    nominal: Eq. 1 / Eq. 4 values at the current speed; previous: last window's values
    (equal to nominal for window 0); previous_nominal: the nominal values the previous
    window had (None: unchanged), so a correction can carry over a speed change as a factor.

    A stop (speed 0) is an ordinary window: the nominal bearing heat is 0 and so is any
    corrected heat (a stopped bearing has no heat to correct).  `previous_factors` carries
    each value's correction factor (value / nominal) through the stop, so the correction
    the spindle had before the stop resumes when it restarts.
    """

    window: int
    start_s: float
    speed_rpm: float
    ambient_C: float
    measured_time_s: np.ndarray
    measured_C: np.ndarray
    simulated_time_s: np.ndarray
    simulated_C: np.ndarray
    nominal: BoundaryValues
    previous: BoundaryValues
    window_s: float = WINDOW_S
    previous_nominal: BoundaryValues | None = None
    """Nominal values of the previous window, if the speed changed since (else = nominal)."""
    twin_state: TwinState | None = None
    """The twin's field and conditions at the window start (set by the loop)."""
    measured_drift_um: np.ndarray | None = None
    """(n,) the recorded axial nose drift at `measured_time_s` (NaN: invalid; None: not
    recorded, or left out as in mm or reversed: `twin.loop.findings.probe_left_out`), less
    the probe's start reading where it was not zeroed at the run start
    (`twin.loop.findings.probe_start_offset_um`).  Only an estimator told to assimilate it
    reads it."""
    measured_speed_rpm: np.ndarray | None = None
    """(n,) the recorded speed at `measured_time_s` (None: not passed).  An estimator
    re-runs the window just ended with it when the speed changed inside that window."""
    previous_factors: tuple[float, float, float, float] | None = None
    """Per value, the factor value / nominal of the last window in which the value was not
    0 (a stopped bearing keeps the factor it had before the stop).  None: derived from
    `previous` and `previous_nominal`, 1 where those are 0."""
    coolant_recorded: bool = True
    """Whether the run records its coolant inlet (`coolant_C`); False: the conditions
    assume the inlet at the ambient, and an estimator may estimate it."""
    measured_coolant_C: np.ndarray | None = None
    """(n,) the recorded coolant inlet at `measured_time_s` (None: not recorded or not
    passed).  An estimator re-runs the window just ended with it where the inlet moved
    inside that window."""

    def __post_init__(self) -> None:
        pairs = (("measured", self.measured_time_s), ("simulated", self.simulated_time_s))
        for name, rows in pairs:
            values = getattr(self, f"{name}_C")
            if np.ndim(values) != 2 or np.shape(values)[1] != 5 or len(values) != len(rows):
                raise ValueError(f"WindowFeatures.{name}_C must be ({len(rows)}, 5)")
        for name in ("nominal", "previous", "previous_nominal"):
            values = getattr(self, name)
            if values is not None and not values_allowed(values):
                raise ValueError(f"WindowFeatures.{name}: heats must be ≥ 0 (0 at a stop) "
                                 "and resistances positive")
        if self.previous_factors is not None and not all(
                np.isfinite(v) and v > 0 for v in self.previous_factors):
            raise ValueError("WindowFeatures.previous_factors must be positive")

    def previous_factor(self) -> np.ndarray:
        """Per value, the previous window's correction factor (see `previous_factors`)."""
        if self.previous_factors is not None:
            return np.asarray(self.previous_factors, dtype=float)
        return correction_factors(self.previous, self.previous_nominal or self.nominal)

    def carried_previous(self) -> np.ndarray:
        """The previous window's values carried to the current nominal values: a speed
        change moves them with the nominal (a factor), a stop takes the heat to 0 and a
        restart brings back the factor from before the stop."""
        return self.previous_factor() * np.asarray(self.nominal, dtype=float)

    def measured_now(self) -> np.ndarray:
        """T1..T5 measured: the last finite sample at or before the window start (°C)."""
        return last_at_or_before(self.measured_time_s, self.measured_C, self.start_s)

    def simulated_now(self) -> np.ndarray:
        """T1..T5 of the twin at the window start (°C)."""
        return last_at_or_before(self.simulated_time_s, self.simulated_C, self.start_s)

    def measured_initial(self) -> np.ndarray:
        """T1..T5 at the start of the run: the first finite sample of each sensor (°C)."""
        return first_finite(self.measured_C)

    def seen_in_last_window(self) -> np.ndarray:
        """(5,) True for each of T1..T5 measured through the last window
        (`window_observed`: valid samples in each of its bins, so a line through them gives
        a level at the window start and a rise that are measurements)."""
        return window_observed(self.measured_time_s, self.measured_C, self.start_s,
                               self.window_s)

    def dead_rings(self) -> tuple[str, ...]:
        """Bearings whose ring sensor was not measured through the last window while the
        sleeve sensor was (`seen_in_last_window`: a stuck or dropped-out ring
        thermocouple)."""
        seen = self.seen_in_last_window()
        return tuple(b for b in BEARINGS if not seen[RING_SENSOR[b]] and seen[SLEEVE_SENSOR[b]])

    def without_dead_sensors(self) -> WindowFeatures:
        """These features with the measured column of every sensor not measured through
        the last window (`seen_in_last_window`: a dropout, a logger gap, a stuck sensor)
        left out entirely (NaN): a correction then holds what that sensor would correct
        instead of reading its last value before it died.

        Why: read on its last valid sample, as `RatioCorrection` was where the last window
        had none (until 2026-11-27), a sensor in a dropout gave a stale value.  For a sleeve
        that stale value entered the Eq. 5
        pressure factor of *now* while the factor of the window before (level minus rise,
        and the rise is unknown) was neutral, so every window of the dropout multiplied
        the resistance by the whole pressure factor since the start: a rear sleeve lost
        for 6 min across a step to 14 500 rpm took the rear resistance to its lower guard,
        and the twin's T4 needed 15 min to come back (suite 555 run 4).  The drop ratio
        (Eq. 6) compared the stale sleeve with the twin's moving one as well.  Without the
        column every factor it enters is neutral: the resistance is held until the sleeve
        reads again (a dead ring is then read through its sleeve,
        `with_dead_rings_read_through_sleeves`).
        """
        seen = self.seen_in_last_window()
        if seen.all():
            return self
        measured = self.measured_C.copy()
        measured[:, ~seen] = np.nan
        return dataclasses.replace(self, measured_C=measured)

    def with_dead_rings_read_through_sleeves(self) -> WindowFeatures:
        """These features with the measured ring column of each of `dead_rings` replaced
        by a stand-in read through its sleeve: the twin's ring off the measurement by the
        sleeve's error e (measured minus twin) scaled to the ring's rise,

            ring(t) = t_f,ring(t) + (t_f,ring − t_amb)/D · e(t),
            D = max(t_f,sleeve − t_amb, SLEEVE_RISE_SHARE · (t_f,ring − t_amb))

        (the twin's rises at the window start).  Eq. 2 then reads 1 + e/D: the sleeve's
        error over its own rise over ambient where that rise is the bearing's (the rear
        sleeve, 0.7 of its ring's on suite 550055 run 8), over half the ring's where the
        cooling jacket holds the sleeve near the coolant (the front sleeve, 0.2 of its
        ring's there, at or below ambient with a cold coolant).  The step has the sign of
        the sleeve's error on either side of ambient.  No stand-in (NaN: the heat is held)
        where the twin's ring is not over ambient.  The stand-in is written over the window
        just ended and at the sleeve's first valid sample, what the ratio law reads (NaN
        between).  The simulated columns are left as they are.  The stand-in's drop says
        nothing about the contact: the anchor holds a dead ring's resistance
        (`twin.correction.methods.ratio_anchor`).

        Why not the sleeve itself in Eq. 2, (t_m,sleeve − t_amb)/(t_f,sleeve − t_amb), as
        until 2026-11-27: a sleeve whose rise over ambient is not the bearing's turns the
        ratio into nonsense.  With the coolant below ambient both rises were negative and
        the ratio inverted: a twin sleeve colder than the measured one cut the heat, which
        cooled it further, down to the guard's 0.2× nominal (suite 550055 run 8, T1 stuck,
        coolant 1.8 K below ambient: T2 1.68 K RMS off against 0.21 K for the ratio law,
        which holds the heat; 97.76 against 99.00 %).  Near ambient the rise was within the
        guard's floor and the heat stayed wherever the first windows had put it.

        Measured on emulated runs of 40 min with T1 or T3 stuck for the whole run (suite
        distribution; and T1 with the coolant 1–2 K below ambient and a slow first speed),
        4 tuning sets of 12: with the divisor t_f,ring − t_amb alone (D's share 1) the mean
        temperature accuracy went −0.04, −0.01, +0.08, +0.51 points against the sleeve
        over ambient (the rear sleeve read slower); with the share 0.5 −0.004, +0.007,
        +0.09, +0.52 (0.3: about the same, 0.7 between); runs at or above the ratio law's
        temperature accuracy 40 → 46 of 48 (the two others −0.07 and −0.03, lost on the
        rear bearing, whose ring reads, as before).
        """
        dead = self.dead_rings()
        if not dead:
            return self
        measured = self.measured_C.copy()
        twin_now = (self.simulated_now() if len(self.simulated_time_s)
                    else np.full(measured.shape[1], np.nan))
        time = np.asarray(self.measured_time_s, dtype=float)
        recent = rows_between(time, self.start_s - self.window_s - 1e-9, np.inf).start
        for bearing in dead:
            ring, sleeve = RING_SENSOR[bearing], SLEEVE_SENSOR[bearing]
            ring_rise = twin_now[ring] - self.ambient_C
            measured[:, ring] = np.nan
            if not ring_rise > 0.0:  # no twin yet, or no rise to scale a heat error by
                continue
            divisor = max(twin_now[sleeve] - self.ambient_C, SLEEVE_RISE_SHARE * ring_rise)

            def stand_in(rows: np.ndarray, ring: int = ring, sleeve: int = sleeve,
                         scale: float = ring_rise / divisor) -> bool:
                """Write the stand-in at `rows`; whether it is finite wherever the
                sleeve is."""
                twin_ring, twin_sleeve = (
                    np.interp(time[rows], self.simulated_time_s, self.simulated_C[:, c])
                    for c in (ring, sleeve))
                sleeve_C = measured[rows, sleeve]
                measured[rows, ring] = twin_ring + scale * (sleeve_C - twin_sleeve)
                return bool(np.isfinite(measured[rows, ring])[np.isfinite(sleeve_C)].all())

            # written where it is read: over the window just ended (its line, its bins,
            # its last value) and at the sleeve's first valid sample (the run's initial
            # value); the rows between stay NaN.  The whole column, as until 2026-11-27,
            # cost a 24-h run's last windows 86 400 rows each.  Where the twin's history
            # has a gap (NaN) there, the whole column, so every reader gets the same.
            first = _finite_rows(measured[:recent, [sleeve]], last=False)
            if not stand_in(np.r_[first[first >= 0], recent:time.size]):
                stand_in(np.arange(time.size))
        return dataclasses.replace(self, measured_C=measured)

    def anchored_inputs(self, anchor: ArrayLike) -> dict[str, np.ndarray]:
        """The (1, 6) input row of each anchored network (ANCHORED_INPUT_NAMES) for this
        window, given the anchor values (4,) in BoundaryValues order.

        A row is NaN where it has no meaning — window 0 (no rise yet), a stopped bearing's
        heat, a missing sensor, a dead ring (the networks never saw a sleeve standing in for
        it) — and the correction then keeps the anchor.
        """
        meas_level, meas_rise = window_line_fit(self.measured_time_s, self.measured_C,
                                                self.start_s, self.window_s)
        sim_level, sim_rise = window_line_fit(self.simulated_time_s, self.simulated_C,
                                              self.start_s, self.window_s)
        level_error, rise_error = meas_level - sim_level, meas_rise - sim_rise
        floor = RELATIVE_ERROR_FLOOR_C
        with np.errstate(divide="ignore", invalid="ignore"):
            anchor_log = np.log(np.asarray(anchor, dtype=float)
                                / np.asarray(self.nominal, dtype=float))
        dead = self.dead_rings()
        out = {}
        for bearing in BEARINGS:
            ring, sleeve = RING_SENSOR[bearing], SLEEVE_SENSOR[bearing]
            # NaN (no twin value) stays NaN through max(): no row
            rise_scale = max(abs(sim_level[ring] - self.ambient_C), floor)
            drop_scale = max(abs(sim_level[ring] - sim_level[sleeve]), floor)
            ring_errors = np.array([level_error[ring], rise_error[ring]]) / rise_scale
            drop_errors = np.array([level_error[ring] - level_error[sleeve],
                                    rise_error[ring] - rise_error[sleeve]]) / drop_scale
            for kind, own, other in (("heat", ring_errors, drop_errors),
                                     ("resistance", drop_errors, ring_errors)):
                output = f"{kind}_{bearing}"
                row = [self.speed_rpm, anchor_log[OUTPUTS.index(output)], own[0], own[1],
                       self.start_s, other[0]]
                out[output] = np.asarray(row, dtype=float)[None, :]
                if bearing in dead:
                    out[output][:] = np.nan
        return {o: out[o] for o in OUTPUTS}

    def network_inputs(self) -> dict[str, np.ndarray]:
        """The (1, 6) input row of each network for this window."""
        return network_inputs(
            speed_rpm=[self.speed_rpm],
            ambient_C=[self.ambient_C],
            run_time_s=[self.start_s],
            measured_C=self.measured_now()[None, :],
            simulated_C=self.simulated_now()[None, :],
            nominal=np.asarray(self.nominal, dtype=float)[None, :],
        )


def values_allowed(values: ArrayLike) -> bool:
    """True for four boundary values with heats ≥ 0 (0 at a stop) and resistances > 0."""
    v = np.asarray(values, dtype=float)
    return bool(np.all(np.isfinite(v)) and np.all(v[:2] >= 0) and np.all(v[2:] > 0))


def correction_factors(values: ArrayLike, nominal: ArrayLike,
                       fallback: ArrayLike | float = 1.0) -> np.ndarray:
    """values / nominal, or `fallback` where the nominal value is 0 (a stopped bearing)."""
    v = np.asarray(values, dtype=float)
    nom = np.asarray(nominal, dtype=float)
    running = nom > 0
    return np.where(running, v / np.where(running, nom, 1.0), fallback)


def last_at_or_before(time_s: ArrayLike, values: ArrayLike, t_s: float) -> np.ndarray:
    """Per column, the last finite value sampled at or before t_s (NaN if there is none);
    `time_s` ascending (`rows_between`)."""
    time = np.asarray(time_s, dtype=float)
    vals = np.asarray(values, dtype=float).reshape(time.size, -1)
    usable = vals[rows_between(time, -np.inf, t_s + 1e-9)]
    return _finite_at(usable, _finite_rows(usable, last=True))


def first_finite(values: ArrayLike) -> np.ndarray:
    """Per column, the first finite value (NaN if there is none)."""
    vals = np.asarray(values, dtype=float)
    return _finite_at(vals, _finite_rows(vals, last=False))


def _finite_at(vals: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Per column j, vals[rows[j], j], NaN where rows[j] is −1."""
    out = np.full(vals.shape[1], np.nan)
    found = rows >= 0
    out[found] = vals[rows[found], np.flatnonzero(found)]
    return out


def _finite_rows(vals: np.ndarray, last: bool) -> np.ndarray:
    """Per column of `vals` (n, m), the row of its first (`last`: last) finite value, −1
    where it has none.  The rows are read in blocks doubling from that end, so a column
    valid near it costs a block, not the whole history: a loop window reads the last
    value and the run's first, and a whole-history scan made each window's cost grow with
    the run (a 24-h replay's last windows read 86 400 rows for each)."""
    n, m = vals.shape
    rows = np.full(m, -1)
    todo = np.arange(m)
    done, size = 0, 64
    while todo.size and done < n:
        upto = min(n, done + size)
        block = vals[n - upto:n - done][::-1] if last else vals[done:upto]
        finite = np.isfinite(block[:, todo])
        found = finite.any(axis=0)
        at = done + finite.argmax(axis=0)[found]
        rows[todo[found]] = n - 1 - at if last else at
        todo = todo[~found]
        done, size = upto, 2 * size
    return rows


def rows_between(time_s: np.ndarray, after_s: float, upto_s: float,
                 with_upto: bool = True) -> slice:
    """The rows of `time_s` with after_s < t <= upto_s (`with_upto` False: < upto_s), for
    times in ascending order (a run's, whose reader refuses time going back, and the
    twin's steps): found by bisection, so a window reading its last 60 s costs the same in
    a run's 24th hour as in its first.  A boolean mask over the whole history, as until
    2026-11-27, made every window's reads grow with the run (the same rows, in the same
    order)."""
    return slice(int(np.searchsorted(time_s, after_s, side="right")),
                 int(np.searchsorted(time_s, upto_s, side="right" if with_upto else "left")))


OBSERVATION_BINS = 3
"""A window's measurements are read in this many equal bins (20 s): the estimator's
observations are their means, and a correction reads a sensor only where every bin of the
window just ended is observed (`window_observed`)."""

MIN_BIN_SAMPLES = 2
"""A bin is observed with at least this many valid samples: a lone sample is too noisy,
where the logger fills a bin with twice as many rows (`min_bin_samples`)."""


def min_bin_samples(time_s: ArrayLike, window_s: float = WINDOW_S) -> int:
    """How many valid samples make a bin of a window observed, from the window's own rows
    (`time_s`, any column valid or not): `MIN_BIN_SAMPLES` where the logger's median
    interval fills a bin with at least twice that many, else 1.  At 0.1 Hz, the slowest
    rate a run may have, a 20 s bin holds two rows, and ±0.3 s of time-stamp jitter put one
    in every other bin: ratio and bpnn held their corrections in 21 of 29 windows of a
    clean run, and the estimator left those bins out."""
    t = np.asarray(time_s, dtype=float)
    if t.size < 2:
        return MIN_BIN_SAMPLES
    interval = float(np.median(np.diff(t)))
    rows_per_bin = window_s / OBSERVATION_BINS / interval if interval > 0 else np.inf
    return MIN_BIN_SAMPLES if rows_per_bin >= 2 * MIN_BIN_SAMPLES else 1


def bin_mean(time_s: np.ndarray, values: np.ndarray, lo_s: float,
             hi_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Per column, the mean of the finite values sampled in (lo_s, hi_s] and their count
    (`time_s` ascending: `rows_between`)."""
    v = values[rows_between(time_s, lo_s + 1e-9, hi_s + 1e-9)]
    ok = np.isfinite(v)
    counts = ok.sum(axis=0)
    total = np.where(ok, v, 0.0).sum(axis=0)
    return np.where(counts > 0, total / np.maximum(counts, 1), np.nan), counts


def window_observed(time_s: ArrayLike, values: ArrayLike, end_s: float,
                    window_s: float = WINDOW_S) -> np.ndarray:
    """Per column, True where each of the `OBSERVATION_BINS` bins of (end_s − window_s,
    end_s] holds at least `min_bin_samples` valid (finite) samples: the estimator's rule
    for an observation, over the whole window that `window_line_fit` reads (`time_s`
    ascending).

    Why the whole window: the ratio law reads a level at end_s and a rise over the window
    off a line through its samples.  With the last bins lost (a logger gap) that line
    extrapolates the last measured seconds over the rest of the window, and a lone sample
    at the window's start gave a level 60 s old and no rise, so Eq. 5 took the whole
    pressure change since the run start as this window's.
    """
    time = np.asarray(time_s, dtype=float)
    vals = np.asarray(values, dtype=float)
    vals = vals[:, None] if vals.ndim == 1 else vals
    edges = end_s - window_s + window_s * np.arange(OBSERVATION_BINS + 1) / OBSERVATION_BINS
    needed = min_bin_samples(time[rows_between(time, edges[0] + 1e-9, end_s + 1e-9)],
                             window_s)
    observed = np.ones(vals.shape[1], dtype=bool)
    for lo, hi in zip(edges[:-1], edges[1:], strict=True):
        observed &= bin_mean(time, vals, lo, hi)[1] >= needed
    return observed


def window_line_fit(
    time_s: ArrayLike, values: ArrayLike, end_s: float, window_s: float = WINDOW_S
) -> tuple[np.ndarray, np.ndarray]:
    """Per column, (level at end_s in °C, rise over the span in K) of a least-squares line
    through the finite samples in (end_s − window_s, end_s] (`time_s` ascending).

    Sensor noise averages out instead of entering a two-point difference at full size.
    A column with a single sample gives that sample as level and NaN rise; with none, NaN.
    """
    time = np.asarray(time_s, dtype=float)
    vals = np.asarray(values, dtype=float).reshape(time.size, -1)
    in_span = rows_between(time, end_s - window_s - 1e-9, end_s + 1e-9)
    time, vals = time[in_span], vals[in_span]
    level = np.full(vals.shape[1], np.nan)
    rise = np.full(vals.shape[1], np.nan)
    for j in range(vals.shape[1]):
        ok = np.isfinite(vals[:, j])
        t = time[ok]
        if t.size == 1:
            level[j] = vals[ok, j][0]
        if t.size < 2 or np.ptp(t) <= 0:
            continue
        t_mean = t.mean()
        slope, mean = np.polyfit(t - t_mean, vals[ok, j], 1)
        level[j] = mean + slope * (end_s - t_mean)
        rise[j] = slope * window_s
    return level, rise


def rise_over_window(
    time_s: ArrayLike, values: ArrayLike, end_s: float, window_s: float = WINDOW_S
) -> np.ndarray:
    """Per column, the rise (K) over (end_s − window_s, end_s] of `window_line_fit`."""
    return window_line_fit(time_s, values, end_s, window_s)[1]


def network_inputs(
    *,
    speed_rpm: ArrayLike,
    ambient_C: ArrayLike,
    run_time_s: ArrayLike,
    measured_C: ArrayLike,
    simulated_C: ArrayLike,
    nominal: ArrayLike,
) -> dict[str, np.ndarray]:
    """The (N, 6) input matrix of each of the four networks (columns as in INPUT_NAMES).

    measured_C, simulated_C: (N, 5) T1..T5; nominal: (N, 4) in BoundaryValues order.
    """
    speed = np.asarray(speed_rpm, dtype=float)
    amb = np.asarray(ambient_C, dtype=float)
    time = np.asarray(run_time_s, dtype=float)
    meas = np.asarray(measured_C, dtype=float)
    sim = np.asarray(simulated_C, dtype=float)
    nom = np.asarray(nominal, dtype=float)
    out = {}
    for i, output in enumerate(OUTPUTS):
        bearing = bearing_of(output)
        ring, sleeve = RING_SENSOR[bearing], SLEEVE_SENSOR[bearing]
        if kind_of(output) == "heat":
            m, s = meas[:, ring], sim[:, ring]
        else:
            m = meas[:, ring] - meas[:, sleeve]
            s = sim[:, ring] - sim[:, sleeve]
        out[output] = np.column_stack([speed, amb, m, s, time, nom[:, i]])
    return out
