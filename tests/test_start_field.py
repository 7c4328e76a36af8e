"""The field a replay starts from (`twin.loop.start_field`): uniform at rest, fitted to the
first readings where the recording begins on a warm spindle.  The warm cases are the twin's
own simulation cut part-way, so the true start field is known."""

from __future__ import annotations

import csv
import json

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

from twin.loop.start_field import WARM_START_SPREAD_K, start_field
from twin.runs import read_run, write_run
from twin.spindle.conditions import nominal_conditions
from twin.spindle.simulate import simulate

AMBIENT_C = 22.0


@pytest.fixture(scope="module")
def warm_up(spindle_model):
    """30 min at 9000 rpm from a uniform 22 °C, the field every minute."""
    return simulate(spindle_model, 9000.0, 30.0, AMBIENT_C, field_every_s=60.0)


def cut_run(path, sim, cut_s, speed_rpm=9000.0):
    """`sim` recorded from `cut_s` on (time and probe zeroed there), as a logger started
    on a warm spindle would write it."""
    keep = sim.time_s >= cut_s
    t = sim.time_s[keep] - cut_s
    columns = {"time_s": t, "speed_rpm": np.full(t.size, speed_rpm),
               "ambient_C": np.full(t.size, AMBIENT_C)}
    for i in range(5):
        columns[f"T{i + 1}_C"] = sim.sensors_C[keep, i]
    columns["disp_z_um"] = sim.disp_z_um[keep] - sim.disp_z_um[keep][0]
    write_run(path, columns)
    return read_run(path)


def replay_open_loop(run_csv, out):
    """`twin replay RUN --methods open_loop` into `out`: (its quality.json findings, the
    text of its first window's deck)."""
    from twin.cli import app

    result = CliRunner().invoke(app, ["replay", str(run_csv), "--out", str(out), "--methods",
                                      "open_loop", "--snapshots", "none", "--fields", "none",
                                      "--quiet"])
    assert result.exit_code == 0, result.output
    name = run_csv.stem
    found = json.loads((out / name / "quality.json").read_text())["findings"]
    return found, (out / name / "decks" / "window_000.inp").read_text()


def test_a_spindle_at_rest_starts_uniform_at_the_mean_of_its_first_readings(tmp_path,
                                                                           spindle_model):
    """T5 1.6 K above the others, as a thermocouple's calibration offset may put it, is
    still a spindle at rest (fitted, it made a motor-heated rotor 8-20 K warm)."""
    columns = {"time_s": np.arange(130.0), "speed_rpm": np.full(130, 9000.0),
               "ambient_C": np.full(130, AMBIENT_C)}
    first = [22.1, 22.4, 22.0, 22.3, 22.2 + 0.9 * WARM_START_SPREAD_K - 0.2]
    for i, value in enumerate(first):
        columns[f"T{i + 1}_C"] = np.full(130, value)
    write_run(tmp_path / "rest.csv", columns)
    start = start_field(spindle_model, read_run(tmp_path / "rest.csv"))
    assert start.uniform and start.history == "at rest"
    np.testing.assert_array_equal(start.field_C, np.full(spindle_model.n_dofs, np.mean(first)))


def test_a_warm_start_is_fitted_close_to_the_true_field(tmp_path, spindle_model, warm_up):
    """Cut 15 min into a warm-up, the fitted field reads T1..T5 within 0.05 K and lies
    within a few tenths of a kelvin of the true field everywhere that matters, where the
    uniform start at the readings' mean is kelvins off."""
    true = dict(warm_up.fields)[900.0]
    run = cut_run(tmp_path / "cut.csv", warm_up, 900.0)
    start = start_field(spindle_model, run)
    assert not start.uniform and start.history.startswith("warming")
    S = spindle_model.sensor_matrix
    assert np.abs(S @ start.field_C - S @ true).max() < 0.05
    rms = float(np.sqrt(np.mean((start.field_C - true) ** 2)))
    uniform = float(np.sqrt(np.mean((np.mean(S @ true) - true) ** 2)))
    assert rms < 0.5 and uniform > 4.0 * rms, (rms, uniform)
    # the nose drift the field holds (what the twin's drift grows from) is close too
    drift = 1e6 * spindle_model.probe_vectors[0]
    assert abs(drift @ (start.field_C - true)) < 0.1 * abs(drift @ (true - AMBIENT_C))


def test_a_recording_that_begins_in_a_pause_is_fitted_as_a_cooling_spindle(tmp_path,
                                                                           spindle_model):
    ran = simulate(spindle_model, 9000.0, 60.0, AMBIENT_C)
    stopped = nominal_conditions(spindle_model, 0.0, AMBIENT_C)
    stepper = spindle_model.thermal.transient(stopped.to_thermal_loads(), dt=4.0)
    *_, true = stepper.march(ran.final_T, 150)  # 10 min stopped
    S = spindle_model.sensor_matrix
    t = np.arange(130.0)
    columns = {"time_s": t, "speed_rpm": np.zeros(t.size), "ambient_C": np.full(t.size, 22.0)}
    for i, value in enumerate(S @ true):
        columns[f"T{i + 1}_C"] = np.full(t.size, value)
    write_run(tmp_path / "pause.csv", columns)
    start = start_field(spindle_model, read_run(tmp_path / "pause.csv"))
    assert start.history.startswith("stopped")
    assert np.abs(S @ start.field_C - S @ true).max() < 0.1
    rms = float(np.sqrt(np.mean((start.field_C - true) ** 2)))
    uniform = float(np.sqrt(np.mean((np.mean(S @ true) - true) ** 2)))
    assert uniform > 3.0 * rms, (rms, uniform)


def test_a_warm_start_replays_the_twins_own_run_from_the_cut(tmp_path, spindle_model, warm_up):
    """Open loop on the twin's own warm-up cut at 15 min is the twin itself: from the fitted
    start it follows the rest of the warm-up within 0.05 K (measured 0.006 K) and its
    drift within 10 % of its change (0.01 of 0.41 µm); from a uniform start at the
    readings' mean (as every replay started before) T5 ran 6.8 K off, T3 4.8 K, and the
    drift 2.6 µm."""
    from twin.correction.methods import OpenLoop
    from twin.loop.replay import replay_method
    from twin.loop.start_field import StartField

    run = cut_run(tmp_path / "cut.csv", warm_up, 900.0)
    replay = replay_method(run, spindle_model, OpenLoop(), keep_fields=False)
    later = warm_up.time_s >= 900.0
    measured = warm_up.sensors_C[later][1:1 + len(replay.time_s)]
    assert np.abs(replay.T_twin_C - measured).max() < 0.05
    rise = warm_up.disp_z_um[later][1:1 + len(replay.time_s)] - warm_up.disp_z_um[later][0]
    assert np.abs(replay.drift_z_um - rise).max() < 0.1 * np.abs(rise).max()

    mean = float(np.mean(run.T_C[0]))
    flat = StartField(np.full(spindle_model.n_dofs, mean), True, "at rest", mean, (), 0.0)
    uniform = replay_method(run, spindle_model, OpenLoop(), keep_fields=False, start=flat)
    assert np.abs(uniform.T_twin_C - measured).max() > 3.0
    assert np.abs(uniform.drift_z_um - rise).max() > 1.0


def test_a_warm_starts_replay_says_so_and_its_first_deck_runs_from_the_written_field(
        tmp_path, spindle_model, warm_up):
    """quality.json tells the fitted start; the first window's deck restarts from
    decks/window_000_start.vtu and, run with apdl-like, gives the reported window."""
    from apdl_like.cli import app as apdl_app

    cut_run(tmp_path / "cut.csv", warm_up, 900.0)
    out = tmp_path / "out"
    found, deck = replay_open_loop(tmp_path / "cut.csv", out)
    warm = [f for f in found if f["kind"] == "warm_start"]
    assert len(warm) == 1 and "warming" in warm[0]["detail"], found
    decks = out / "cut" / "decks"
    antypes = [line for line in deck.splitlines() if line.startswith("ANTYPE")]
    assert antypes[0] == "ANTYPE,TRANS,REST" and "TUNIF" not in deck
    result = CliRunner().invoke(apdl_app, [
        "run", str(decks / "window_000.inp"), "--spindle", "--quiet", "--out",
        str(tmp_path / "w0"), "--start", str(decks / "window_000_start.vtu")])
    assert result.exit_code == 0, result.output
    last = meshio.read(sorted((tmp_path / "w0").glob("result_*.vtu"))[-1])
    with open(out / "cut" / "keypoints.csv", newline="") as fh:
        rows = [r for r in csv.DictReader(fh) if float(r["time_s"]) == 60.0]
    reported = [float(rows[0][f"T{i}_twin_C"]) for i in range(1, 6)]
    np.testing.assert_allclose(spindle_model.sensor_matrix @ last.point_data["TEMP"],
                               reported, atol=1e-4)


def test_a_cold_starts_replay_tells_nothing_and_starts_its_deck_from_tunif(tmp_path,
                                                                         spindle_model):
    sim = simulate(spindle_model, 9000.0, 3.0, AMBIENT_C)
    cut_run(tmp_path / "cold.csv", sim, 0.0)
    out = tmp_path / "out"
    found, deck = replay_open_loop(tmp_path / "cold.csv", out)
    assert not [f for f in found if f["kind"] == "warm_start"]
    antypes = [line for line in deck.splitlines() if line.startswith("ANTYPE")]
    assert antypes[0] == "ANTYPE,TRANS" and "TUNIF,22" in deck
    assert not (out / "cold" / "decks" / "window_000_start.vtu").exists()


def test_a_recording_begun_just_after_a_stop_is_not_fitted_as_a_far_hotter_spindle(
        tmp_path, spindle_model):
    """A logger started seconds after the spindle stopped (20 min at 14700 rpm) finds the
    rings at their running temperatures.  The cooling family began one minute into the
    pause, so the fit took that minute's cooling up with source scales of 5.5 and 3.9: a
    field up to 108 °C where the spindle held 48, 26 K RMS off (the uniform start 8.9) and
    the open-loop drift 17 µm off over the run (from the uniform start 2.6).  Its first
    seconds of cooling are in the family now: 2.3 K RMS off, the drift 0.4 µm."""
    from twin.correction.methods import OpenLoop
    from twin.loop.replay import replay_method

    ran = simulate(spindle_model, 14700.0, 20.0, AMBIENT_C)
    stopped = nominal_conditions(spindle_model, 0.0, AMBIENT_C)
    stepper = spindle_model.thermal.transient(stopped.to_thermal_loads(), dt=4.0)
    fields = np.array(list(stepper.march(ran.final_T, 45)))  # 3 min stopped, every 4 s
    true = fields[0]  # the recording begins 4 s after the stop
    S = spindle_model.sensor_matrix
    drift = 1e6 * spindle_model.probe_vectors[0]
    columns = {"time_s": 4.0 * np.arange(len(fields)), "speed_rpm": np.zeros(len(fields)),
               "ambient_C": np.full(len(fields), AMBIENT_C),
               "disp_z_um": np.asarray((fields - true) @ drift).ravel()}
    for i, values in enumerate(S @ fields.T):
        columns[f"T{i + 1}_C"] = values
    write_run(tmp_path / "stop.csv", columns)
    run = read_run(tmp_path / "stop.csv")
    start = start_field(spindle_model, run)
    assert start.history.startswith("stopped")
    # the family's history (60 min at 9000 rpm) is not this one: the rotor is fitted 5.6 K
    # hotter than it was (was 60 K)
    assert start.field_C.max() < true.max() + 8.0, (start.history, start.field_C.max())
    rms = float(np.sqrt(np.mean((start.field_C - true) ** 2)))
    uniform = float(np.sqrt(np.mean((np.mean(S @ true) - true) ** 2)))
    assert rms < 0.5 * uniform, (rms, uniform)
    replay = replay_method(run, spindle_model, OpenLoop(), keep_fields=False, start=start)
    measured = columns["disp_z_um"][1:1 + len(replay.time_s)]
    assert np.abs(replay.drift_z_um - measured).max() < 1.0


@pytest.fixture(scope="module")
def hour_at_9000(spindle_model):
    """An hour at 9000 rpm (the history the cooling family assumes), then 12 min stopped:
    the field every 4 s of the pause."""
    ran = simulate(spindle_model, 9000.0, 60.0, AMBIENT_C)
    stopped = nominal_conditions(spindle_model, 0.0, AMBIENT_C)
    stepper = spindle_model.thermal.transient(stopped.to_thermal_loads(), dt=4.0)
    return np.array(list(stepper.march(ran.final_T, 180)))


def pause_run(path, model, fields):
    S = model.sensor_matrix
    drift = 1e6 * model.probe_vectors[0]
    columns = {"time_s": 4.0 * np.arange(len(fields)), "speed_rpm": np.zeros(len(fields)),
               "ambient_C": np.full(len(fields), AMBIENT_C),
               "disp_z_um": np.asarray((fields - fields[0]) @ drift).ravel()}
    for i, values in enumerate(S @ fields.T):
        columns[f"T{i + 1}_C"] = values
    write_run(path, columns)
    return read_run(path), columns["disp_z_um"]


@pytest.mark.parametrize("after_s", [4.0, 600.0])
def test_a_pause_is_fitted_with_plausible_scales_not_whichever_meets_the_readings_best(
        tmp_path, spindle_model, hour_at_9000, after_s):
    """The twin's own pause after the very history the family assumes.  Chosen by the
    readings' misfit alone (0.14 to 0.24 K RMS over the first minutes), 4 s into it the fit
    took 2 min of cooling from three times the bearing heat (scales 3.0, 0.8, 2.4): a field
    12.8 K RMS off (uniform 8.1), the open-loop drift 9.8 µm off (uniform 1.1); 10 min into
    it, 90 min of cooling from 36 times the heat.  Chosen by the fit's whole cost, with the
    common scale drawn towards the nominal heat: 4.8 K and 1.8 µm, and 12 min from scales
    near 1."""
    from twin.correction.methods import OpenLoop
    from twin.loop.replay import replay_method

    fields = hour_at_9000[int(after_s / 4.0) - 1:]
    run, measured = pause_run(tmp_path / "pause.csv", spindle_model, fields)
    start = start_field(spindle_model, run)
    assert start.history.startswith("stopped")
    assert max(start.scales) < 2.0, (start.history, start.scales)
    S = spindle_model.sensor_matrix
    rms = float(np.sqrt(np.mean((start.field_C - fields[0]) ** 2)))
    uniform = float(np.sqrt(np.mean((np.mean(S @ fields[0]) - fields[0]) ** 2)))
    assert rms < 0.7 * uniform, (rms, uniform)
    replay = replay_method(run, spindle_model, OpenLoop(), keep_fields=False, start=start)
    assert np.abs(replay.drift_z_um - measured[1:1 + len(replay.time_s)]).max() < 2.5


def test_a_cold_start_loads_no_fitting_library(tmp_path):
    """A cold start is replayed as before, at its cost before: the bounded least squares'
    module (scipy.optimize) loaded with the replay for every run added 9 MB to a cold
    replay's peak memory (bench `replay_peak_rss_MB` 132 -> 141) and its import time."""
    import subprocess
    import sys

    t = np.arange(130.0)
    columns = {"time_s": t, "speed_rpm": np.full(t.size, 9000.0),
               "ambient_C": np.full(t.size, AMBIENT_C)}
    for i in range(5):
        columns[f"T{i + 1}_C"] = np.full(t.size, AMBIENT_C + 0.1 * i)
    write_run(tmp_path / "rest.csv", columns)
    probe = (
        "import json, sys\n"
        "from twin.loop.runfiles import replay_run_to_dir\n"
        "from twin.loop.start_field import start_field\n"
        "from twin.runs import read_run\n"
        "from twin.spindle.model import SpindleModel\n"
        f"start = start_field(SpindleModel.load(), read_run({str(tmp_path / 'rest.csv')!r}))\n"
        "assert start.uniform\n"
        "print(json.dumps(sorted(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", probe], check=True, capture_output=True,
                         text=True).stdout
    loaded = set(json.loads(out.splitlines()[-1]))
    assert "twin.loop.start_field" in loaded and "scipy.optimize" not in loaded


def test_a_warm_start_is_not_told_its_speed_may_be_in_rev_per_s(tmp_path):
    """`warms_unlike_twin` compares the thermocouples' rise with the open-loop twin's at the
    recorded speeds, calibrated on runs begun at rest.  From a fitted warm start the twin's
    rise is that of the guessed history's continuation: a spindle whose bearings run 40 %
    and motor 30 % above nominal (as suite runs draw), recorded from 10 min into 12000 rpm,
    was told its speed might be in rev/s (rise 3.3 K, 3347 times the twin's), as 5 of 42
    warm recordings cut from suite runs were; from the uniform start before, none."""
    from twin.cli import app

    (tmp_path / "hot.toml").write_text(
        "[bearing_heat.front]\ntime_s = [0]\nfactor = [1.4]\n"
        "[bearing_heat.rear]\ntime_s = [0]\nfactor = [1.4]\n"
        "[motor_heat]\ntime_s = [0]\nfactor = [1.3]\n")
    run = tmp_path / "hot.csv"
    result = CliRunner().invoke(app, [
        "synth", "--speed", "12000", "--minutes", "40", "--ambient", "22", "--seed", "7000123",
        "--scenario", str(tmp_path / "hot.toml"), "--record-from", "10", "--out", str(run)])
    assert result.exit_code == 0, result.output
    found, _ = replay_open_loop(run, tmp_path / "out")
    kinds = [f["kind"] for f in found]
    assert "warm_start" in kinds and "warms_unlike_twin" not in kinds, found


def test_resume_draws_a_warm_starts_snapshot_without_fitting_its_start_again(
        tmp_path, spindle_model, warm_up, monkeypatch):
    """`--resume` adding a snapshot to a finished warm-start folder took the picture's drift
    from the start field fitted again (0.17 s a run); it reads the start the replay wrote
    (decks/window_000_start.vtu) and draws the replay's own picture, its drift caption
    (measured from that start) included."""
    from twin.loop import runfiles
    from twin.loop.batch import replay_batch

    run = cut_run(tmp_path / "cut.csv", warm_up, 1500.0)
    assert not start_field(spindle_model, run).uniform
    fresh = tmp_path / "fresh"
    replay_batch([str(tmp_path / "cut.csv")], fresh, ["open_loop"], None, snapshots="end")
    out = tmp_path / "out"
    replay_batch([str(tmp_path / "cut.csv")], out, ["open_loop"], None, snapshots="none")

    def fitted_again(*_: object) -> None:
        raise AssertionError("the start field was fitted again")

    monkeypatch.setattr(runfiles, "start_field", fitted_again)
    resumed = replay_batch([str(tmp_path / "cut.csv")], out, ["open_loop"], None,
                           snapshots="end", resume=True)
    assert resumed.skipped == ["cut"] and not resumed.failed, resumed.failed
    name = "snapshots/open_loop_t00300s.png"
    assert (out / "cut" / name).read_bytes() == (fresh / "cut" / name).read_bytes()
