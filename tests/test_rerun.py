"""Re-running a window with a missed speed change (twin.correction.rerun) in the loop: the
`bpnn` starts the next window from the re-run's field, reads its inputs off the re-run, and
the decks (window decks and the re-run deck) reproduce both the reported trajectory and
the carried state."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from twin.contract import STEPS_PER_WINDOW
from twin.correction.methods import BpnnCorrection, RatioCorrection
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


def test_the_decks_reproduce_the_reported_trajectory_and_the_carried_state(
        tmp_path, spindle_model):
    """Window 0's deck from the uniform start, window 1's deck from its end (the reported
    window 1), the re-run deck of window 1 from the same field, and window 2's deck from
    the re-run's end: the reported window 2, step by step.  Run in a fresh session, from
    the deck texts alone."""
    from apdl_like.session import Session

    model = spindle_model
    run = read_run(write_speed_step_run(tmp_path / "step.csv", model))
    replay = replay_method(run, model, BpnnCorrection(load_model(BUNDLED_MODEL)),
                           solver=deck_window_solver(model), keep_fields=False)
    w = replay.windows
    assert w[0].rerun_deck is not None  # the first window (its rings warm fastest)
    assert w[1].rerun_deck is not None  # the speed changed inside window 1
    assert all(x.rerun_deck is None for x in w if x.window > 1)
    # one load step per 4 s solver step (the loads follow the rings), 15 per window
    assert w[0].rerun_deck.count("SOLVE") == 15
    assert w[1].rerun_deck.count("SOLVE") == 15
    # a replay done in another process brings its re-run decks back
    assert method_replay_from_json(method_replay_to_json(replay)).windows[1].rerun_deck == \
        w[1].rerun_deck
    # the paper's ratio law keeps the forecast
    ratio = replay_method(run, model, RatioCorrection(), solver=direct_window_solver(model),
                          keep_fields=False)
    assert all(x.rerun_deck is None for x in ratio.windows)

    session = Session.from_mesh(model.mesh, model.materials, order=model.order,
                                T_ref_C=model.elastic.T_ref)

    def sensors(fields):
        return (model.sensor_matrix @ np.asarray(fields).T).T

    def reported(k):
        return replay.T_twin_C[k * STEPS_PER_WINDOW:(k + 1) * STEPS_PER_WINDOW]

    T = np.full(model.n_dofs, replay.T_initial_C)
    window0 = session.advance(T, 0.0, w[0].deck)
    np.testing.assert_allclose(sensors(window0), reported(0), atol=1e-9)
    rerun0_end = session.advance(T, 0.0, w[0].rerun_deck)[-1]
    window1 = session.advance(rerun0_end, 60.0, w[1].deck)
    np.testing.assert_allclose(sensors(window1), reported(1), atol=1e-9)
    rerun_end = session.advance(rerun0_end, 60.0, w[1].rerun_deck)[-1]
    # the re-run ends elsewhere than the forecast (it saw the step): by 0.45 K at T4 with
    # its loads following the rings every step (above 0.5 K in 20 s pieces) ...
    assert np.abs(sensors([rerun_end]) - sensors([window1[-1]])).max() > 0.3
    # ... and window 2 starts from it
    window2 = session.advance(rerun_end, 120.0, w[2].deck)
    np.testing.assert_allclose(sensors(window2), reported(2), atol=1e-9)
