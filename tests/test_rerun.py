"""Re-running a window with a missed speed change (twin.correction.rerun) in the loop: the
`bpnn` starts the next window from the re-run's field, reads its inputs off the re-run, and
the decks (window decks and the re-run deck) reproduce both the reported trajectory and
the carried state."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from twin.contract import STEPS_PER_WINDOW
from twin.correction.methods import BpnnCorrection, OpenLoop, RatioCorrection
from twin.correction.modelfile import load_model
from twin.correction.rerun import rerun_window, speed_stretches
from twin.loop.replay import (
    deck_window_solver,
    direct_window_solver,
    method_replay_from_json,
    method_replay_to_json,
    replay_method,
)
from twin.runs import read_run

from .test_estimation import write_speed_step_run

BUNDLED_MODEL = Path(__file__).resolve().parent.parent / "examples" / "correction_model.safetensors"


def test_stretches_of_equal_speed_are_solved_one_after_another():
    speeds = np.array([6000.0] * 4 + [12000.0] * 6 + [3000.0] * 5)
    assert speed_stretches(speeds) == [(6000.0, 0, 4), (12000.0, 4, 6), (3000.0, 10, 5)]
    calls = []

    def advance(speed, T, n, start_s):  # each step adds the speed in krpm
        calls.append((speed, n, start_s))
        return T + 1e-3 * speed * np.arange(1, n + 1)[:, None]

    fields = rerun_window(np.zeros(2), 60.0, speeds, 4.0, advance, max_steps=None)
    assert calls == [(6000.0, 4, 60.0), (12000.0, 6, 76.0), (3000.0, 5, 100.0)]
    assert fields.shape == (15, 2)
    np.testing.assert_allclose(fields[:, 0], np.cumsum(1e-3 * speeds))
    # a stretch may be solved in pieces (of 20 s here: 5 steps), each from where the
    # last ended, so that its loads can follow the field
    calls.clear()
    pieces = rerun_window(np.zeros(2), 60.0, speeds, 4.0, advance, max_steps=5)
    assert calls == [(6000.0, 4, 60.0), (12000.0, 5, 76.0), (12000.0, 1, 96.0),
                     (3000.0, 5, 100.0)]
    np.testing.assert_allclose(pieces, fields)
    # by default step by step: the loads follow the field every solver step
    calls.clear()
    steps = rerun_window(np.zeros(2), 60.0, speeds, 4.0, advance)
    assert calls == [(float(s), 1, 60.0 + 4.0 * i) for i, s in enumerate(speeds)]
    np.testing.assert_allclose(steps, fields)
    assert speed_stretches(np.full(12, 9000.0), max_steps=5) == [
        (9000.0, 0, 5), (9000.0, 5, 5), (9000.0, 10, 2)]


def test_bpnn_starts_the_next_window_from_the_rerun(tmp_path, spindle_model, monkeypatch):
    """Speed 6000 → 12000 rpm at 76 s → 3000 rpm at 100 s, inside window 1 (loads fixed at
    60 s), on the nominal model itself.  With the re-run window 2 starts from the right
    field; without it the twin carries the missed heat into the following windows."""
    model = spindle_model
    run = read_run(write_speed_step_run(tmp_path / "step.csv", model))
    network = load_model(BUNDLED_MODEL)

    def after_the_change(rerun: bool) -> tuple[float, np.ndarray]:
        """Largest |error| of T1..T5 over windows 2-3 (°C) and window 2's heat factors."""
        replay = replay_method(run, model, BpnnCorrection(network, rerun_missed_speed=rerun),
                               solver=direct_window_solver(model), keep_fields=False)
        rows = (replay.time_s > 120.0) & (replay.time_s <= 240.0)
        window = replay.windows[2]
        heat = np.array(window.correction.values[:2]) / np.array(window.nominal[:2])
        return np.abs(replay.T_twin_C - run.at(replay.time_s).T_C)[rows].max(), heat

    (with_rerun, heat_rerun), (without, heat_without) = (after_the_change(True),
                                                         after_the_change(False))
    # the truth is the nominal heat: without the re-run the ratio law reads the missed
    # 24 s at 12 000 rpm as a heat 1.4-1.6x too high; with it the factors stay near 1
    assert np.all(np.abs(np.log(heat_without)) > 0.3)
    assert np.all(np.abs(np.log(heat_rerun)) < 0.1)
    assert with_rerun < 0.7 * without


def _heat_factors_and_error(run, model, corrector) -> tuple[np.ndarray, float]:
    """Each window's heat factors (windows, 2) and the mean |error| of T1..T5 after 120 s."""
    replay = replay_method(run, model, corrector, solver=direct_window_solver(model),
                           keep_fields=False)
    factors = np.array([np.array(w.correction.values[:2]) / np.array(w.nominal[:2])
                        for w in replay.windows])
    late = replay.time_s > 120.0
    return factors, float(np.abs(replay.T_twin_C - run.at(replay.time_s).T_C)[late].mean())


def test_the_ratio_law_reads_the_rerun_not_the_missed_speed_change(tmp_path, spindle_model):
    """The step of the bpnn test above for the ratio law: its Eq. 2 compared the measured
    ring with a forecast that missed 24 s at 12 000 rpm and read a heat 1.5-1.8x too high
    (the truth is the nominal heat); from the re-run the factors stay near 1."""
    run = read_run(write_speed_step_run(tmp_path / "step.csv", spindle_model))
    rerun, _ = _heat_factors_and_error(run, spindle_model, RatioCorrection())
    forecast, _ = _heat_factors_and_error(run, spindle_model,
                                          RatioCorrection(rerun_missed_speed=False))
    assert np.all(np.abs(np.log(forecast[2])) > 0.3)
    assert np.all(np.abs(np.log(rerun[2])) < 0.1)


SPEEDS_EVERY_28_S = (6000.0, 11000.0, 8000.0, 13000.0, 7000.0, 12000.0, 9000.0)


def test_the_ratio_law_is_calm_when_the_speed_changes_inside_every_window(
        tmp_path, spindle_model):
    """A new speed every 28 s, so inside every window, on the nominal model itself (true
    factors 1).  Read off the forecast, each window's missed change became a heat factor
    for the next window at another speed: the front heat swung 0.5 <-> 2.1.  From the
    re-runs the factors stay near 1 and the twin is closer to the measurement."""
    run = read_run(write_speed_step_run(
        tmp_path / "fast.csv", spindle_model, windows=12,
        speed_at=lambda t: SPEEDS_EVERY_28_S[int(t // 28.0) % len(SPEEDS_EVERY_28_S)]))
    rerun, error = _heat_factors_and_error(run, spindle_model, RatioCorrection())
    forecast, error_forecast = _heat_factors_and_error(
        run, spindle_model, RatioCorrection(rerun_missed_speed=False))
    assert np.abs(np.log(forecast)).max() > 0.6
    assert np.abs(np.log(rerun)).max() < 0.2
    assert error < 0.9 * error_forecast


def test_after_a_rerun_every_window_reads_the_history_the_twin_ran(tmp_path, spindle_model):
    """The run above (a new speed every 28 s) on the nominal model itself with ideal
    thermocouples: with every window re-run, the twin's history is the truth and every
    correction factor stays 1.  When window k's start row in the history was the forecast's
    end of window k−1 (the re-run went to window k's correction alone), the next window's
    line read it as its first point: heat factors off by up to 6.5 %."""
    run = read_run(write_speed_step_run(
        tmp_path / "fast.csv", spindle_model, windows=12,
        speed_at=lambda t: SPEEDS_EVERY_28_S[int(t // 28.0) % len(SPEEDS_EVERY_28_S)]))
    for corrector in (RatioCorrection(), BpnnCorrection(load_model(BUNDLED_MODEL))):
        replay = replay_method(run, spindle_model, corrector,
                               solver=direct_window_solver(spindle_model), keep_fields=False)
        factors = np.array([np.array(w.correction.values) / np.array(w.nominal)
                            for w in replay.windows])
        assert np.abs(np.log(factors)).max() < 1e-4, type(corrector).__name__


def test_the_decks_reproduce_the_reported_trajectory_and_the_carried_state(
        tmp_path, spindle_model):
    """Window 0's deck from the uniform start, window 1's deck from its end (the reported
    window 1), the re-run deck of window 1 from the same field, and window 2's deck from
    the re-run's end: the reported window 2.  Run in a fresh session, from the deck texts
    alone; a session returns the last load step of a deck, so each window is checked at its
    end here (every step: `apdl-like run`'s result files, the test below)."""
    from apdl_like.session import Session

    model = spindle_model
    run = read_run(write_speed_step_run(tmp_path / "step.csv", model))
    replay = replay_method(run, model, BpnnCorrection(load_model(BUNDLED_MODEL)),
                           solver=deck_window_solver(model), keep_fields=False)
    w = replay.windows
    # window 0's loads followed its rings as they warmed: nothing to re-run there
    assert w[0].rerun_deck is None
    assert w[1].rerun_deck is not None  # the speed changed inside window 1
    assert all(x.rerun_deck is None for x in w if x.window > 1)
    # one load step per 4 s solver step (the loads follow the rings), 15 per window
    assert w[0].deck.count("SOLVE") == 15
    assert w[1].rerun_deck.count("SOLVE") == 15
    # 15 load steps stay readable: how the deck runs is said once, then each step says
    # which it is, its speed and where its loads come from (the 4-line header and
    # "15 steps ... held over the window" were repeated on every 4 s step)
    lines = w[1].rerun_deck.splitlines()
    assert sum("loads only" in x for x in lines) == 1
    assert sum("load step" in x and " of 15: " in x for x in lines) == 15
    assert "! ---- window 1, load step 5 of 15: t = 76 .. 80 s, 1 step of 4 s" in lines
    assert "! re-run at the recorded speed 12000 rpm; bearing heat and contact resistance " \
           "follow the rings:" in lines
    assert not any("held over the window" in x or "1 steps" in x for x in lines)
    assert w[2].deck.count("SOLVE") == 15 and w[2].deck.count("loads only") == 1
    # held for each window (the paper's literal boundary conditions), window 0 kept the
    # cold start's loads for 60 s: it is re-run, and a deck is one load step
    held = replay_method(run, model, BpnnCorrection(load_model(BUNDLED_MODEL),
                                                    loads_follow_rings=False),
                         solver=deck_window_solver(model), keep_fields=False)
    assert held.windows[0].rerun_deck is not None and held.windows[1].rerun_deck is not None
    assert held.windows[2].deck.count("SOLVE") == 1
    assert "held over the window" in held.windows[2].deck
    # a replay done in another process brings its re-run decks back
    assert method_replay_from_json(method_replay_to_json(replay)).windows[1].rerun_deck == \
        w[1].rerun_deck
    # the ratio law re-runs as bpnn does; open loop keeps the forecast
    ratio = replay_method(run, model, RatioCorrection(), solver=deck_window_solver(model),
                          keep_fields=False)
    assert ratio.windows[1].rerun_deck is not None
    assert all(x.rerun_deck is None for x in ratio.windows if x.window != 1)
    forecast = replay_method(run, model, OpenLoop(), solver=direct_window_solver(model),
                             keep_fields=False)
    assert all(x.rerun_deck is None for x in forecast.windows)

    session = Session.from_mesh(model.mesh, model.materials, order=model.order,
                                T_ref_C=model.elastic.T_ref)

    def sensors(fields):
        return (model.sensor_matrix @ np.asarray(fields).T).T

    def reported(k):
        return replay.T_twin_C[k * STEPS_PER_WINDOW:(k + 1) * STEPS_PER_WINDOW]

    T = np.full(model.n_dofs, replay.T_initial_C)
    window0 = session.advance(T, 0.0, w[0].deck)
    np.testing.assert_allclose(sensors(window0[-1:]), reported(0)[-1:], atol=1e-9)
    window1 = session.advance(window0[-1], 60.0, w[1].deck)
    np.testing.assert_allclose(sensors(window1[-1:]), reported(1)[-1:], atol=1e-9)
    rerun_end = session.advance(window0[-1], 60.0, w[1].rerun_deck)[-1]
    # the re-run ends elsewhere than the forecast (it saw the step): by 0.45 K at T4 with
    # its loads following the rings every step (above 0.5 K in 20 s pieces) ...
    assert np.abs(sensors([rerun_end]) - sensors([window1[-1]])).max() > 0.3
    # ... and window 2 starts from it
    window2 = session.advance(rerun_end, 120.0, w[2].deck)
    np.testing.assert_allclose(sensors(window2[-1:]), reported(2)[-1:], atol=1e-9)


def test_every_window_runs_with_apdl_like_from_the_replays_outputs(tmp_path, spindle_model):
    """A user's audit of `twin replay`'s decks with `apdl-like run`, from the folder alone.
    The estimator starts each window from its analysed field and bpnn the window after a
    re-run from the re-run's end, neither the end of the deck before: no command could run
    those windows (`--start` did not exist, no start field was written), and chaining the
    decks missed the analysis or the re-run by kelvins.  Each such window's start field is
    `decks/.../window_kkk_start.vtu` (with the estimator's readings and lag), and a result
    file of `apdl-like run` starts the next deck too."""
    import csv

    import meshio
    from typer.testing import CliRunner

    from apdl_like.cli import app as apdl_app
    from twin.cli import app
    from twin.lag import first_order_lag

    model = spindle_model
    run = write_speed_step_run(tmp_path / "step.csv", model, drift=True)  # offsets too
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["replay", str(run), "--out", str(out), "--methods",
                                      "bpnn,estimator", "--snapshots", "none", "--quiet"])
    assert result.exit_code == 0, result.output
    run_dir = out / "step"
    with open(run_dir / "keypoints.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))

    def reported(method, k):  # T1..T5 of window k as keypoints.csv has them (6 digits)
        return np.array([[float(r[f"T{i}_twin_C"]) for i in range(1, 6)] for r in rows
                         if r["method"] == method
                         and 60.0 * k < float(r["time_s"]) <= 60.0 * (k + 1)])

    def apdl(deck, start, name):
        args = ["run", str(deck), "--spindle", "--quiet", "--out", str(tmp_path / name)]
        result = CliRunner().invoke(apdl_app, args + (["--start", str(start)] if start else []))
        assert result.exit_code == 0, result.output
        return [meshio.read(f) for f in sorted((tmp_path / name).glob("result_*.vtu"))]

    def sensors(vtu):
        return model.sensor_matrix @ vtu.point_data["TEMP"]

    # the estimator's window 2: its deck from its analysed field, 15 load steps of 4 s; the
    # metal at T1..T5 through the stated lag from the stated readings, plus the stated
    # thermocouple offsets, is what it reported
    decks = run_dir / "decks" / "estimator"
    start = meshio.read(decks / "window_002_start.vtu")
    assert start.field_data["TIME"][0] == 120.0
    steps = apdl(decks / "window_002.inp", decks / "window_002_start.vtu", "est2")
    assert [s.field_data["TIME"][0] for s in steps] == [120.0 + 4.0 * i for i in range(1, 16)]
    metal = np.vstack([sensors(start), [sensors(s) for s in steps]])
    readings = first_order_lag(metal, 4.0 * np.arange(16), start.field_data["SENSOR_LAG_S"][0],
                               start.field_data["READINGS_START_C"])[1:]
    readings = readings + start.field_data["SENSOR_OFFSET_C"]
    np.testing.assert_allclose(readings, reported("estimator", 2), atol=1e-4)
    # the analysed field is not the forecast's end: chaining the decks would miss it
    window1 = apdl(decks / "window_001.inp", decks / "window_001_start.vtu", "est1")
    assert np.abs(sensors(window1[-1]) - sensors(start)).max() > 0.05

    # bpnn: window 1's re-run from window 1's start ends on window 2's start field, from
    # which window 2's deck gives the reported window 2
    decks = run_dir / "decks"
    rerun = apdl(decks / "window_001_rerun.inp", decks / "window_001_start.vtu", "rerun1")
    window2_start = meshio.read(decks / "window_002_start.vtu").point_data["TEMP"]
    np.testing.assert_allclose(rerun[-1].point_data["TEMP"], window2_start, atol=1e-9)
    window2 = apdl(decks / "window_002.inp", tmp_path / "rerun1" / "result_015.vtu", "bpnn2")
    np.testing.assert_allclose(sensors(window2[-1]), reported("bpnn", 2)[-1], atol=1e-4)
    window1 = apdl(decks / "window_001.inp", decks / "window_001_start.vtu", "bpnn1")
    assert np.abs(sensors(window1[-1]) - sensors(rerun[-1])).max() > 0.3

    # a start state needs the spindle's nodes; a file that is not one is named
    result = CliRunner().invoke(apdl_app, ["run", str(decks / "window_002.inp"), "--out",
                                           str(tmp_path / "x"), "--start", str(run)])
    assert result.exit_code == 2 and "--start needs --spindle" in result.output
    result = CliRunner().invoke(apdl_app, ["run", str(decks / "window_002.inp"), "--spindle",
                                           "--out", str(tmp_path / "x"), "--start", str(run)])
    assert result.exit_code == 2 and f"{run}" in result.output and "vtu" in result.output
    assert len(result.output.strip().splitlines()) == 1
