"""Data-quality repairs of a recorded run, each reported as a finding (never silent).

Repaired here, in this order: duplicate timestamps (merged), spikes (robust Hampel-type
filter; for the speed, a command, only one-sample glitches between equal neighbours),
NaN dropouts and short time gaps (linear interpolation up to `max_gap_s`, the speed held
at its last value; longer ones, and those before a column's first reading, are filled for
continuity but excluded from the metrics), noisy sensors
(centred moving average), stuck sensors (flat while the others move: excluded), dead
thermocouples (no value in the whole run: excluded).  A
finding is a plain JSON-serialisable dict:

    {"column": "T2_C", "kind": "stuck", "count": 1800, "rows": [3, 4, ...],
     "spans_s": [[0.0, 1799.0]], "action": "excluded from metrics", "detail": "..."}

`rows` are 1-based file lines (CSV) or data rows (Parquet), at most `MAX_LISTED` of them;
`count` is the number of samples concerned; `spans_s` are time spans in run time.  A
finding that counts something else names it in the key instead of `count`: a replay's
`correction_held` (`twin.loop.findings.held_correction_findings`) has `count_windows`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from twin.runs.schema import AMBIENT, COOLANT, DISPLACEMENTS, SPEED, TEMPERATURES, TIME
from twin.runs.table import RawTable

MAX_LISTED = 20
SAMPLES = "samples"
"""What a finding's `count` counts (see `finding`)."""


@dataclass(frozen=True)
class QualityConfig:
    """Thresholds of the repairs (temperatures in °C, displacements in µm, times in s)."""

    max_gap_s: float = 30.0
    """Dropouts and time gaps up to this long are interpolated; longer ones are excluded."""
    spike_sigmas: float = 8.0
    spike_floor_C: float = 0.5
    spike_floor_um: float = 1.0
    spike_half_window: int = 5
    stuck_min_s: float = 60.0
    stuck_others_move_C: float = 0.5
    noisy_floor_C: float = 0.25
    noisy_floor_um: float = 1.0
    noisy_ratio: float = 5.0
    smooth_target_C: float = 0.05
    smooth_target_um: float = 0.1
    smooth_max_s: float = 30.0
    speed_glitch_max_s: float = 10.0
    """A single speed sample unlike its two equal neighbours, which lie at most this far
    apart, is a logging glitch: no spindle stops or changes speed and comes back within
    a few seconds (it takes seconds to ramp), and thermally such a blip is nothing."""
    probe_flat_um: float = 0.1
    probe_flat_running_s: float = 1200.0
    """An axial probe whose readings span less than `probe_flat_um` through this long at
    speed does not read the nose drift: a spindle drifts micrometres in minutes (the real
    machine of `examples/real` 0.9 µm in its first 10 min at 1250 rpm, the reference
    spindle 11 µm in 30 min at 9000 rpm)."""


@dataclass
class Repaired:
    """Repaired columns on the repaired time axis, validity masks and findings."""

    time_s: np.ndarray
    rows: np.ndarray
    columns: dict[str, np.ndarray]
    valid: dict[str, np.ndarray]
    gaps_s: list[tuple[float, float]] = field(default_factory=list)
    findings: list[dict] = field(default_factory=list)


def finding(column: str, kind: str, action: str, *, rows: np.ndarray | None = None,
            spans_s: list[tuple[float, float]] | None = None, count: int | None = None,
            detail: str = "", counted: str = SAMPLES) -> dict:
    """One data-quality finding as a JSON-serialisable dict.  `count` is of samples (by
    default the `rows` given); one of anything else (`counted="windows"`) is told under
    `count_<counted>`, so that no reader takes it for samples."""
    rows_list = [] if rows is None else [int(r) for r in np.asarray(rows)[:MAX_LISTED]]
    spans = [[round(float(a), 3), round(float(b), 3)] for a, b in (spans_s or [])[:MAX_LISTED]]
    key = "count" if counted == SAMPLES else f"count_{counted}"
    return {"column": column, "kind": kind,
            key: int(count if count is not None else (0 if rows is None else len(rows))),
            "rows": rows_list, "spans_s": spans, "action": action, "detail": detail}


def finding_count(found: dict) -> tuple[object, str]:
    """(count, what it counts) of a finding of any release: `count` is of samples,
    `count_<what>` of what its key says; a `correction_held` written before 2026-11-27
    counted windows under `count`.  (None, "samples") where it holds no count."""
    for key, value in found.items():
        if isinstance(key, str) and key.startswith("count_"):
            return value, key.removeprefix("count_")
    if found.get("kind") == "correction_held":
        return found.get("count"), "windows"
    return found.get("count"), SAMPLES


def true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive (start, end) index pairs of the True runs in a boolean array."""
    padded = np.concatenate([[False], mask, [False]])
    edges = np.flatnonzero(np.diff(padded.astype(np.int8)))
    return [(int(a), int(b) - 1) for a, b in zip(edges[::2], edges[1::2], strict=True)]


def noise_sigma(values: np.ndarray, keep: np.ndarray | None = None) -> float:
    """Robust white-noise estimate from second differences (blind to slow trends).

    With `keep` (bool per sample), only second differences of three consecutive kept
    samples count: the noise of the running or the stopped stretches of a run, say.
    """
    ok = ~np.isnan(values)
    if keep is None:
        x = values[ok]
        d2 = x[2:] - 2.0 * x[1:-1] + x[:-2]
    else:
        ok &= keep
        d2 = (values[2:] - 2.0 * values[1:-1] + values[:-2])[ok[2:] & ok[1:-1] & ok[:-2]]
    if d2.size < 3:
        return 0.0
    # Var(d2) = 6 σ² for white noise; 1.4826·MAD estimates a standard deviation.
    return float(1.4826 * np.median(np.abs(d2 - np.median(d2))) / np.sqrt(6.0))


def _unit_floor(name: str, celsius: float, micron: float) -> float:
    return micron if name.endswith("_um") else celsius


def _unit_of_change(name: str) -> str:
    """The unit of a difference of the column's values, for a finding's detail: a spike's
    threshold read "deviation above 0.5" with no unit (K or µm, or rpm)."""
    return "µm" if name.endswith("_um") else "rpm" if name.endswith("_rpm") else "K"


def drop_repeated_rows(table: RawTable) -> tuple[RawTable, list[dict]]:
    """Drop rows that repeat an earlier row exactly (every column, time included).

    A logger re-sending its buffer writes a block of rows a second time; the copies carry
    no new information.  Rows whose time goes back with different values are left for
    `check_structure` to refuse.
    """
    names = list(table.columns)
    if TIME not in table.columns or table.n_samples < 2:
        return table, []
    matrix = np.ascontiguousarray(np.stack([table.columns[n] for n in names], axis=1))
    matrix[np.isnan(matrix)] = np.nan  # one NaN bit pattern: missing cells compare equal
    keys = matrix.view(np.dtype((np.void, matrix.dtype.itemsize * matrix.shape[1]))).ravel()
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    repeated = first[inverse.ravel()] != np.arange(table.n_samples)
    if not repeated.any():
        return table, []
    keep = ~repeated
    kept = replace(table, columns={n: v[keep] for n, v in table.columns.items()},
                   rows=table.rows[keep])
    time = table.columns[TIME]
    spans = [(float(time[a] - time[0]), float(time[b] - time[0])) for a, b in true_runs(repeated)]
    found = finding(TIME, "repeated_rows", "dropped (exact copies of earlier rows)",
                    rows=table.rows[repeated], spans_s=spans, count=int(repeated.sum()),
                    detail=f"{len(spans)} block(s) of rows repeated verbatim, as a logger "
                           "re-sending its buffer writes them")
    return kept, [found]


def merge_duplicates(table: RawTable) -> tuple[np.ndarray, np.ndarray, dict, list[dict]]:
    """Merge samples sharing a timestamp into their mean (NaN-aware)."""
    time = table.columns[TIME]
    names = [n for n in table.columns if n != TIME]
    unique, first, counts = np.unique(time, return_index=True, return_counts=True)
    if unique.size == time.size:
        return time.copy(), table.rows.copy(), {n: table.columns[n].copy() for n in names}, []
    group = np.repeat(np.arange(unique.size), counts)  # time is sorted: groups are contiguous
    merged = {}
    for n in names:
        x = table.columns[n]
        ok = ~np.isnan(x)
        total = np.bincount(group, weights=np.where(ok, x, 0.0), minlength=unique.size)
        number = np.bincount(group, weights=ok.astype(float), minlength=unique.size)
        with np.errstate(invalid="ignore", divide="ignore"):
            merged[n] = np.where(number > 0, total / np.maximum(number, 1), np.nan)
    dropped = np.setdiff1d(np.arange(time.size), first)
    spans = [(float(t), float(t)) for t in unique[counts > 1]]
    found = finding(TIME, "duplicate_timestamp",
                    "merged into one sample (mean of the duplicates)",
                    rows=table.rows[dropped], spans_s=spans, count=int(dropped.size),
                    detail=f"{int((counts > 1).sum())} timestamps appear more than once")
    return unique, table.rows[first], merged, [found]


def running_median(v: np.ndarray, size: int) -> np.ndarray:
    """Centred running median over an odd `size`, the ends padded with the end values:
    `scipy.ndimage.median_filter(v, size, mode="nearest")`, without importing
    scipy.ndimage (about 0.1 s of every cold `twin replay`, for an 11-sample median)."""
    half = size // 2
    windows = np.lib.stride_tricks.sliding_window_view(np.pad(v, half, mode="edge"), size)
    return np.median(windows, axis=1)


def remove_spikes(name: str, t: np.ndarray, x: np.ndarray, rows: np.ndarray,
                  cfg: QualityConfig) -> tuple[np.ndarray, list[dict]]:
    """Replace isolated outliers by the running median (Hampel-type filter).

    A sample off the running median is an outlier only if it also breaks the trend on
    both sides of it (`_jumps_away_and_back`): a turn or a step is data.
    """
    ok = np.flatnonzero(~np.isnan(x))
    if ok.size < 2 * cfg.spike_half_window + 1:
        return x, []
    v = x[ok]
    med = running_median(v, 2 * cfg.spike_half_window + 1)
    floor = _unit_floor(name, cfg.spike_floor_C, cfg.spike_floor_um)
    threshold = max(cfg.spike_sigmas * noise_sigma(v), floor)
    spikes = _jumps_away_and_back(ok, t, v, np.abs(v - med) > threshold, threshold)
    if not spikes.any():
        return x, []
    out = x.copy()
    idx = ok[spikes]
    out[idx] = med[spikes]
    spans = [(float(t[ok[a]]), float(t[ok[b]])) for a, b in true_runs(spikes)]
    return out, [finding(name, "spike", "replaced by the running median of "
                         f"{2 * cfg.spike_half_window + 1} samples", rows=rows[idx],
                         spans_s=spans, count=int(idx.size),
                         detail=f"deviation above {threshold:.3g} {_unit_of_change(name)} "
                                "from the running median")]


def _jumps_away_and_back(ok: np.ndarray, t: np.ndarray, v: np.ndarray,
                         candidates: np.ndarray, threshold: float) -> np.ndarray:
    """The candidates that leave the signal and come back (a spike, not a turn or a step).

    The running median stands off a smooth signal wherever it bends sharply: at 0.25 Hz
    its 11 samples span 40 s, and the last samples before a ring's temperature turns (a
    load change) sit above a median drawn from both sides.  Those samples continue the
    trend on one side of them; a glitch continues neither.  A candidate is cleared when it
    lies within `threshold` of the line through the two nearest accepted samples on its
    left (sweeping forward) or on its right (sweeping back); cleared samples are accepted.
    """
    accepted = ~candidates
    clean = np.flatnonzero(accepted)
    tv = t[ok]
    for a, b in true_runs(candidates):
        before = [int(i) for i in clean[clean < a][-2:]]
        after = [int(i) for i in clean[clean > b][:2]][::-1]  # nearest last, as `before`
        for order, pair in ((range(a, b + 1), before), (range(b, a - 1, -1), after)):
            for i in order:
                if not accepted[i] and len(pair) == 2:
                    (i0, i1) = pair
                    slope = (v[i1] - v[i0]) / (tv[i1] - tv[i0])
                    accepted[i] = abs(v[i] - v[i1] - slope * (tv[i] - tv[i1])) <= threshold
                if accepted[i]:
                    pair[:] = [*pair[-1:], i]
    return candidates & ~accepted


def repair_speed_glitches(t: np.ndarray, x: np.ndarray, rows: np.ndarray,
                          cfg: QualityConfig) -> tuple[np.ndarray, list[dict]]:
    """Replace one-sample speed glitches (`QualityConfig.speed_glitch_max_s`) by their
    neighbours' speed.  The spike filter does not suit a speed: its steps are commands,
    and a glitch is told by its neighbours agreeing, not by a noise level.  A glitch
    matters because a window takes the speed of its start's sample: a single 0 rpm there
    would stop the twin for a minute."""
    ok = np.flatnonzero(~np.isnan(x))
    if ok.size < 3:
        return x, []
    v, tv = x[ok], t[ok]
    glitch = np.zeros(ok.size, dtype=bool)
    glitch[1:-1] = ((v[:-2] == v[2:]) & (v[1:-1] != v[:-2])
                    & (tv[2:] - tv[:-2] <= cfg.speed_glitch_max_s))
    if not glitch.any():
        return x, []
    out = x.copy()
    idx = ok[glitch]
    out[idx] = v[np.flatnonzero(glitch) - 1]
    return out, [finding(SPEED, "glitch", "replaced by the speed on both sides of it",
                         rows=rows[idx], spans_s=[(float(t[i]), float(t[i])) for i in idx],
                         count=int(idx.size),
                         detail="one sample off equal neighbours at most "
                                f"{cfg.speed_glitch_max_s:g} s apart")]


HELD_INPUTS = (SPEED, AMBIENT, COOLANT)
"""The recorded columns the twin runs on (`fill_dropouts` holds them through a gap)."""


def fill_dropouts(name: str, t: np.ndarray, x: np.ndarray, rows: np.ndarray,
                  cfg: QualityConfig) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """Interpolate NaN runs linearly in time; runs longer than `max_gap_s` are excluded.
    The twin's inputs (`HELD_INPUTS`: the speed, a command that holds until the next, and
    the air and coolant temperatures its boundaries run at) keep their last value instead:
    a linear fill reads a value measured after the gap, and a window's loads may use only
    what was measured before it starts (DESIGN.md).  Until 2026-11-27 a coolant log with a
    10-min gap ramped the inlet the replay ran at towards the reading after it.
    The samples before a column's first reading have neither a reading to hold nor two to
    interpolate between: they are invalid whatever their length, as a long dropout's,
    and hold the first reading only as a finite stand-in (`leading_dropout`).  Until
    2026-11-28 a missing first sample was a valid one, the next sample's value told as
    "linearly interpolated" (or "held at the last reading"): a thermocouple's start
    reading, and a probe's zero, taken from a later sample."""
    valid = np.ones(x.size, dtype=bool)
    missing = np.isnan(x)
    if not missing.any():
        return x, valid, []
    ok = ~missing
    out = x.copy()
    # Beyond the first/last value the nearest value is held (np.interp clamps).
    out[missing] = np.interp(t[missing], t[ok], x[ok])
    if name in HELD_INPUTS:
        # a linear fill would ramp across a step the gap hides; the last value holds
        # (before the first value, the first, as above)
        last = np.maximum.accumulate(np.where(ok, np.arange(x.size), -1))
        held = missing & (last >= 0)
        out[held] = x[last[held]]
    how = ("held at the last speed" if name == SPEED else "held at the last reading"
           if name in HELD_INPUTS else "linearly interpolated in time")
    found = []
    if missing[0]:
        b = int(np.argmax(ok)) - 1  # the last sample before the first reading
        valid[:b + 1] = False
        first = "speed" if name == SPEED else "reading"
        found.append(finding(name, "leading_dropout",
                             f"held at the first {first} for continuity; excluded from "
                             "metrics", rows=rows[:b + 1], spans_s=[(t[0], t[b])],
                             detail=f"missing values before the first {first}, at "
                                    f"{t[b + 1]:g} s"))
    short_rows, long_rows, short_spans, long_spans = [], [], [], []
    for a, b in true_runs(missing):
        if a == 0:  # before the first reading: told above
            continue
        left = t[a - 1]
        right = t[b + 1] if b + 1 < x.size else t[b]
        if right - left > cfg.max_gap_s:
            valid[a:b + 1] = False
            long_rows.append(rows[a:b + 1])
            long_spans.append((t[a], t[b]))
        else:
            short_rows.append(rows[a:b + 1])
            short_spans.append((t[a], t[b]))
    if short_rows:
        r = np.concatenate(short_rows)
        found.append(finding(name, "dropout", how, rows=r,
                             spans_s=short_spans, count=r.size,
                             detail=f"missing values, gaps up to {cfg.max_gap_s:g} s"))
    if long_rows:
        r = np.concatenate(long_rows)
        found.append(finding(name, "long_dropout",
                             f"{how} for continuity; excluded from metrics", rows=r,
                             spans_s=long_spans, count=r.size,
                             detail=f"missing values over more than {cfg.max_gap_s:g} s"))
    return out, valid, found


def time_gaps(t: np.ndarray, rows: np.ndarray,
              cfg: QualityConfig) -> tuple[list[tuple[float, float]], list[dict]]:
    """Intervals without samples: short ones are interpolated across, long ones excluded."""
    dt = np.diff(t)
    typical = float(np.median(dt))
    short = np.flatnonzero((dt > 3.0 * typical) & (dt <= cfg.max_gap_s))
    long = np.flatnonzero(dt > cfg.max_gap_s)
    found = []
    if short.size:
        found.append(finding(TIME, "short_gap", "values interpolated across the gap",
                             rows=rows[short + 1], count=int(short.size),
                             spans_s=[(t[i], t[i + 1]) for i in short],
                             detail=f"no samples for more than 3 typical intervals "
                                    f"({typical:g} s)"))
    gaps = [(float(t[i]), float(t[i + 1])) for i in long]
    if long.size:
        found.append(finding(TIME, "long_gap", "times inside the gap excluded from metrics",
                             rows=rows[long + 1], count=int(long.size), spans_s=gaps,
                             detail=f"no samples for more than {cfg.max_gap_s:g} s"))
    return gaps, found


def smooth_noisy(name: str, t: np.ndarray, x: np.ndarray, sigma: float,
                 others: float | None, cfg: QualityConfig) -> tuple[np.ndarray, list[dict]]:
    """Smooth a sensor far noisier than its peers (`others`: their median noise; None for
    a column without peers, the ambient, say) with a centred moving average."""
    floor = _unit_floor(name, cfg.noisy_floor_C, cfg.noisy_floor_um)
    if sigma <= max(floor, cfg.noisy_ratio * (others or 0.0)):
        return x, []
    target = _unit_floor(name, cfg.smooth_target_C, cfg.smooth_target_um)
    interval = float(np.median(np.diff(t)))
    width = int(np.ceil((sigma / target) ** 2))
    width = max(3, min(width, int(cfg.smooth_max_s / interval)))
    width += 1 - width % 2  # odd: centred, no time shift
    from scipy.ndimage import uniform_filter1d  # only for a noisy sensor: kept off startup

    out = uniform_filter1d(x, size=width, mode="nearest")
    unit = "µm" if name.endswith("_um") else "°C"
    return out, [finding(name, "noisy", f"smoothed by a centred moving average of {width} "
                         f"samples ({width * interval:g} s)", count=x.size,
                         spans_s=[(t[0], t[-1])],
                         detail=f"noise {sigma:.3g} {unit}" + (
                             "" if others is None else f" (others {others:.3g} {unit})"))]


def find_stuck(t: np.ndarray, raw: dict[str, np.ndarray], rows: np.ndarray,
               cfg: QualityConfig) -> tuple[dict[str, np.ndarray], list[dict]]:
    """Temperature sensors that stay flat while the others move (dead thermocouples)."""
    stuck: dict[str, np.ndarray] = {}
    found = []
    names = [n for n in TEMPERATURES if n in raw]
    for name in names:
        others = [raw[n] for n in names if n != name]
        x = raw[name]
        # (a) exactly repeated values for a long stretch while another sensor moves
        mask = frozen_spells(t, x, others, cfg.stuck_min_s, cfg.stuck_others_move_C)
        # (b) flat within noise over the whole run while the others warm up clearly
        rise = _rise(t, x)
        other_rises = [abs(_rise(t, o)) for o in others]
        if other_rises and np.median(other_rises) >= 2.0 and abs(rise) < 0.02 * np.median(
                other_rises) and np.nanpercentile(x, 99) - np.nanpercentile(x, 1) < 1.0:
            mask[:] = True
        if mask.any():
            stuck[name] = mask
            spans = [(t[a], t[b]) for a, b in true_runs(mask)]
            found.append(finding(name, "stuck", "excluded from metrics and correction inputs",
                                 rows=rows[mask], spans_s=spans, count=int(mask.sum()),
                                 detail="flat while the other temperature sensors move"))
    return stuck, found


AXIAL_PROBE = "disp_z_um"
"""The displacement the twin models and the corrections read (`find_stuck_probe`)."""


def running_s(t: np.ndarray, speed_rpm: np.ndarray, mask: np.ndarray,
              max_step_s: float = QualityConfig.max_gap_s) -> float:
    """Time (s) at speed over the samples of `mask`, each sample holding until the next but
    no longer than `max_step_s` (a gap in the log is no time seen at speed)."""
    step = np.minimum(np.diff(t, append=t[-1]), max_step_s)
    return float(step[(speed_rpm > 0) & mask].sum())


FLAT_FROZEN, FLAT_IN_MM = "frozen", "in_mm"
"""What `flat_probe` finds an axial probe that does not read the drift to be."""


def flat_probe(t: np.ndarray, x_um: np.ndarray, speed_rpm: np.ndarray, ok: np.ndarray,
               cfg: QualityConfig) -> tuple[str, float, float] | None:
    """(what, median reading µm, time at speed s) of an axial probe whose valid readings
    (`ok`) span less than `cfg.probe_flat_um` through `cfg.probe_flat_running_s` at speed:
    `FLAT_FROZEN` where they are all equal or lie 1 µm or more from 0 (a frozen channel),
    else `FLAT_IN_MM` (next to 0 and moving a little: a column in mm, below 1 mm).  None
    for a probe that reads a drift.  The one rule `find_stuck_probe` and the replay's
    `probe_in_mm` finding both take: the two measured it apart, and a probe in mm off 0 by
    0.095 mm was called stuck."""
    if not ok.any():
        return None
    x = x_um[ok]
    at_speed_s = running_s(t, speed_rpm, ok, cfg.max_gap_s)
    if at_speed_s < cfg.probe_flat_running_s or np.ptp(x) >= cfg.probe_flat_um:
        return None
    level = float(np.median(x))
    frozen = np.ptp(x) == 0 or abs(level) >= 1.0
    return (FLAT_FROZEN if frozen else FLAT_IN_MM), level, at_speed_s


def probe_resolution_um(x_um: np.ndarray) -> float:
    """The smallest step between two successive valid readings of a probe (µm; inf for
    none): what it resolves, 1 µm for a probe logged in whole micrometres."""
    steps = np.abs(np.diff(x_um[np.isfinite(x_um)]))
    steps = steps[steps > 0]
    return float(steps.min()) if steps.size else float("inf")


def find_stuck_probe(t: np.ndarray, raw: dict[str, np.ndarray], columns: dict[str, np.ndarray],
                     valid: dict[str, np.ndarray], rows: np.ndarray,
                     cfg: QualityConfig) -> list[dict]:
    """An axial probe that does not read the drift, its samples cleared in `valid` (a stuck
    thermocouple's rule: excluded from metrics and correction inputs):

    - frozen through the run (`flat_probe`, `FLAT_FROZEN`);
    - frozen for a spell: one reading repeated exactly while a thermocouple moves
      (`frozen_spells`, the thermocouples' thresholds), a logger channel holding its last
      value; only for a probe that resolves finer than half `cfg.probe_flat_um`: one
      logged in whole micrometres repeats its readings for minutes as the spindle warms
      (on the 9000 rpm bundled run rounded to 1 µm, 493 samples were taken for stuck).

    Assimilated, a probe frozen at 20 µm pulled the estimator's temperatures off; scored, it
    said nothing of the twin.  A probe in mm (`FLAT_IN_MM`) is left for the replay to tell
    (`twin.loop.findings.probe_scale_findings`), scored as recorded.  The radial columns
    are left alone: a radial drift can stay within a tenth of a micrometre.  Like the
    thermocouples' rules these read the whole run, as the quality check does before any
    replay."""
    if AXIAL_PROBE not in columns or not valid[AXIAL_PROBE].any():
        return []
    ok = valid[AXIAL_PROBE]
    flat = flat_probe(t, columns[AXIAL_PROBE], columns[SPEED], ok, cfg)
    if flat is not None and flat[0] == FLAT_FROZEN:
        _, level, at_speed_s = flat
        valid[AXIAL_PROBE] = np.zeros(t.size, dtype=bool)
        return [finding(AXIAL_PROBE, "stuck", "excluded from metrics and correction inputs",
                        rows=rows[ok], spans_s=[(t[a], t[b]) for a, b in true_runs(ok)],
                        count=int(ok.sum()),
                        detail=f"reads {level:.4g} µm throughout {at_speed_s / 60:.0f} min "
                               "at speed: the nose drifts micrometres in minutes")]
    if probe_resolution_um(raw[AXIAL_PROBE]) >= cfg.probe_flat_um / 2:
        return []
    thermocouples = [raw[n] for n in TEMPERATURES if n in raw]
    frozen = frozen_spells(t, raw[AXIAL_PROBE], thermocouples, cfg.stuck_min_s,
                           cfg.stuck_others_move_C) & ok
    if not frozen.any():
        return []
    valid[AXIAL_PROBE] = ok & ~frozen
    return [finding(AXIAL_PROBE, "stuck", "excluded from metrics and correction inputs",
                    rows=rows[frozen], spans_s=[(t[a], t[b]) for a, b in true_runs(frozen)],
                    count=int(frozen.sum()),
                    detail="repeats one reading while the thermocouples move")]


def frozen_spells(t: np.ndarray, x: np.ndarray, others: list[np.ndarray], min_s: float,
                  others_move: float) -> np.ndarray:
    """Mask of the spells where `x` repeats one value exactly (at least 5 valid samples
    over at least `min_s`) while one of `others` moves by `others_move` or more: a logger
    channel frozen at its last reading.  NaN samples inside a spell neither break nor
    join it."""
    ok = np.flatnonzero(~np.isnan(x))
    mask = np.zeros(x.size, dtype=bool)
    same = np.concatenate([[False], x[ok][1:] == x[ok][:-1]])
    for a, b in true_runs(same):
        a -= 1  # the spell starts at the first of the equal values
        i0, i1 = ok[a], ok[b]
        if t[i1] - t[i0] < min_s or b - a + 1 < 5:
            continue
        moved = max((np.nanmax(o[i0:i1 + 1]) - np.nanmin(o[i0:i1 + 1])
                     for o in others if np.isfinite(o[i0:i1 + 1]).any()), default=0.0)
        if moved >= others_move:
            mask[i0:i1 + 1] = True
    return mask


def _rise(t: np.ndarray, x: np.ndarray) -> float:
    """Change between the first and last 10 % of the run (medians, NaN-aware)."""
    edge = t[0] + 0.1 * (t[-1] - t[0]), t[-1] - 0.1 * (t[-1] - t[0])
    head, tail = x[t <= edge[0]], x[t >= edge[1]]
    if not np.isfinite(head).any() or not np.isfinite(tail).any():
        return 0.0
    return float(np.nanmedian(tail) - np.nanmedian(head))


def repair(table: RawTable, cfg: QualityConfig | None = None) -> Repaired:
    """Apply every repair to a validated table and collect the findings."""
    cfg = cfg or QualityConfig()
    time, rows, columns, findings = merge_duplicates(table)
    if time[0] != 0.0:
        findings.append(finding(TIME, "time_offset", f"run time counted from the first "
                                f"sample (time_s - {time[0]:g})", count=0,
                                detail=f"first sample at {time[0]:g} s"))
        time = time - time[0]

    empty = [n for n in columns if np.isnan(columns[n]).all()]
    dead = [n for n in empty if n in TEMPERATURES]
    for name in empty:
        # Only optional columns and thermocouples can be empty here (validation rejects
        # the other required ones and a run without any temperature).
        if name in dead:
            findings.append(finding(name, "dead", "excluded from metrics and correction "
                                    "inputs", count=time.size, spans_s=[(time[0], time[-1])],
                                    detail="no values in the whole run"))
        else:
            findings.append(finding(name, "empty_column", "column ignored", count=time.size,
                                    detail="no values in the whole run"))
        del columns[name]
    raw = {n: v.copy() for n, v in columns.items()}
    valid: dict[str, np.ndarray] = {}
    for name, x in columns.items():
        if name != SPEED:
            x, found = remove_spikes(name, time, x, rows, cfg)
        else:  # speed steps are real; a spindle speed is a command, not noise
            x, found = repair_speed_glitches(time, x, rows, cfg)
        findings += found
        x, valid[name], found = fill_dropouts(name, time, x, rows, cfg)
        findings += found
        columns[name] = x

    gaps, found = time_gaps(time, rows, cfg)
    findings += found

    sigmas = {n: noise_sigma(raw[n]) for n in columns}
    for group in (TEMPERATURES, DISPLACEMENTS, ("ambient_C",), ("coolant_C",)):
        present = [n for n in group if n in columns]
        for name in present:
            peers = [sigmas[n] for n in present if n != name]
            others = float(np.median(peers)) if peers else None
            columns[name], found = smooth_noisy(name, time, columns[name], sigmas[name],
                                                others, cfg)
            findings += found

    stuck, found = find_stuck(time, raw, rows, cfg)
    findings += found
    for name, mask in stuck.items():
        valid[name] &= ~mask
    findings += find_stuck_probe(time, raw, columns, valid, rows, cfg)
    for name in dead:
        # A dead channel keeps its place in T1..T5, never valid.  Its values are the
        # ambient's, a finite stand-in that nothing reads (every consumer masks by
        # `valid`; the outputs write NaN there), so no NaN reaches a solver or a filter.
        columns[name] = columns[AMBIENT].copy()
        valid[name] = np.zeros(time.size, dtype=bool)
    return Repaired(time_s=time, rows=rows, columns=columns, valid=valid, gaps_s=gaps,
                    findings=findings)
