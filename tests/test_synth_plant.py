"""The emulated spindle: differs from the nominal twin like a real spindle, stays physical."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from twin.plant.emulator import DT_S, synthesize, write_synth
from twin.plant.profile import SpeedProfile
from twin.plant.scenario import Scenario, parse_scenario
from twin.plant.timetable import StepTable
from twin.runs import read_run

AMBIENT = 25.3
STEADY_EXTERNALS = f"""
[coolant]
time_s = [0]
inlet_C = [{AMBIENT}]
[ambient]
time_s = [0]
ambient_C = [{AMBIENT}]
"""


@pytest.fixture(scope="module")
def truth_spindle():
    """The truth's spindle model (the default scenario's mesh), built once for the module."""
    from twin.spindle import SpindleModel

    return SpindleModel.load(size_factor=Scenario().model.size_factor)


@pytest.fixture(scope="module")
def default_run(truth_spindle):
    return synthesize(model=truth_spindle, speed_rpm=9000, minutes=30, ambient_C=AMBIENT, seed=1)


@pytest.fixture(scope="module")
def nominal(spindle_model):
    """The twin's open loop: nominal loads on the default mesh (issue 3's simulate)."""
    from twin.spindle import simulate

    return simulate(spindle_model, 9000, 30, AMBIENT)


def test_deterministic_by_seed(default_run, truth_spindle):
    again = synthesize(model=truth_spindle, speed_rpm=9000, minutes=30, ambient_C=AMBIENT, seed=1)
    other = synthesize(model=truth_spindle, speed_rpm=9000, minutes=30, ambient_C=AMBIENT, seed=2)
    for name, values in default_run.columns.items():
        np.testing.assert_array_equal(values, again.columns[name])
    assert not np.array_equal(default_run.columns["T1_C"], other.columns["T1_C"])
    assert default_run.metadata == again.metadata


def test_open_loop_twin_error_clearly_above_noise(default_run, nominal):
    t = default_run.columns["time_s"]
    twin_T1 = np.interp(t, nominal.time_s, nominal.sensors_C[:, 0])
    error = np.abs(default_run.columns["T1_C"] - twin_T1)
    assert error[t >= 600].mean() > 5 * 0.05  # sensor noise 0.05 °C
    # ... yet the same spindle: within a few kelvin of the nominal model
    assert error.max() < 3.0
    rise = default_run.truth["T1_true_C"][-1] - AMBIENT
    assert 3.0 < rise < 25.0


def test_energy_balance_every_step(default_run):
    truth = default_run.extra["truth_run"]
    assert default_run.max_relative_residual < 1e-8
    # heat in is what Palmgren × factor and the motor loss put in: bearings are part of it
    loads = default_run.truth
    assert np.all(truth.heat_in_W > 0)
    assert np.all(loads["H_front"] > 0) and np.all(loads["R_front"] > 0)


def test_monotone_warm_up_at_constant_speed(truth_spindle):
    run = synthesize(model=truth_spindle, speed_rpm=9000, minutes=30, ambient_C=AMBIENT, seed=4,
                     scenario=parse_scenario(STEADY_EXTERNALS))
    truth = run.extra["truth_run"]
    T = truth.sensors_C
    # the preload relaxing may pull a ring back by a few hundredths of a kelvin: never
    # more than the sensor noise below the running maximum
    drop = np.maximum.accumulate(T, axis=0) - T
    assert drop.max() < 0.05
    # the housing (T5) warms least: about 0.5 K in 30 min, less with a strong housing film
    assert np.all(T[-1] - T[0] > 0.3)
    assert np.all(np.diff(truth.disp_z_um) >= -1e-9)
    assert 4.0 < truth.disp_z_um[-1] < 15.0  # the reference system: 8.47 µm


def test_cold_start_rings_warm_without_steps(truth_spindle):
    """The truth's bearing heat follows its rings every step.  Held over 20 s from the cold
    start (oil at ambient, too much heat) it dropped T1 by 0.46 K (T3 0.44 K) in this run's
    2 s step after 20 s and by 0.15 K in the next, and again, less, every 20 s."""
    run = synthesize(model=truth_spindle, speed_rpm=15000, minutes=3, ambient_C=AMBIENT, seed=1,
                     scenario=parse_scenario(STEADY_EXTERNALS))
    truth = run.extra["truth_run"]
    rings = truth.sensors_C[:, [0, 2]]  # T1, T3: the outer rings
    steps = np.diff(rings, axis=0)
    # a warm-up at full speed: the rings rise by 0.018-2.2 K per 2 s step throughout
    assert steps.min() > 1e-3, f"a ring cooled by {-steps.min():.3f} K in one step"
    # the nominal heat is taken every step: it falls as the oil warms, step by step
    H = truth.loads["H_front_nominal"]
    assert np.all(np.diff(H[:-1]) < 0) and H[0] > 1.1 * H[-1]


def test_truth_factors_follow_the_scenario(truth_spindle):
    scenario = parse_scenario(STEADY_EXTERNALS + """
[bearing_heat.front]
time_s = [0, 300, 1800]
factor = [1.00, 1.12, 1.04]
[contact_resistance.rear]
time_s = [0, 600]
factor = [1.0, 0.7]
""")
    run = synthesize(model=truth_spindle, speed_rpm=9000, minutes=12, ambient_C=AMBIENT, seed=3,
                     scenario=scenario)
    t, truth = run.columns["time_s"], run.truth
    # bearing factors are taken at every 2 s step's start: a 1 s sample reads its step's
    # (the last sample, the end state, the last step's)
    starts = np.minimum(t - t % DT_S, t[-1] - DT_S)
    expected_H = np.interp(starts, [0, 300, 1800], [1.0, 1.12, 1.04])
    np.testing.assert_allclose(truth["factor_H_front"], expected_H, rtol=1e-9)
    expected_R = np.interp(starts, [0, 600], [1.0, 0.7])
    np.testing.assert_allclose(truth["factor_R_rear"], expected_R, rtol=1e-9)
    np.testing.assert_allclose(truth["R_rear"], truth["R_rear_nominal"] * expected_R, rtol=1e-12)
    np.testing.assert_allclose(truth["coolant_C"], AMBIENT)


def test_sensor_lag_and_noise(truth_spindle):
    quiet = "[sensors]\nnoise_C = 0.0\nnoise_um = 0.0\nlag_s = 8.0\n"
    scenario = parse_scenario(STEADY_EXTERNALS + quiet)
    run = synthesize(model=truth_spindle, speed_rpm=9000, minutes=10, ambient_C=AMBIENT, seed=5,
                     scenario=scenario)
    t, truth = run.columns["time_s"], run.truth["T1_true_C"]
    slope = np.gradient(truth, t)
    i = np.searchsorted(t, 400.0)
    # a first-order sensor on a slowly bending ramp trails by τ·dT/dt
    assert run.columns["T1_C"][i] == pytest.approx(truth[i] - 8.0 * slope[i], abs=0.01)
    noisy = synthesize(model=truth_spindle, speed_rpm=9000, minutes=10, ambient_C=AMBIENT, seed=5,
                       scenario=parse_scenario(STEADY_EXTERNALS))
    residual = noisy.columns["T3_C"] - run.columns["T3_C"]
    assert np.std(residual) == pytest.approx(0.05, rel=0.1)
    assert np.std(noisy.columns["disp_z_um"] - run.columns["disp_z_um"]) == pytest.approx(
        0.1, rel=0.1)


def test_xy_drift_is_a_few_microns(default_run):
    for axis in ("x", "y"):
        final = abs(default_run.truth[f"disp_{axis}_true_um"][-1])
        assert 0.5 < final < 6.0


def test_written_run_reads_clean_and_faults_are_found(tmp_path, default_run, truth_spindle):
    path, truth_path = write_synth(default_run, tmp_path / "run.csv")
    run = read_run(path)
    assert run.quality == [] and run.coolant_C is not None and run.disp_um.shape == (1801, 3)
    assert truth_path.name == "run.truth.csv" and truth_path.exists()
    faulty = synthesize(model=truth_spindle, speed_rpm=9000, minutes=20, ambient_C=AMBIENT, seed=1,
                        scenario=parse_scenario("""
[faults]
stuck = ["T2"]
dropouts = [{sensor = "T4", start_s = 600, end_s = 660}]
spikes = [{sensor = "T1", time_s = 300, size = 6.0}]
"""))
    path, _ = write_synth(faulty, tmp_path / "faulty.parquet")
    found = {(f["column"], f["kind"]) for f in read_run(path).quality}
    assert found == {("T2_C", "stuck"), ("T4_C", "long_dropout"), ("T1_C", "spike")}


def test_speed_profile_steps_the_loads(truth_spindle):
    profile = SpeedProfile(StepTable([0.0, 301.0], [6000.0, 12000.0]))
    run = synthesize(model=truth_spindle, profile=profile, minutes=10, ambient_C=AMBIENT, seed=2,
                     scenario=parse_scenario(STEADY_EXTERNALS))
    t, speed = run.columns["time_s"], run.columns["speed_rpm"]
    assert speed[t < 301].max() == 6000.0 and speed[t >= 301].min() == 12000.0
    applied = run.truth["speed_rpm"]
    first_fast = t[np.argmax(applied == 12000.0)]
    assert 301.0 <= first_fast <= 301.0 + DT_S  # the load update follows the change
    T1 = run.truth["T1_true_C"]
    before = np.gradient(T1, t)[(t > 250) & (t < 300)].mean()
    after = np.gradient(T1, t)[(t > 320) & (t < 370)].mean()
    assert after > before  # more heat at the higher speed


def test_cli(tmp_path):
    from twin.cli import app

    runner = CliRunner()
    out = tmp_path / "r.csv"
    ok = runner.invoke(app, ["synth", "--speed", "9000", "--minutes", "3", "--ambient", "25",
                             "--seed", "1", "--out", str(out), "--quiet"])
    assert ok.exit_code == 0, ok.output
    assert read_run(out).duration_s == 180.0 and (tmp_path / "r.truth.csv").exists()
    for args in (["--speed", "9000", "--profile", "p.csv"], ["--speed", "20000"],
                 ["--speed", "9000", "--rate", "50"], ["--speed", "9000", "--minutes", "1"]):
        argv = ["synth", "--minutes", "3", "--ambient", "25", "--seed", "1",
                "--out", str(tmp_path / "x.csv"), *args]
        bad = runner.invoke(app, argv)
        assert bad.exit_code == 2, (args, bad.output)
    assert not (tmp_path / "x.csv").exists()


@pytest.mark.parametrize("ambient", ["45", "-40"])
def test_a_run_emulated_at_a_bound_of_the_range_replays(tmp_path, ambient):
    """--ambient 45 and -40 lie in the range every reader accepts, but the air and inlet
    readings' noise crossed it: the run was emulated and then refused ("would be refused
    by replay", at 45 as "looks like Fahrenheit").  The readings now stay in the range."""
    from twin.cli import app
    from twin.contract import OPERATING_TEMPERATURE_C

    out = tmp_path / "bound.csv"
    done = CliRunner().invoke(app, ["synth", "--speed", "9000", "--minutes", "3", "--ambient",
                                    ambient, "--seed", "900999", "--out", str(out), "--quiet"])
    assert done.exit_code == 0, done.output
    run = read_run(out)
    lo, hi = OPERATING_TEMPERATURE_C
    for reading in (run.ambient_C, run.coolant_C):
        assert lo <= reading.min() and reading.max() <= hi
        assert np.ptp(reading) > 0.0  # a reading still, noise and all, inside
