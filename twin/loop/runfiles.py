"""Replay one recorded run with every requested method and write its output folder.

Layout under DIR/<run-name>/ (shared DESIGN.md):
    keypoints.csv      time_s, method, T1..T5 twin and measured, nose drift twin/measured,
                       and the 90 % band (…_twin_lo/_hi) when a method has one (estimator)
    corrections.csv    window, method, H_front, H_rear, R_front, R_rear, C_H, C_C (on the
                       previous values carried to this window's nominal level), and
                       <name>_factor for further estimated values (motor, film groups),
                       sensor_lag_s, coolant_C and T1..T5_offset_K (each thermocouple's
                       offset) where a method estimates them
    accuracy.json      per-method metrics (twin.loop.metrics)
    quality.json       data-quality findings of the recorded run
    decks/window_kkk.inp        the primary method's window decks (others: decks/<method>/),
                                window_kkk_rerun.inp (a re-run) and window_kkk_start.vtu
                                (the start field where the decks do not give it)
    fields/*.vtu + fields.pvd   the primary method's field at every window end (--fields
                                every; end: the last one; none: neither)
    snapshots/*.png             field pictures (--snapshots end|every), drawn from the
                                replay's own fields, not from the field files
    plots/*.png                 the report's figures of this run
    .done.json                  written last: what --resume checks
The primary method is bpnn when it runs, else the last method listed.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Sequence
from dataclasses import replace
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin.contract import SENSOR_NAMES, WINDOW_S
from twin.correction.features import first_finite
from twin.errors import InputError
from twin.io.atomic import write_csv, write_json, write_text
from twin.loop.findings import replay_findings
from twin.loop.folders import replaced_folder
from twin.loop.metrics import accuracy_metrics
from twin.loop.overlap import ForkedTask, ForkedTaskError
from twin.loop.replay import (
    MethodReplay,
    deck_window_solver,
    method_replay_from_json,
    method_replay_to_json,
    replay_method,
)
from twin.loop.runnames import run_name
from twin.loop.start_field import StartField, start_field
from twin.version import code_identity

if TYPE_CHECKING:
    from twin.correction.result import Corrector
    from twin.loop.replay import WindowRecord, WindowSolver
    from twin.runs import RecordedRun
    from twin.spindle.model import SpindleModel

DONE_FILE = ".done.json"
WINDOW_END_CHOICES = ("none", "end", "every")
"""Which window ends a replay pictures (snapshots) or writes field files of (fields)."""


def file_digest(path: str | Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def resume_token(path: str | Path, methods: Sequence[str], model_path: str | None,
                 assimilate_drift: bool = True, fields: str = "every") -> dict:
    """What must match for a finished run folder to be reused by --resume.  `fields` is
    part of it unless it is the default: a folder replayed with `--fields none` lacks the
    files `--fields every` asks for (and a folder of earlier releases had every field).
    `code` is the code that replays (`twin.version.code_identity`): a folder replayed by
    other code (a method that behaves otherwise) is replayed again, as is one whose token
    predates it and so cannot say what code wrote it."""
    token = {"input_sha256": file_digest(path), "methods": list(methods),
             "code": code_identity()}
    if fields != "every":
        token["fields"] = fields
    if "estimator" in methods:
        token["estimator_assimilate_drift"] = bool(assimilate_drift)
    if "bpnn" in methods and model_path is not None:
        token["model_sha256"] = file_digest(model_path)
    return token


def is_done(out_dir: Path, token: dict) -> bool:
    try:
        return json.loads((out_dir / DONE_FILE).read_text()) == token
    except (OSError, ValueError):
        return False


def primary_method(methods: Sequence[str]) -> str:
    return "bpnn" if "bpnn" in methods else methods[-1]


def replay_run_to_dir(
    run_path: str | Path,
    out_root: str | Path,
    methods: Sequence[str],
    model_path: str | None,
    snapshots: str = "none",
    spindle: SpindleModel | None = None,  # a loaded spindle to reuse
    on_window: Callable[[str, int, int], None] | None = None,
    overlap: bool = True,
    assimilate_drift: bool = True,
    plotter: ForkedTask | None = None,
    fields: str = "every",
    stop: Callable[[], None] | None = None,
) -> dict:
    """Replay one run with `methods`, write its folder, return its accuracy.json dict.
    `assimilate_drift`: the estimator's option (twin.estimation.method.EstimatorConfig).
    `snapshots`, `fields`: the window ends pictured and written as field files
    (`WINDOW_END_CHOICES`).  `on_window(method, done, total)`: told after each window
    replayed in this process (`_replay_methods`).

    The folder DIR/<run-name>/ is replaced as a whole (`replaced_folder`): a shorter rerun
    leaves none of the longer run's files, and a failed one leaves no earlier result.
    overlap: use a second core through forked children (`twin.loop.overlap`) for part of
    the methods and for the figures; the outputs are the same either way.  A batch whose
    workers already fill the cores turns it off.
    stop: called between windows and once more before the folder is swapped in; what it
    raises ends the run as a failure does (a stopped batch's run leaves no folder).
    plotter: a `twin.loop.report.run_plotter` forked earlier (by the CLI, before its heavy
    imports, so that matplotlib loads on the idle core); used if still fresh, else this
    run forks its own.
    """
    for option, value in (("snapshots", snapshots), ("fields", fields)):
        if value not in WINDOW_END_CHOICES:
            raise ValueError(f"{option} must be one of {WINDOW_END_CHOICES}, got {value!r}")
    window_hook = on_window
    if stop is not None:
        def window_hook(method: str, window: int, windows: int) -> None:
            stop()
            if on_window is not None:
                on_window(method, window, windows)
    with replaced_folder(Path(out_root) / run_name(run_path)) as out_dir:
        accuracy = _replay_into(run_path, out_dir, methods, model_path, snapshots, spindle,
                                window_hook, overlap, assimilate_drift, plotter, fields)
        if stop is not None:
            stop()
        return accuracy


def _replay_into(run_path: str | Path, out_dir: Path, methods: Sequence[str],
                 model_path: str | None, snapshots: str, spindle: SpindleModel | None,
                 on_window: Callable[[str, int, int], None] | None, overlap: bool,
                 assimilate_drift: bool, plotter: ForkedTask | None, fields: str) -> dict:
    from twin.io.figures import load_matplotlib
    from twin.loop.report import run_plotter

    # the report's figures are drawn by a forked child on the second core, overlapping the
    # solve (it imports matplotlib meanwhile) and the field files (it draws meanwhile)
    fresh = plotter is not None and plotter.fresh
    if not fresh and overlap:
        load_matplotlib()  # here, once per process: the plotters of later runs inherit it
    with plotter if fresh else run_plotter(fork=overlap) as plots:
        accuracy, token = _replay_outputs(run_path, out_dir, methods, model_path, snapshots,
                                          spindle, on_window, plots, assimilate_drift, fields)
        plots.join()
    write_json(out_dir / "accuracy.json", accuracy)
    write_json(out_dir / DONE_FILE, token)
    return accuracy


def _replay_outputs(run_path: str | Path, out_dir: Path, methods: Sequence[str],
                    model_path: str | None, snapshots: str, spindle: SpindleModel | None,
                    on_window: Callable[[str, int, int], None] | None, plots: ForkedTask,
                    assimilate_drift: bool = True,
                    fields: str = "every") -> tuple[dict, dict]:
    """Replay and write every file but accuracy.json and the .done token; `plots` is
    started once keypoints.csv and corrections.csv (what the figures show) are written."""
    from twin.correction.methods import make_corrector
    from twin.runs import read_run, write_quality
    from twin.spindle.model import SpindleModel

    model = spindle if spindle is not None else SpindleModel.load()
    run = read_run(run_path, max_speed_rpm=model.spec.spindle.max_speed_rpm)
    run = replace(run, name=run_name(run_path))  # as its folder and accuracy.json know it
    token = resume_token(run_path, methods, model_path, assimilate_drift, fields)
    config = None
    if "estimator" in methods:  # its modules load only for the method that uses them
        from twin.estimation.method import EstimatorConfig

        config = EstimatorConfig(assimilate_drift=assimilate_drift)
    correctors = [
        make_corrector(m, model_path if m == "bpnn" else None, spindle=model,
                       estimator_config=config)
        for m in methods
    ]
    solver = deck_window_solver(model)  # one session serves every method of the run
    primary = primary_method(methods)
    start = start_field(model, run)  # every method's, found once

    results = _replay_methods(run, model, correctors, primary, solver, on_window,
                              partial(_write_fields, out_dir, model, fields), snapshots,
                              fork=plots.forked,
                              keep_fields=fields != "none" or snapshots != "none",
                              start=start)

    first = next(iter(results.values()))
    meas_T, meas_T0, meas_drift = measured_reference(run, first.time_s)
    accuracy = {
        "run": run_name(run_path),
        "speed_rpm": float(np.mean(run.speed_rpm)),
        "ambient_C": float(np.mean(run.ambient_C)),
        "duration_s": float(run.duration_s),
        "methods": {
            name: method_accuracy(r, meas_T, meas_T0, meas_drift) for name, r in results.items()
        },
    }

    _write_keypoints(out_dir / "keypoints.csv", results, meas_T, meas_drift)
    _write_corrections(out_dir / "corrections.csv", results)
    plots.start(str(out_dir))
    if snapshots != "none":
        _write_snapshots(out_dir, model, results[primary], snapshots, run)
    open_loop = results.get("open_loop")
    told = replay_findings(run, model, methods, None if open_loop is None else open_loop.T_twin_C,
                           first.start_key_points_C(model), meas_T, meas_T0, start)
    write_quality(replace(run, quality=[*run.quality, *told]), out_dir / "quality.json")
    for name, r in results.items():
        deck_dir = out_dir / "decks" if name == primary else out_dir / "decks" / name
        for w in r.windows:
            if w.deck is not None:
                write_text(deck_dir / f"window_{w.window:03d}.inp", w.deck)
            if w.rerun_deck is not None:
                write_text(deck_dir / f"window_{w.window:03d}_rerun.inp", w.rerun_deck)
            if w.start_C is not None and w.deck is not None:
                _write_start_state(deck_dir / f"window_{w.window:03d}_start.vtu", model, w)
    return accuracy, token


def _write_start_state(path: Path, model: SpindleModel, w: WindowRecord) -> None:
    """The field window `w` starts from, on the deck session's nodes (node i+1 = vertex i,
    `apdl_like.session`), with the estimator's stated readings and lag: what `apdl-like run
    --spindle --start` runs its deck (or its re-run deck) from."""
    from apdl_like.outputs import write_state_vtu

    thermal = model.mesh.thermal
    c = w.correction
    extra = {} if c.readings_start_C is None else {
        "READINGS_START_C": c.readings_start_C, "SENSOR_LAG_S": c.sensor_lag_s}
    if c.sensor_offset_C is not None:
        extra["SENSOR_OFFSET_C"] = c.sensor_offset_C
    write_state_vtu(path, thermal.p.T, thermal.t.T, w.start_C[:thermal.p.shape[1]],
                    w.start_s, extra)


def _window_ends(fields: dict[float, np.ndarray], choice: str) -> list[float]:
    """The window ends pictured or written (`WINDOW_END_CHOICES`): none, the last one
    (end) or all (every)."""
    times = sorted(fields)
    return {"none": [], "end": times[-1:], "every": times}[choice]


def _write_snapshots(out_dir: Path, model: SpindleModel, r: MethodReplay, snapshots: str,
                     run: RecordedRun) -> None:
    from twin.loop.snapshot import render_snapshot, snapshot_title

    clim = frames_range(model, snapshots, r.fields)
    for t in _window_ends(r.fields, snapshots):
        render_snapshot(model, r.fields[t], out_dir / _snapshot_name(r.method, t),
                        title=snapshot_title(run.name, r.method, t, run),
                        T_initial_C=r.start_reference_C, clim=clim)


def frames_range(model: SpindleModel, snapshots: str,
                 fields: dict[float, np.ndarray]) -> tuple[float, float] | None:
    """The colour range the snapshots `snapshots` asks for share: with `every`, the range
    of the temperature over all the run's window-end `fields` of the method pictured (the
    frames of one run are compared and played as a sequence); else None, the picture's
    own field's range (one picture, as `twin snapshot` draws).  The replay and --resume's
    `add_snapshots` (from the field files) both take it here."""
    from twin.loop.snapshot import colour_range

    if snapshots != "every":
        return None
    return colour_range(model, (fields[t] for t in sorted(fields)), "temperature")


def _snapshot_name(method: str, t: float) -> str:
    return f"snapshots/{method}_t{t:05.0f}s.png"


def _field_name(method: str, t: float) -> str:
    return f"fields/{method}_t{t:05.0f}s.vtu"


def add_snapshots(run_path: str | Path, out_dir: Path, methods: Sequence[str],
                  snapshots: str, duration_s: float) -> int:
    """Draw the snapshots `snapshots` asks for that the finished run folder `out_dir` lacks,
    from its field files, without solving again (--resume on a run it skips); pictures it
    has are kept, but for an `end` replay's one picture where `every` draws the others
    (`frames_range`: the frames share the run's range, that picture spans its own).
    `duration_s`: the run's (accuracy.json), which sets its window ends.
    Returns how many were drawn.  InputError: a field file it needs is missing (`--fields
    end` or `none`) or damaged (the caller replays the run)."""
    from twin.contract import windows_in
    from twin.io.vtk import read_vtu
    from twin.loop.snapshot import render_snapshot, snapshot_title
    from twin.runs import read_run
    from twin.spindle.model import SpindleModel

    primary = primary_method(methods)
    ends = dict.fromkeys(WINDOW_S * k for k in range(1, windows_in(duration_s) + 1))
    wanted = [t for t in _window_ends(ends, snapshots)
              if not (out_dir / _snapshot_name(primary, t)).is_file()]
    if snapshots == "every" and wanted == list(ends)[:-1]:
        # the end frame alone: an `end` replay's picture, in its own field's range (kept,
        # one run's frames used two ranges).  Drawn again in the run's, first: a resume
        # stopped part-way leaves it so beside the frames it drew
        wanted.insert(0, max(ends))
    if not wanted:
        return 0
    model = SpindleModel.load()
    run = read_run(run_path, max_speed_rpm=model.spec.spindle.max_speed_rpm)

    def field_at(t: float) -> np.ndarray:
        path = out_dir / _field_name(primary, t)
        if not path.is_file():
            raise InputError("no field file to draw the snapshot from", file=str(path))
        T = read_vtu(path).point_data.get("temperature_C")
        if T is None or np.shape(T) != (model.n_dofs,) or not np.all(np.isfinite(T)):
            raise InputError("no temperature_C array of the spindle's vertices", file=str(path))
        return np.asarray(T, float)

    # every frame's range is over all the window ends, drawn or kept: read them all then
    shown = {t: field_at(t) for t in (ends if snapshots == "every" else wanted)}
    clim = frames_range(model, snapshots, shown)
    start_C = _replayed_start(out_dir, model, run)
    for t in wanted:
        render_snapshot(model, shown[t], out_dir / _snapshot_name(primary, t),
                        title=snapshot_title(run_name(run_path), primary, t, run),
                        T_initial_C=start_C, clim=clim)
    return len(wanted)


def _replayed_start(out_dir: Path, model: SpindleModel, run: RecordedRun) -> np.ndarray:
    """The field the finished run folder `out_dir`'s replay started from (the zero of its
    drift): its first deck's start state, `decks/window_000_start.vtu`, where the replay
    wrote one (always for a warm start: its fitted field), else the run's start field,
    which is then uniform and found without a fit.  Fitting a warm start again cost
    --resume 0.17 s a run for a picture's drift.  InputError: a damaged start file."""
    from apdl_like.outputs import read_state_vtu

    path = out_dir / "decks" / "window_000_start.vtu"
    if not path.is_file():
        return start_field(model, run).field_C
    _, T, _ = read_state_vtu(path)
    if np.shape(T) != (model.n_dofs,) or not np.all(np.isfinite(T)):
        raise InputError("no TEMP array of the spindle's vertices", file=str(path))
    return T


def _replay_methods(run: RecordedRun, model: SpindleModel, correctors: list[Corrector],
                    primary: str, solver: WindowSolver,
                    on_window: Callable[[str, int, int], None] | None,
                    write_primary_fields: Callable[[MethodReplay], None], snapshots: str,
                    fork: bool, start: StartField,
                    keep_fields: bool = True) -> dict[str, MethodReplay]:
    """Every method's replay, by name in the order given; the primary's field files are
    written by `write_primary_fields` as soon as it is replayed.  `keep_fields`: the
    primary keeps its window-end fields (for the field files or the snapshots).  `start`:
    the run's start field, every method's.

    With `fork` a forked child on the second core replays the primary and writes its
    fields (their structural solves and stress recovery cost about as much as replaying one
    more method) and, with four methods or more, some of the others, so that each process
    replays about half; it sends its replays back as JSON with only the fields the
    snapshots show.  The parent replays the rest meanwhile.
    `on_window(method, done, total)` is told after each window this process replays:
    `done` of the `total` windows of the methods it replays itself (a callback cannot
    cross processes; the child's half runs alongside).  It was once given only without
    the fork, and so never: a replay showed no progress until its run was done.
    Each window's solve depends on its own inputs only (the session's cached
    factorizations are keyed by the matrix), so the split changes no number.  Should the
    child fail, the parent replays its methods itself: the error, if it is one, is then
    raised here with its own type.
    """
    def replay(corrector: Corrector,
               told: Callable[[int, int], None] | None = None) -> MethodReplay:
        r = replay_method(run, model, corrector,
                          keep_fields=keep_fields and corrector.name == primary,
                          on_window=told, solver=solver, start=start)
        if r.method == primary:
            write_primary_fields(r)
        return r

    def pictured(r: MethodReplay) -> MethodReplay:
        return replace(r, fields={t: r.fields[t] for t in _window_ends(r.fields, snapshots)})

    def replay_away(_: str) -> str:
        return json.dumps([method_replay_to_json(pictured(replay(c))) for c in away])

    others = [c for c in correctors if c.name != primary]
    away = []
    if fork and others:
        away = [c for c in correctors if c.name == primary] + others[: (len(others) - 1) // 2]
    here = [c for c in correctors if c not in away]

    def told(i: int, corrector: Corrector) -> Callable[[int, int], None] | None:
        if on_window is None:
            return None
        return lambda k, n: on_window(corrector.name, i * n + k, len(here) * n)

    side = ForkedTask(replay_away, fork=bool(away))
    with side:
        if away:
            side.start()
        results = {c.name: replay(c, told(i, c)) for i, c in enumerate(here)}
        try:
            sent = json.loads(side.join() or "[]")
        except ForkedTaskError:
            sent = json.loads(replay_away(""))
    results.update((c.name, method_replay_from_json(text)) for c, text in zip(away, sent,
                                                                              strict=True))
    return {c.name: results[c.name] for c in correctors}


def measured_reference(
    run: RecordedRun, time_s: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """What a replay is compared with at `time_s`: T1..T5 (k, 5) and the axial drift (k,)
    (NaN where invalid; None if not recorded), and T1..T5 at the run start (5,)."""
    measured = run.at(time_s)
    meas_T = measured.T_valid_C
    meas_drift = None
    if measured.disp_um is not None and "disp_z_um" in measured.valid:
        meas_drift = np.where(measured.valid["disp_z_um"], measured.disp_um[:, 2], np.nan)
    meas_T0 = run.before(np.array([run.time_s[0]])).T_valid_C[0]
    if np.any(~np.isfinite(meas_T0)):  # a sensor that starts invalid: its first good value
        meas_T0 = np.where(np.isfinite(meas_T0), meas_T0, first_finite(run.T_valid_C))
    return meas_T, meas_T0, meas_drift


def method_accuracy(
    r: MethodReplay, meas_T: np.ndarray, meas_T0: np.ndarray, meas_drift: np.ndarray | None
) -> dict:
    """accuracy.json entry of one method (twin.loop.metrics), its band included."""
    return accuracy_metrics(
        r.time_s, r.T_twin_C, meas_T, meas_T0, r.drift_z_um, meas_drift, band=band_of(r)
    )


def band_of(r: MethodReplay) -> tuple[np.ndarray, np.ndarray] | None:
    """(lo, hi), each (k, 6): the 90 % band of T1..T5 (°C) and the axial drift (µm)."""
    if r.band_sd is None:
        return None
    from twin.estimation.method import BAND_Z

    centre = np.column_stack([r.T_twin_C, r.drift_z_um])
    return centre - BAND_Z * r.band_sd, centre + BAND_Z * r.band_sd


def _write_keypoints(
    path: Path, results: dict[str, MethodReplay], meas_T: np.ndarray, meas_drift: np.ndarray | None
) -> None:
    header = ["time_s", "method"]
    header += [f"{s}_twin_C" for s in SENSOR_NAMES] + [f"{s}_meas_C" for s in SENSOR_NAMES]
    header += ["disp_z_twin_um", "disp_z_meas_um", "disp_r_twin_um", "disp_r_meas_um"]
    with_band = any(r.band_sd is not None for r in results.values())
    if with_band:
        for s in SENSOR_NAMES:
            header += [f"{s}_twin_lo_C", f"{s}_twin_hi_C"]
        header += ["disp_z_twin_lo_um", "disp_z_twin_hi_um"]
    rows = []
    nan = float("nan")
    for name, r in results.items():
        band = band_of(r)
        for i, t in enumerate(r.time_s):
            row = [
                float(t),
                name,
                *r.T_twin_C[i],
                *meas_T[i],
                r.drift_z_um[i],
                nan if meas_drift is None else meas_drift[i],
                r.drift_r_um[i],
                nan,
            ]
            if with_band:
                row += [nan] * 12 if band is None else [
                    v for j in range(6) for v in (band[0][i, j], band[1][i, j])
                ]
            rows.append(row)
    write_csv(path, header, rows)


def _write_corrections(path: Path, results: dict[str, MethodReplay]) -> None:
    header = [
        "window",
        "method",
        "start_s",
        "speed_rpm",
        "H_front",
        "H_rear",
        "R_front",
        "R_rear",
        "C_H_front",
        "C_H_rear",
        "C_C_front",
        "C_C_rear",
    ]
    # further values a method estimates (the estimator's motor and film factors)
    extra = list(dict.fromkeys(
        k for r in results.values() for w in r.windows for k in w.correction.factors
    ))
    header += [f"{k}_factor" for k in extra]
    # the thermocouples' time constant, where a method estimates it (the estimator)
    lagged = any(w.correction.sensor_lag_s > 0 for r in results.values() for w in r.windows)
    header += ["sensor_lag_s"] if lagged else []
    # the coolant inlet, where a method estimates it (the estimator, on a run without one)
    cooled = any(w.correction.coolant_C is not None for r in results.values() for w in r.windows)
    header += ["coolant_C"] if cooled else []
    # each thermocouple's offset, where a method estimates it (the estimator)
    offset = any(w.correction.sensor_offset_C is not None
                 for r in results.values() for w in r.windows)
    header += [f"T{i + 1}_offset_K" for i in range(5)] if offset else []
    rows = []
    for name, r in results.items():
        for w in r.windows:
            c = w.correction
            rows.append(
                [
                    w.window,
                    name,
                    w.start_s,
                    w.speed_rpm,
                    c.H_front_W_m3,
                    c.H_rear_W_m3,
                    c.R_front_m2K_W,
                    c.R_rear_m2K_W,
                    *c.C_H,
                    *c.C_C,
                    *(c.factors.get(k, float("nan")) for k in extra),
                    *([c.sensor_lag_s if c.sensor_lag_s > 0 else float("nan")] if lagged else []),
                    *([float("nan") if c.coolant_C is None else c.coolant_C] if cooled else []),
                    *((np.full(5, np.nan) if c.sensor_offset_C is None else c.sensor_offset_C)
                      if offset else []),
                ]
            )
    write_csv(path, header, rows)


def _write_fields(out_dir: Path, model: SpindleModel, fields: str, r: MethodReplay) -> None:
    """fields/*.vtu and fields.pvd of the window ends `fields` chooses; none: neither."""
    from twin.io.vtk import write_field_series
    from twin.spindle.fields import field_mesh

    times = _window_ends(r.fields, fields)
    if not times:
        return
    write_field_series(out_dir, ((t, _field_name(r.method, t),
                                  field_mesh(model, r.fields[t], r.start_reference_C))
                                 for t in times))
