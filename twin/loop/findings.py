"""What a replay tells of its run beyond the quality check (`twin.runs.quality`): the
quality.json findings that need the loop's own rules or the twin.

- `correction_held`: windows a ring or sleeve thermocouple was not measured through, where
  `ratio` and `bpnn` hold what it corrects;
- `not_replayed`: the samples after the last whole 60 s window;
- the axial probe as the twin reads it (`disp_z_um`, µm, its drift from 0 at the run
  start, growing as the spindle warms): `probe_not_zeroed` (the correction methods read
  its change from its start reading), `probe_in_mm` and `probe_reversed` (they leave it
  out; `probe_left_out`);
- `warms_unlike_twin`: the thermocouples warm many times more than the open-loop twin at
  the recorded speeds (a speed column in rev/s or krpm), told of a start at rest only;
- `warm_start`: the recording begins on a warm spindle, and the replay starts from a field
  fitted to the first readings (`twin.loop.start_field`).

Every finding is told; none changes what the metrics compare with: the readings as
recorded (DESIGN.md), the quality check's exclusions aside.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from twin.contract import WINDOW_S, windows_in
from twin.correction.features import (
    MIN_BIN_SAMPLES,
    OBSERVATION_BINS,
    RING_SENSOR,
    SLEEVE_SENSOR,
    rows_between,
    window_observed,
)
from twin.loop.start_field import SOURCES, WARM_START_SPREAD_K, StartField
from twin.runs import TEMPERATURES, RecordedRun
from twin.runs.quality import (
    AXIAL_PROBE,
    FLAT_IN_MM,
    QualityConfig,
    finding,
    flat_probe,
    running_s,
    true_runs,
)

if TYPE_CHECKING:
    from twin.spindle.model import SpindleModel


RING_AND_SLEEVE = tuple(sorted({*RING_SENSOR.values(), *SLEEVE_SENSOR.values()}))
"""T1..T4 by index: the thermocouples the bearing values are corrected by."""

HELD_CORRECTION = "correction_held"
"""quality.json kind of `held_correction_findings`."""
HOLDING_METHODS = ("ratio", "bpnn")
"""The methods that hold what a thermocouple corrects through windows it was not measured
in (`WindowFeatures.without_dead_sensors`)."""


def held_correction_findings(run: RecordedRun, methods: Sequence[str]) -> list[dict]:
    """quality.json findings (`twin.runs.quality.finding`): per ring and sleeve
    thermocouple (T1..T4, what `ratio` and `bpnn` correct by), the windows whose correction
    finds it not measured through the 60 s before the window starts
    (`WindowFeatures.seen_in_last_window`: a logger gap, a long dropout, a stuck sensor).
    They compute nothing from it there and hold what it corrects; the estimator leaves
    its unobserved bins out of its update.  Spans are the held windows' [start, end) in
    run time; the count is of windows (`count_windows`), where the quality check's
    findings count samples.  None unless one of `HOLDING_METHODS` is among `methods`:
    nothing held a correction then."""
    holding = [m for m in HOLDING_METHODS if m in methods]
    if not holding:
        return []
    action = (f"{' and '.join(holding)} compute{'s' if len(holding) == 1 else ''} nothing "
              f"from this sensor in these windows and hold{'s' if len(holding) == 1 else ''} "
              "what it corrects")
    if "estimator" in methods:
        action += "; the estimator leaves its unobserved bins out"
    measured = run.T_valid_C
    # window k's correction reads up to 60k s
    ends = WINDOW_S * np.arange(1, windows_in(run.duration_s))
    spans = [rows_between(run.time_s, end - WINDOW_S - 1e-9, end + 1e-9) for end in ends]
    unseen = np.array([~window_observed(run.time_s[rows], measured[rows], end)
                       for rows, end in zip(spans, ends, strict=True)]).reshape(-1, 5)
    found = []
    for column in RING_AND_SLEEVE:
        stretches = true_runs(unseen[:, column])
        if not stretches:
            continue
        windows = ", ".join(f"{a + 1}" if a == b else f"{a + 1}-{b + 1}" for a, b in stretches)
        found.append(finding(
            TEMPERATURES[column], HELD_CORRECTION, action,
            spans_s=[(ends[a], ends[b] + WINDOW_S) for a, b in stretches],
            count=int(unseen[:, column].sum()), counted="windows",
            detail=f"fewer than {MIN_BIN_SAMPLES} valid samples (1 where the logger writes "
                   f"fewer than {2 * MIN_BIN_SAMPLES} rows in it) in a "
                   f"{WINDOW_S / OBSERVATION_BINS:g} s bin of the {WINDOW_S:g} s before the "
                   f"start of window {windows}"))
    return found


NOT_REPLAYED = "not_replayed"
"""quality.json kind of `tail_findings`."""


def tail_findings(run: RecordedRun) -> list[dict]:
    """The quality.json finding (`twin.runs.quality.finding`) of the samples after the
    run's last whole 60 s window, which a replay neither solves nor scores: a 150 s run
    was replayed and scored over 120 s, and neither quality.json nor the report said so."""
    end = windows_in(run.duration_s) * WINDOW_S
    after = np.flatnonzero(run.time_s > end + 1e-6)
    if after.size == 0:
        return []
    return [finding("time_s", NOT_REPLAYED,
                    "not replayed and not scored: a replay solves whole 60 s windows",
                    rows=run.rows[after[:1]], count=after.size,
                    spans_s=[(end, run.duration_s)],
                    detail=f"the {run.duration_s - end:g} s after the last whole window "
                           f"(ends at {end:g} s)")]


PROBE_NOT_ZEROED = "probe_not_zeroed"
"""quality.json kind of `probe_offset_findings`."""

PROBE_ZERO_TOLERANCE_UM = 2.0
"""How far the axial probe's first reading may lie from 0 before quality.json tells it:
nearly seven times the largest probe noise a suite draws (0.3 µm), so that no emulated
run's noise is told as an offset."""


def probe_start_reading(run: RecordedRun) -> int | None:
    """The sample of the axial probe's start reading: its first valid one where that lies
    in the run's first window (a probe whose log starts late, its first cells a gap too
    long to fill), else None (no probe, or none read that early: the twin's drift may have
    moved by then)."""
    if run.disp_um is None or AXIAL_PROBE not in run.valid:
        return None
    valid = np.flatnonzero(run.valid[AXIAL_PROBE])
    if not valid.size or run.time_s[valid[0]] - run.time_s[0] > WINDOW_S:
        return None
    return int(valid[0])


def probe_start_offset_um(run: RecordedRun) -> float:
    """The axial probe's start reading (`probe_start_reading`) where it was not zeroed
    there (more than `PROBE_ZERO_TOLERANCE_UM` from 0), else 0, µm.  The twin's drift
    starts at 0 at the run start (its uniform start field), so the correction methods read
    the probe's change from that reading; the scores compare with the readings as
    recorded.  Read only at the first sample, as until 2026-11-27, a probe 50 µm off whose
    first cells were blank was taken as zeroed and assimilated as recorded."""
    i = probe_start_reading(run)
    if i is None or run.disp_um is None:
        return 0.0
    first = float(run.disp_um[i, 2])
    return first if abs(first) > PROBE_ZERO_TOLERANCE_UM else 0.0


def probe_offset_findings(run: RecordedRun) -> list[dict]:
    """The quality.json finding of an axial probe that does not read about 0 at the run's
    start (`probe_start_offset_um`).  A probe zeroed elsewhere, 50 µm off, scored 15 %
    deformation accuracy for open loop and, assimilated as recorded, pulled the
    estimator's temperatures off (99.86 → 96.80 %) without a word of the cause."""
    offset = probe_start_offset_um(run)
    i = probe_start_reading(run)
    if offset == 0.0 or i is None:
        return []
    when = "the start" if i == 0 else f"{run.time_s[i] - run.time_s[0]:g} s"
    return [finding(AXIAL_PROBE, PROBE_NOT_ZEROED,
                    "scored as recorded: the twin's drift starts at 0 µm at the run start; "
                    "zero the probe there (or subtract its first reading). The estimator "
                    "reads the change from that reading",
                    rows=run.rows[i:i + 1],
                    detail=f"reads {offset:.3g} µm at {when}, more than "
                           f"{PROBE_ZERO_TOLERANCE_UM:g} µm from 0")]


PROBE_IN_MM = "probe_in_mm"
"""quality.json kind of `probe_scale_findings`."""


def probe_in_mm(run: RecordedRun) -> tuple[float, float] | None:
    """(largest |reading| µm, time at speed s) of an axial probe that reads next to
    nothing while the spindle runs (`twin.runs.quality.flat_probe`, `FLAT_IN_MM`): a
    column written in mm, the twin's disp_z_um being µm.  None for a probe that reads the
    drift (or none recorded; a frozen one the quality check excluded)."""
    if run.disp_um is None or AXIAL_PROBE not in run.valid:
        return None
    valid = run.valid[AXIAL_PROBE]
    flat = flat_probe(run.time_s, run.disp_um[:, 2], run.speed_rpm, valid, QualityConfig())
    if flat is None or flat[0] != FLAT_IN_MM:
        return None
    return float(np.max(np.abs(run.disp_um[valid, 2]))), flat[2]


def probe_scale_findings(run: RecordedRun) -> list[dict]:
    """The quality.json finding of an axial probe in mm (`probe_in_mm`): it scored
    -82 381 % deformation accuracy and, assimilated, pulled the estimator's temperatures
    off (99.86 → 97.33 %) without a word of the cause.  Scored as recorded (the user's
    file says so); left out of the correction inputs, as a stuck sensor is."""
    told = probe_in_mm(run)
    if told is None:
        return []
    span, at_speed_s = told
    return [finding(AXIAL_PROBE, PROBE_IN_MM,
                    "scored as recorded, excluded from correction inputs: the column is in "
                    "µm (a reading in mm is 1000 times too small)",
                    count=int(run.valid[AXIAL_PROBE].sum()),
                    detail=f"every reading within ±{span:.3g} µm through "
                           f"{at_speed_s / 60:.0f} min at speed: in mm?")]


PROBE_REVERSED = "probe_reversed"
"""quality.json kind of `probe_direction_findings`."""

PROBE_REVERSED_CORRELATION = -0.5
"""A probe whose readings correlate with the thermocouples' mean at most this much, the
twin's drift growing as the spindle warms, reads the drift the other way round.  Over 24
emulated suite runs and the bundled runs (speed steps, stops, coolant and ambient swings)
the correlation lay between +0.86 and +0.99."""


def probe_reversed(run: RecordedRun, model: SpindleModel) -> float | None:
    """The correlation of the axial probe's readings with the mean of the valid T1..T5
    where it runs against the twin's: the twin's nose drift for a uniform warming
    (`model.probe_vectors`) has one sign, a probe mounted or logged the other way round
    the opposite one (a real machine's probes read either way: two of five on the machine
    of `examples/real` fall as it warms).  None unless the probe moved more than
    `PROBE_ZERO_TOLERANCE_UM` through `QualityConfig.probe_flat_running_s` at speed and
    correlates at most `PROBE_REVERSED_CORRELATION` (signed by the twin's direction)."""
    if run.disp_um is None or AXIAL_PROBE not in run.valid:
        return None
    valid = run.valid[AXIAL_PROBE]
    cfg = QualityConfig()
    T = run.T_valid_C
    read = np.isfinite(T).sum(axis=1)
    T_mean = np.where(read > 0, np.nansum(T, axis=1) / np.maximum(read, 1), np.nan)
    both = valid & (read > 0)
    if both.sum() < 3 or running_s(run.time_s, run.speed_rpm, both, cfg.max_gap_s) < \
            cfg.probe_flat_running_s:
        return None
    x = run.disp_um[both, 2]
    if np.ptp(x) <= PROBE_ZERO_TOLERANCE_UM or np.ptp(T_mean[both]) == 0:
        return None
    warming = float(np.sign(model.probe_vectors[0].sum()))
    correlation = warming * float(np.corrcoef(x, T_mean[both])[0, 1])
    return correlation if correlation <= PROBE_REVERSED_CORRELATION else None


def probe_direction_findings(run: RecordedRun, model: SpindleModel) -> list[dict]:
    """The quality.json finding of an axial probe read the other way round
    (`probe_reversed`).  Assimilated, one negated on the 9000 rpm bundled run pulled the
    estimator's temperatures from 99.86 to 97.40 %, and every method scored about -85 %
    deformation accuracy without a word of the cause."""
    correlation = probe_reversed(run, model)
    if correlation is None:
        return []
    return [finding(AXIAL_PROBE, PROBE_REVERSED,
                    "scored as recorded, excluded from correction inputs: disp_z_um is the "
                    "twin's axial nose drift, which grows as the spindle warms; negate the "
                    "column if the probe reads the other way round",
                    count=int(run.valid[AXIAL_PROBE].sum()),
                    detail=f"falls as the thermocouples warm (correlation "
                           f"{correlation:+.2f} with their mean)")]


def probe_left_out(run: RecordedRun, model: SpindleModel) -> bool:
    """True where the correction methods do not read the axial probe although it was
    recorded: in mm (`probe_in_mm`) or read the other way round (`probe_reversed`); both
    are told in quality.json and scored as recorded."""
    return probe_in_mm(run) is not None or probe_reversed(run, model) is not None


WARMS_UNLIKE_TWIN = "warms_unlike_twin"
"""quality.json kind of `warming_findings`."""

WARMING_RATIO = 3.0
WARMING_MIN_RISE_K = 3.0
"""Told where the ring and sleeve thermocouples' rise (the median over T1..T4 of each
one's largest rise over its first reading) is `WARMING_RATIO` times the open-loop twin's
at the recorded speeds or more, and at least `WARMING_MIN_RISE_K`.  Not the other way
round: a run that starts warm rises less than the twin started from a uniform field.
Over 244 emulated runs (suites of 20-90 min, and families beyond the suite's: motor and
film factors up to 1.6, long stops, coolant and ambient swings, slow or misplaced
thermocouples) the ratio lay between 0.65 and 1.56, none told; the bundled 9000 rpm run's
speed logged in rev/s gave 21, in krpm 28."""


def warming_findings(open_loop_C: np.ndarray | None, open_loop_start_C: np.ndarray,
                     measured_C: np.ndarray, measured_start_C: np.ndarray) -> list[dict]:
    """The quality.json finding of a run whose thermocouples warm many times more than the
    open-loop twin at its recorded speeds (`WARMING_RATIO`): a speed logged in rev/s or
    krpm (150 or 9 for 9000 rpm) replayed as rpm with next to no bearing heat, every
    method scoring 79 % temperature accuracy without a word of the cause.
    `open_loop_C` (k, 5): the open-loop twin's T1..T5 at the replay's steps from its
    start field, whose T1..T5 are `open_loop_start_C` (5,) (None: open loop not replayed,
    nothing told); `measured_C` (k, 5) the readings then (NaN where invalid),
    `measured_start_C` (5,) their first."""
    if open_loop_C is None:
        return []
    measured_rise, twin_rise = [], []
    for k in RING_AND_SLEEVE:
        column = measured_C[:, k] - measured_start_C[k]
        if not np.isfinite(column).any():
            continue
        measured_rise.append(float(np.nanmax(column)))
        twin_rise.append(float(np.max(open_loop_C[:, k]) - open_loop_start_C[k]))
    if not measured_rise:
        return []
    measured, twin = float(np.median(measured_rise)), float(np.median(twin_rise))
    if measured < WARMING_MIN_RISE_K or measured < WARMING_RATIO * max(twin, 1e-3):
        return []
    return [finding("speed_rpm", WARMS_UNLIKE_TWIN,
                    "scored as recorded: every method replays the speeds as recorded",
                    detail=f"the ring and sleeve thermocouples rise {measured:.1f} K, "
                           f"{measured / max(twin, 1e-3):.0f} times more than the open-loop "
                           f"twin at the recorded speeds ({twin:.1f} K): speed_rpm in rpm? "
                           "(a speed in rev/s reads 60 times, one in krpm 1000 times too "
                           "slow)")]


WARM_START = "warm_start"
"""quality.json kind of `start_findings`."""


def start_findings(run: RecordedRun, start: StartField) -> list[dict]:
    """The quality.json finding of a recording that begins on a warm spindle: the replay
    starts from a field fitted to the first readings, not from a uniform one."""
    if start.uniform:
        return []
    scales = ", ".join(f"{name} {a:.2f}" for name, a in zip(SOURCES, start.scales,
                                                             strict=True))
    return [finding(TEMPERATURES[0], WARM_START,
                    "the replay starts from a field fitted to the first readings (every "
                    "method); the drift is taken from there",
                    rows=run.rows[:1],
                    detail=f"the first T1..T5 spread more than {WARM_START_SPREAD_K:g} K: "
                           f"fitted as {start.history} (source scales {scales}), "
                           f"T1..T5 within {start.misfit_K:.2f} K RMS")]


def replay_findings(run: RecordedRun, model: SpindleModel, methods: Sequence[str],
                    open_loop_C: np.ndarray | None, open_loop_start_C: np.ndarray,
                    measured_C: np.ndarray, measured_start_C: np.ndarray,
                    start: StartField) -> list[dict]:
    """Every finding of this module for a replay of `run` with `methods` (the open-loop
    twin's key points as `warming_findings` reads them; `start` the replay's start
    field), in the order quality.json lists them after the quality check's.

    `warming_findings` only from a start at rest: from a fitted warm start the open-loop
    twin's rise is the guessed history's continuation, not the twin's warming at the
    recorded speeds (5 of 42 warm recordings cut from suite runs, speeds in rpm, were
    told theirs might be in rev/s, one at 3442 times the twin's rise); the uniform start
    before told none of them either."""
    return [*start_findings(run, start),
            *held_correction_findings(run, methods), *tail_findings(run),
            *probe_offset_findings(run), *probe_scale_findings(run),
            *probe_direction_findings(run, model),
            *(warming_findings(open_loop_C, open_loop_start_C, measured_C, measured_start_C)
              if start.uniform else [])]
