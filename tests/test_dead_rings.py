"""A ring thermocouple dead for a whole run (T1 front, T3 rear): `bpnn`'s anchor reads the
bearing through its sleeve (`WindowFeatures.with_dead_rings_read_through_sleeves`), and that
must not leave the twin further off than the paper's ratio law, which holds the bearing's
heat and resistance without its ring.

The emulated runs have a cooling jacket below ambient, where the front sleeve sits: read as
the ring in Eq. 2 over ambient (the anchor until 2026-11-27), its negative rise inverted the
ratio and the front heat ran down to 0.2× nominal (suite 550055 run 8: bpnn 97.76 % against
the ratio law's 99.00 %), or stayed wherever it was once that rise fell within the guard's
floor.  The rear sleeve sits kelvins over ambient, where reading it is what the anchor gains
on the ratio law.
"""

from __future__ import annotations

import pytest

from twin.correction.methods import BpnnCorrection, RatioCorrection
from twin.correction.modelfile import load_model
from twin.loop.replay import direct_window_solver, replay_method
from twin.loop.runfiles import measured_reference, method_accuracy
from twin.plant.emulator import synthesize, write_synth
from twin.plant.profile import SpeedProfile
from twin.plant.scenario import parse_scenario
from twin.plant.timetable import StepTable
from twin.runs import read_run

from .test_rerun import BUNDLED_MODEL

AMBIENT_C = 24.0


def _scenario(stuck: str) -> str:
    """Front heat 0.75×, rear 1.5×, contacts 0.65× / 0.75× nominal, the coolant 1.8 K below
    ambient, 18 s thermocouples, `stuck` dead from the start; no other model-form error."""
    def table(name: str, factor: float) -> str:
        return f"[{name}]\ntime_s = [0.0]\nfactor = [{factor}]\n"

    return "".join([
        table("bearing_heat.front", 0.75), table("bearing_heat.rear", 1.5),
        table("contact_resistance.front", 0.65), table("contact_resistance.rear", 0.75),
        table("motor_heat", 1.0), table("film.coolant", 1.0), table("film.housing", 1.0),
        table("film.air_gap", 1.0), table("film.rotor", 1.0),
        f"[coolant]\ntime_s = [0.0]\ninlet_C = [{AMBIENT_C - 1.8}]\n",
        "[material]\nconductivity = 1.0\nexpansion = 1.0\n",
        "[sensors]\nlag_s = 18.0\nnoise_C = 0.03\nnoise_um = 0.1\nplacement_mm = 0.0\n",
        f'[faults]\nstuck = ["{stuck}"]\n',
    ])


def _temperature_accuracy(tmp_path, spindle_model, stuck: str) -> dict[str, float]:
    """ratio's and bpnn's temperature accuracy (%) on a 20-min run, 3500 → 6000 rpm at
    600 s, with `stuck` dead for the whole run (the quality check leaves it out)."""
    path = tmp_path / f"dead_{stuck}.csv"
    profile = SpeedProfile(StepTable([0.0, 600.0], [3500.0, 6000.0]))
    write_synth(synthesize(minutes=20, ambient_C=AMBIENT_C, seed=11, profile=profile,
                           scenario=parse_scenario(_scenario(stuck), "s.toml")), path)
    run = read_run(path)
    assert any(f["column"] == f"{stuck}_C" and f["kind"] == "stuck" for f in run.quality)
    model = spindle_model
    out = {}
    for method in (RatioCorrection(), BpnnCorrection(load_model(BUNDLED_MODEL))):
        r = replay_method(run, model, method, solver=direct_window_solver(model),
                          keep_fields=False)
        meas_T, meas_T0, meas_drift = measured_reference(run, r.time_s)
        out[method.name] = method_accuracy(r, meas_T, meas_T0, meas_drift)[
            "temperature_accuracy_pct"]
    return out


@pytest.mark.parametrize(("stuck", "margin"), [("T1", 0.1), ("T3", 0.5)])
def test_a_dead_ring_leaves_bpnn_at_least_as_close_as_the_ratio_law(tmp_path, spindle_model,
                                                                    stuck, margin):
    """Measured, temperature accuracy in %.  T1 dead (the front sleeve 0–1 K below ambient
    on the jacket): ratio 99.41, bpnn 99.72 (front heat 0.71–0.83× nominal from window 2
    on, the truth 0.75×); the sleeve read as the ring over ambient (before 2026-11-27)
    98.98, the front heat 1.32× from window 3 on, the sleeve's rise within the guard's
    0.5 K floor.  T3 dead: the ratio law holds the rear heat at nominal against a truth of
    1.5×: ratio 98.47, bpnn 99.50 (the sleeve over ambient 99.51).  Holding the dead ring's
    bearing as the ratio law does gives 99.41 and 98.54: the margins ask that the sleeve is
    read, and read right."""
    accuracy = _temperature_accuracy(tmp_path, spindle_model, stuck)
    assert accuracy["bpnn"] >= accuracy["ratio"] + margin, accuracy
