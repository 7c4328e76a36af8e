"""Open-loop runs: plausibility against the reference system, energy balance, CLI files."""

import csv
import json

import numpy as np
import pytest
from typer.testing import CliRunner

from twin.spindle import SpindleModel, simulate

BEARING_OR_ROTOR = {"rotor", "front_inner_ring", "front_rolling_band", "front_outer_ring",
                    "rear_inner_ring", "rear_rolling_band", "rear_outer_ring"}


@pytest.fixture(scope="module")
def runs(spindle_model):
    return {n: simulate(spindle_model, n, 30.0, 25.3) for n in (3000, 6000, 9000, 12000, 15000)}


def test_reference_operating_point_is_plausible(runs):
    # REFERENCE.md §1: 9000 rpm, 25.34 °C, 30 min → rotor hottest at 57.0 °C, 8.47 µm
    r = runs[9000]
    assert r.max_temperature_region in BEARING_OR_ROTOR
    assert 45.0 <= r.max_temperature_C <= 70.0
    assert 4.0 <= r.disp_z_um[-1] <= 15.0
    assert r.time_s[-1] == 1800.0 and np.allclose(np.diff(r.time_s), 4.0)
    # the housing surface stays near ambient, the rings are warmer than their sleeves
    t = r.sensors_C[-1]
    assert t[4] < min(t[:4])
    assert t[0] > t[1] and t[2] > t[3]


def test_temperatures_and_drift_grow_with_speed(runs):
    speeds = sorted(runs)
    final = np.array([runs[n].sensors_C[-1] for n in speeds])
    assert np.all(np.diff(final, axis=0) > 0), final
    drift = [runs[n].disp_z_um[-1] for n in speeds]
    assert np.all(np.diff(drift) > 0), drift
    # the motor power is constant above the base speed (12000 rpm): up to it the hottest
    # point also rises with speed
    tmax = [runs[n].max_temperature_C for n in speeds if n <= 12000]
    assert np.all(np.diff(tmax) > 0), tmax


def test_energy_balance_closes_every_step(runs, spindle_model):
    for r in runs.values():
        assert r.relative_residual.max() < 0.01
        # early on most heat is stored, later more leaves through the films
        assert r.stored_W[0] > r.heat_out_W[0]
        assert r.heat_out_W[-1] > r.heat_out_W[0]


def test_energy_balance_agrees_with_the_fem(spindle_model):
    # our per-step dot products vs twin.fem's energy_balance on the same step
    r = simulate(spindle_model, 9000.0, 1.0, 25.3, field_every_s=4.0)
    loads = r.conditions[0].to_thermal_loads()
    (_, T0), (_, T1) = r.fields[0], r.fields[1]
    eb = spindle_model.thermal.energy_balance(T0, T1, loads, 4.0)
    assert r.heat_in_W[0] == pytest.approx(eb["heat_in_W"], rel=1e-9)
    assert r.heat_out_W[0] == pytest.approx(eb["heat_out_W"], rel=1e-6, abs=1e-9)
    assert r.stored_W[0] == pytest.approx(eb["stored_W"], rel=1e-9)


def test_cold_start_hold_versus_feedback(spindle_model):
    held = simulate(spindle_model, 9000.0, 10.0, 25.3, update_every_s=None)
    fed = simulate(spindle_model, 9000.0, 10.0, 25.3)
    assert len(held.conditions) == 1 and len(fed.conditions) == 10 * 15  # every 4 s step
    # warm oil → less bearing heat → cooler outer ring than with the cold-start heat
    assert fed.sensors_C[-1, 0] < held.sensors_C[-1, 0]


def test_simulate_cli_writes_the_files(tmp_path):
    from twin.cli import app

    out = tmp_path / "run"
    result = CliRunner().invoke(app, ["simulate", "--speed", "6000", "--minutes", "3",
                                      "--ambient", "24", "--coolant", "22", "--out", str(out)])
    assert result.exit_code == 0, result.output
    names = sorted(p.name for p in out.iterdir())
    assert names == ["fields", "fields.pvd", "keypoints.csv", "summary.json"]
    rows = list(csv.DictReader(open(out / "keypoints.csv")))
    assert len(rows) == 3 * 15 + 1
    assert list(rows[0]) == ["time_s", "speed_rpm", "ambient_C", "T1_C", "T2_C", "T3_C",
                             "T4_C", "T5_C", "disp_z_um", "disp_r_um"]
    assert float(rows[0]["T1_C"]) == pytest.approx(24.0)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["coolant_C"] == 22.0
    assert summary["energy_balance"]["max_relative_residual"] < 0.01
    assert summary["max_temperature_at"]["region"]
    pvd = (out / "fields.pvd").read_text()
    vtus = sorted(p.name for p in (out / "fields").iterdir())
    assert len(vtus) == 4 and all(f"fields/{v}" in pvd for v in vtus)
    import meshio

    last = meshio.read(out / "fields" / vtus[-1])
    # the field files of simulate and replay share names and units (twin.io.vtk)
    assert {"temperature_C", "displacement_um", "von_mises_MPa"} <= set(last.point_data)
    assert last.point_data["temperature_C"].max() > 24.0
    # thermal stress of a few K of warming: MPa, far below the yield of steel (~400 MPa)
    assert 0.1 < last.point_data["von_mises_MPa"].max() < 400.0
    # the nose vertex's axial displacement is the nose drift of keypoints.csv (µm, from
    # the start of the run): the same probe point, the same convention
    nose = np.argmin(np.hypot(last.points[:, 0] - 0.025, last.points[:, 1] - 0.450))
    assert last.point_data["displacement_um"][nose, 1] == pytest.approx(
        float(rows[-1]["disp_z_um"]), abs=1e-5)
    assert not any(p.name.startswith(".") for p in out.rglob("*"))  # no temp files


def test_simulate_cli_rejects_bad_speed(tmp_path):
    from twin.cli import app

    for speed in ("-100", "20000"):
        result = CliRunner().invoke(app, ["simulate", "--speed", speed, "--minutes", "1",
                                          "--ambient", "24", "--out", str(tmp_path / "x")])
        assert result.exit_code == 2, result.output
        assert "speed_rpm" in result.output
    assert not (tmp_path / "x").exists()



def test_simulate_refuses_a_replay_output_folder(tmp_path):
    # `--out` given a replay's folder: the simulation's summary.json replaced the replay's
    # (every run's accuracy), its keypoints.csv and fields/ landed beside the run folders
    from twin.cli import app

    out = tmp_path / "replay"
    (out / "run1").mkdir(parents=True)
    (out / "run1" / "accuracy.json").write_text("{}")
    (out / "summary.json").write_text('{"runs": []}')
    result = CliRunner().invoke(app, ["simulate", "--speed", "9000", "--minutes", "1",
                                      "--ambient", "24", "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert result.output.strip() == (f"error: {out}, option '--out': is a twin replay output "
                                     "folder, whose summary.json this would replace: choose "
                                     "another --out")
    assert (out / "summary.json").read_text() == '{"runs": []}'
    assert sorted(p.name for p in out.iterdir()) == ["run1", "summary.json"]

def test_replay_refuses_a_simulate_output_folder(tmp_path):
    # the reverse: `twin replay --out` given a simulation's folder replaced its summary.json
    # and put run folders and a report beside its keypoints.csv
    from twin.cli import app

    out = tmp_path / "sim"
    out.mkdir()
    (out / "keypoints.csv").write_text("time_s\n")
    (out / "summary.json").write_text('{"speed_rpm": 9000}')
    result = CliRunner().invoke(app, ["replay", "--out", str(out), "--quiet"])
    assert result.exit_code == 2, result.output
    assert result.output.strip() == (f"error: {out}, option '--out': is a twin simulate output "
                                     "folder, whose summary.json this would replace: choose "
                                     "another --out")
    assert sorted(p.name for p in out.iterdir()) == ["keypoints.csv", "summary.json"]
    assert (out / "summary.json").read_text() == '{"speed_rpm": 9000}'


def test_p2_elements_agree_with_the_default_p1_run(spindle_model):
    # discretisation check: quadratic elements on the same mesh change the 10 min key
    # points by well under the sensors' accuracy
    p2 = SpindleModel.load(order=2)
    a = simulate(spindle_model, 9000.0, 10.0, 25.3)
    b = simulate(p2, 9000.0, 10.0, 25.3)
    assert np.abs(a.sensors_C[-1] - b.sensors_C[-1]).max() < 0.3
    assert b.disp_z_um[-1] == pytest.approx(a.disp_z_um[-1], rel=0.05)
    assert b.max_temperature_region in BEARING_OR_ROTOR


def test_simulate_again_into_a_folder_leaves_nothing_of_the_earlier_run(tmp_path, monkeypatch):
    # a 2-min run after a 3-min one left step_00045.vtu of the 3-min run in fields/; an
    # interrupted run left the earlier summary.json beside its own new files
    from twin.cli import app
    from twin.spindle import output

    out = tmp_path / "run"
    (tmp_path / "run").mkdir()
    (out / "notes.txt").write_text("mine")  # not simulate's: stays

    def simulate_cli(minutes):
        return CliRunner().invoke(app, ["simulate", "--speed", "6000", "--minutes", minutes,
                                        "--ambient", "24", "--out", str(out), "--quiet"])

    assert simulate_cli("3").exit_code == 0
    assert simulate_cli("2").exit_code == 0
    assert sorted(p.name for p in (out / "fields").iterdir()) == [
        "step_00000.vtu", "step_00015.vtu", "step_00030.vtu"]
    assert json.loads((out / "summary.json").read_text())["minutes"] == 2.0

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(output, "write_fields", interrupted)
    assert simulate_cli("1").exit_code == 130
    assert not (out / "summary.json").exists()  # no earlier run's summary that looks current
    assert (out / "notes.txt").read_text() == "mine"


def test_simulate_says_the_duration_it_ran(tmp_path):
    # whole 4 s steps: 0.1 min runs 2 steps (8 s), and the line said "0.1 min"
    from twin.cli import app

    out = tmp_path / "run"
    result = CliRunner().invoke(app, ["simulate", "--speed", "6000", "--minutes", "0.1",
                                      "--ambient", "24", "--field-every", "0", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert result.output.startswith(f"6000 rpm, {8 / 60:g} min: ")
    rows = list(csv.DictReader(open(out / "keypoints.csv")))
    assert [r["time_s"] for r in rows] == ["0", "4", "8"]


@pytest.mark.parametrize("speed", [12000.0, 13500.0, 15000.0])
def test_sensor_temperatures_are_continuous_after_a_cold_start(spindle_model, speed):
    # A real spindle's bearing heat follows the ring temperature smoothly.  With the loads
    # held for 60 s from the cold start (oil at ambient: too much heat) and then
    # re-evaluated at the ring's new temperature, T1 fell 1.8 K in the 4 s after the first
    # minute at 13 500 rpm, after rising 0.3 K in the 4 s before (T3 likewise), and jumped
    # again at 120 s.  No step may change a sensor by more than a few times the step before.
    r = simulate(spindle_model, speed, 3.0, 22.0)
    for i, name in ((0, "T1"), (2, "T3")):
        change = np.abs(np.diff(r.sensors_C[:, i]))
        jumps = np.flatnonzero(change[1:] > 3.0 * change[:-1] + 0.02) + 1
        assert jumps.size == 0, (name, r.time_s[jumps + 1], change[jumps], change[jumps - 1])
    # from a uniform start at ambient, at constant speed, the rings only warm up
    assert np.all(np.diff(r.sensors_C[:, [0, 2]], axis=0) > 0)


@pytest.mark.parametrize("every", ["inf", "1e300"])
def test_simulate_field_interval_past_the_end_keeps_start_and_end(tmp_path, every):
    # --field-every inf passed typer's x >= 0 bound and ended in an internal error
    # (OverflowError converting the step count); any interval past the end keeps the
    # start and end fields, as --field-every 0 does
    from twin.cli import app

    out = tmp_path / "run"
    result = CliRunner().invoke(app, ["simulate", "--speed", "6000", "--minutes", "0.2",
                                      "--ambient", "24", "--field-every", every,
                                      "--out", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in (out / "fields").iterdir()) == ["step_00000.vtu",
                                                                   "step_00003.vtu"]
