"""Model-form error and stops in the emulated spindle: each factor moves the truth the
way the physics says (issue 12), and a stop is a cool-down without heat."""

from __future__ import annotations

import numpy as np
import pytest

from twin.plant.emulator import synthesize, truth_model
from twin.plant.profile import SpeedProfile
from twin.plant.scenario import FactorTable, FilmGroups, MaterialFactors, Scenario, Sensors
from twin.plant.timetable import StepTable
from twin.plant.truth import FILM_GROUPS
from twin.spindle.spec import BOUNDARY_NAMES

AMBIENT = 25.0
MINUTES = 12


def _one(value: float) -> FactorTable:
    return FactorTable(time_s=[0.0], factor=[value])


def pinned(**changes) -> Scenario:  # noqa: ANN003
    """Every truth factor pinned at 1 (no drift, no noise, nominal sensor points)."""
    base = dict(
        bearing_heat={"front": _one(1.0), "rear": _one(1.0)},
        contact_resistance={"front": _one(1.0), "rear": _one(1.0)},
        coolant={"time_s": [0.0], "inlet_C": [AMBIENT]},
        ambient={"time_s": [0.0], "ambient_C": [AMBIENT]},
        motor_heat=_one(1.0),
        film=FilmGroups(**{g: _one(1.0) for g in FILM_GROUPS}),
        material=MaterialFactors(conductivity=1.0, expansion=1.0),
        sensors=Sensors(noise_C=0.0, noise_um=0.0, lag_s=0.0, placement_mm=0.0),
    )
    base.update(changes)
    return Scenario(**base)


@pytest.fixture(scope="module")
def nominal_truth():
    """The truth's nominal spindle (the default scenario's mesh), built once for the module."""
    from twin.spindle import SpindleModel

    return SpindleModel.load(size_factor=Scenario().model.size_factor)


@pytest.fixture(scope="module")
def truth_of(nominal_truth):
    def run(scenario: Scenario, speed_rpm: float = 9000.0, profile=None):  # noqa: ANN001, ANN202
        kwargs = {"profile": profile} if profile is not None else {"speed_rpm": speed_rpm}
        return synthesize(minutes=MINUTES, ambient_C=AMBIENT, seed=7, scenario=scenario,
                          model=nominal_truth, **kwargs)

    return run


@pytest.fixture(scope="module")
def reference(truth_of):
    return truth_of(pinned())


def region_spread_C(run, nominal) -> float:  # noqa: ANN001
    """max − min of the final truth field over the shaft's dofs, K."""
    region = "shaft"
    model = truth_model(nominal, run.extra["tables"].form)
    cells = model.mesh.region(region)
    dofs = np.unique(model.thermal.basis.element_dofs[:, cells])
    T = run.extra["truth_run"].final_field_C[dofs]
    return float(T.max() - T.min())


def test_film_groups_cover_every_convective_boundary():
    grouped = [b for names in FILM_GROUPS.values() for b in names]
    assert sorted(grouped) == sorted(b for b in BOUNDARY_NAMES if b != "axis")


def test_more_motor_heat_raises_T5_and_the_drift(reference, truth_of):
    hot = truth_of(pinned(motor_heat=_one(1.3)))
    T5 = hot.truth["T5_true_C"][-1] - reference.truth["T5_true_C"][-1]
    drift = hot.truth["disp_z_true_um"][-1] - reference.truth["disp_z_true_um"][-1]
    assert T5 > 0.02 and drift > 0.1
    # and the heat really went in: 30 % more motor loss
    q_ref = reference.extra["truth_run"].heat_in_W
    q_hot = hot.extra["truth_run"].heat_in_W
    assert np.all(q_hot > q_ref)
    assert hot.truth["factor_motor"][0] == pytest.approx(1.3)


def housing_film(factor: float) -> FilmGroups:
    return FilmGroups(**{**{g: _one(1.0) for g in FILM_GROUPS}, "housing": _one(factor)})


def test_weaker_housing_film_raises_T5(reference, truth_of):
    # The housing sits on the coolant jacket, so its surface film (natural convection and
    # radiation, ~10 W/m²K) moves T5 by thousandths of a kelvin in a short run: small, but
    # a million times the solver's precision, and ordered with the film.
    T5 = [truth_of(pinned(film=housing_film(f))).truth["T5_true_C"][-1] for f in (0.6, 1.4)]
    T5_ref = reference.truth["T5_true_C"][-1]
    assert T5[0] > T5_ref + 5e-4 > T5_ref > T5[1] + 5e-4


def test_weaker_coolant_film_heats_the_stator_side(reference, truth_of, nominal_truth):
    weak = truth_of(pinned(film=FilmGroups(**{**{g: _one(1.0) for g in FILM_GROUPS},
                                              "coolant": _one(0.6)})))
    assert weak.truth["T5_true_C"][-1] > reference.truth["T5_true_C"][-1] + 0.01
    def stator_C(run) -> float:  # noqa: ANN001
        field = run.extra["truth_run"].final_field_C
        return nominal_truth.region_mean_C(field)["stator"]

    assert stator_C(weak) > stator_C(reference) + 0.1


def test_lower_conductivity_widens_ring_sleeve_and_shaft_gradients(reference, truth_of,
                                                                  nominal_truth):
    poor = truth_of(pinned(material=MaterialFactors(conductivity=0.9, expansion=1.0)))
    drop = {name: run.truth["T1_true_C"][-1] - run.truth["T2_true_C"][-1]
            for name, run in (("ref", reference), ("poor", poor))}
    assert drop["poor"] > drop["ref"] > 0.0
    assert region_spread_C(poor, nominal_truth) > region_spread_C(reference, nominal_truth)
    # Eq. 4: the contact resistance scales with 1/k
    R0 = {n: r.truth["R_front_nominal"][0] for n, r in (("ref", reference), ("poor", poor))}
    np.testing.assert_allclose(R0["poor"] / R0["ref"], 1 / 0.9, rtol=1e-6)


def test_larger_expansion_scales_the_drift(reference, truth_of):
    wide = truth_of(pinned(material=MaterialFactors(conductivity=1.0, expansion=1.05)))
    # same temperatures up to the (small) Eq. 5 change of the fit's resistance;
    # linear thermo-elasticity: u ∝ α
    ratio = wide.truth["disp_z_true_um"][-1] / reference.truth["disp_z_true_um"][-1]
    assert ratio == pytest.approx(1.05, rel=0.01)


def test_placement_moves_sensors_inside_the_solid(reference, truth_of, nominal_truth):
    moved = truth_of(pinned(sensors=Sensors(noise_C=0.0, noise_um=0.0, lag_s=0.0,
                                            placement_mm=3.0)))
    offsets = moved.extra["tables"].form.sensor_offsets_mm
    spec = nominal_truth.spec
    assert set(offsets) == {"T1", "T2", "T3", "T4", "T5"}
    for name, (dr, dz) in offsets.items():
        assert 0.0 < np.hypot(dr, dz) <= 3.0
        p = spec.sensors[name]
        assert spec.inside_body(p.r_mm + dr, p.z_mm + dz)
    differs = [abs(moved.truth[f"T{j}_true_C"][-1] - reference.truth[f"T{j}_true_C"][-1])
               for j in range(1, 6)]
    assert max(differs) > 0.01
    # the same seed places the sensors the same way
    again = truth_of(pinned(sensors=Sensors(noise_C=0.0, noise_um=0.0, lag_s=0.0,
                                            placement_mm=3.0)))
    assert again.extra["tables"].form.sensor_offsets_mm == offsets


def test_default_truth_carries_model_form_error(nominal_truth):
    run = synthesize(speed_rpm=9000, minutes=3, ambient_C=AMBIENT, seed=11, model=nominal_truth)
    form = run.extra["tables"].form
    assert 0.85 <= float(form.motor_heat(0.0)) <= 1.15
    assert all(0.75 <= float(form.film[g](0.0)) <= 1.25 for g in FILM_GROUPS)
    assert 0.95 <= form.conductivity <= 1.05 and 0.97 <= form.expansion <= 1.03
    assert float(form.motor_heat(0.0)) != 1.0 and form.conductivity != 1.0
    other = synthesize(speed_rpm=9000, minutes=3, ambient_C=AMBIENT, seed=12,
                       model=nominal_truth)
    assert other.extra["tables"].form.conductivity != form.conductivity


def test_a_stop_has_no_heat_and_cools_down(truth_of):
    profile = SpeedProfile(StepTable([0.0, 360.0], [9000.0, 0.0]))
    run = truth_of(pinned(), profile=profile)
    truth = run.extra["truth_run"]
    t = truth.time_s[:-1]
    stopped = t >= 360.0
    assert np.all(truth.heat_in_W[~stopped] > 0)
    np.testing.assert_array_equal(truth.heat_in_W[stopped], 0.0)
    loads = run.truth
    at_stop = run.columns["time_s"] >= 360.0
    for name in ("H_front", "H_rear", "H_front_nominal", "H_rear_nominal"):
        np.testing.assert_array_equal(loads[name][at_stop], 0.0)
    for name in ("factor_H_front", "factor_R_rear", "factor_motor"):
        assert np.all(np.isfinite(loads[name]))
    # the bearing rings cool once the heat is off (after the hot rotor's heat has spread)
    T1 = truth.sensors_C[:, 0]
    late = truth.time_s >= 480.0
    assert np.all(np.diff(T1[late]) < 0)
    assert T1[-1] < T1[truth.time_s == 360.0][0]
    assert run.max_relative_residual < 1e-8


def test_calibration_offsets_shift_the_readings_not_the_metal(truth_of):
    """An offset is added to its channel's every reading, noise and all, and to nothing
    else: the truth file keeps the metal's temperature and records the offset."""
    noisy = Sensors(noise_C=0.05, noise_um=0.1, lag_s=8.0, placement_mm=0.0)
    plain = truth_of(pinned(sensors=noisy))
    offsets = {"T2": 0.25, "T5": -0.4, "coolant": -0.2}
    shifted = truth_of(pinned(sensors=noisy.model_copy(update={"offset_C": Sensors(
        offset_C=offsets).offset_C})))
    for column, values in plain.columns.items():
        offset = offsets.get(column.removesuffix("_C"), 0.0) if column != "time_s" else 0.0
        np.testing.assert_allclose(shifted.columns[column] - values, offset, atol=1e-12,
                                   err_msg=column)
    for column, values in plain.truth.items():
        np.testing.assert_array_equal(shifted.truth[column], values)
    recorded = shifted.extra["truth_metadata"]
    assert (recorded["T2_calibration_offset_C"], recorded["T5_calibration_offset_C"],
            recorded["coolant_calibration_offset_C"]) == ("0.25", "-0.4", "-0.2")
    assert not any("calibration" in key for key in plain.extra["truth_metadata"])
