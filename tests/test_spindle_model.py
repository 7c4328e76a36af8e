"""SpindleModel and nominal boundary conditions."""

import numpy as np
import pytest

from twin.errors import InputError
from twin.fem import ThermalLoads
from twin.spindle import nominal_conditions


def test_model_parts(spindle_model):
    assert spindle_model.sensor_matrix.shape == (5, spindle_model.n_dofs)
    # interpolation weights of a point inside the mesh sum to one
    assert np.allclose(np.asarray(spindle_model.sensor_matrix.sum(axis=1)).ravel(), 1.0)
    assert spindle_model.probe_vectors.shape == (2, spindle_model.n_dofs)
    T = np.full(spindle_model.n_dofs, 31.0)
    assert np.allclose(spindle_model.sensor_matrix @ T, 31.0)


def test_uniform_warming_of_a_single_material_would_be_free_expansion(spindle_model):
    # sanity of the structural supports: the axial nose probe sees, for a uniform +10 K,
    # roughly α·ΔT times its distance from the mount (steel 12.2e-6; other materials
    # nearby differ by < 10 %): (450 − 380) mm · 12.2e-6 · 10 = 8.5 µm.
    dz = spindle_model.probe_vectors[0] @ np.full(spindle_model.n_dofs, 10.0) * 1e6
    assert dz == pytest.approx(8.5, rel=0.25)


def test_nominal_conditions_content(spindle_model):
    bc = nominal_conditions(spindle_model, 9000.0, 25.3)
    loads = bc.to_thermal_loads()
    assert isinstance(loads, ThermalLoads)
    assert set(loads.contact_resistance) == {"contact_front", "contact_rear"}
    for region in ("front_inner_ring", "front_rolling_band", "front_outer_ring"):
        assert loads.sources[region] == bc.H_front
    assert set(loads.convection) == set(spindle_model.mesh.boundaries) - {"axis"}
    # heat in W: sources × volumes, checked against the FEM's own volumes
    total = sum(q * spindle_model.thermal.volume(r) for r, q in loads.sources.items())
    assert total == pytest.approx(sum(bc.heat_W().values()), rel=1e-9)
    assert 1e-5 < bc.R_front < 1e-3 and 1e-5 < bc.R_rear < 1e-3


def test_overrides_replace_exactly_the_four_values(spindle_model):
    bc = nominal_conditions(spindle_model, 9000.0, 25.3)
    base = bc.to_thermal_loads()
    over = bc.to_thermal_loads(H_front=2.0e6, R_rear=3e-4)
    assert over.sources["front_outer_ring"] == 2.0e6
    assert over.sources["rear_outer_ring"] == base.sources["rear_outer_ring"]
    assert over.contact_resistance["contact_rear"] == 3e-4
    assert over.contact_resistance["contact_front"] == base.contact_resistance["contact_front"]
    assert over.convection == base.convection
    with pytest.raises(ValueError, match="R_front"):
        bc.to_thermal_loads(R_front=0.0)
    with pytest.raises(ValueError, match="H_rear"):
        bc.to_thermal_loads(H_rear=float("nan"))


def test_bearing_temperature_feedback(spindle_model):
    cold = nominal_conditions(spindle_model, 9000.0, 25.3)
    warm = nominal_conditions(spindle_model, 9000.0, 25.3, T_bearings_C=40.0)
    assert warm.H_front < cold.H_front  # the oil thins
    tight = nominal_conditions(spindle_model, 9000.0, 25.3, T_bearings_C=40.0, T_sleeves_C=30.0)
    loose = nominal_conditions(spindle_model, 9000.0, 25.3, T_bearings_C=30.0, T_sleeves_C=40.0)
    assert tight.R_front < warm.R_front < loose.R_front  # Eq. 5


@pytest.mark.parametrize(("speed", "field"), [(-1.0, "speed_rpm"), (15001.0, "speed_rpm"),
                                              (float("nan"), "speed_rpm")])
def test_impossible_operating_points(spindle_model, speed, field):
    with pytest.raises(InputError, match=field):
        nominal_conditions(spindle_model, speed, 25.0)


def test_bad_ambient(spindle_model):
    with pytest.raises(InputError, match="ambient_C"):
        nominal_conditions(spindle_model, 1000.0, 500.0)


def test_loads_kept_between_steps_give_the_bits_a_fresh_model_gives(spindle_model):
    """The thermal problem keeps a few film-load vectors and heat-balance film sums between
    load sets (twin.fem.thermal) and the model its spec's bearing constants
    (SpindleModel.constants): after other load sets, a step and its heat balance under a
    load set are what a model that never saw another gives, to the bit; a load set that
    differs from a kept one only in a bulk temperature or a film is not served from it."""
    from dataclasses import replace

    from twin.spindle import SpindleModel
    from twin.spindle.conditions import bearing_values_at

    def step(model, bc):  # noqa: ANN001, ANN202
        stepper = model.thermal.transient(bc.to_thermal_loads(), dt=2.0, theta=1.0)
        T0 = np.full(model.n_dofs, 31.0)
        T1 = stepper.step(T0)
        return T1, stepper.energy_balance(T0, T1)

    a = nominal_conditions(spindle_model, 9000.0, 25.0)
    a = a.with_values(**bearing_values_at(spindle_model, 9000.0, [33.0, 31.0, 30.0, 29.0]))
    warmer = replace(a, convection={k: (h, t + 2.0) for k, (h, t) in a.convection.items()})
    filmier = a.scaled({"film_coolant": 1.2})
    cases = (a, warmer, filmier, a)
    seen = [step(spindle_model, bc) for bc in cases]
    for i in (0, 1, 2):  # each against a model that solves that load set first
        fresh = step(SpindleModel.load(), cases[i])
        for got in (seen[i], seen[3]) if i == 0 else (seen[i],):
            np.testing.assert_array_equal(got[0], fresh[0])
            assert got[1] == fresh[1]


def test_film_coefficients_kept_per_operating_point_are_a_fresh_evaluation(spindle_model):
    """SpecConstants keeps the film coefficients of each (speed, film ambient) it was asked
    for: after others, every operating point's films are those of a spec evaluated afresh
    (a bare SpindleSpec: new constants each call), and a new speed or film ambient after a
    kept one is evaluated, not served from it."""
    from twin.spindle.conditions import SpecConstants

    model = type(spindle_model).load()  # constants of its own: no earlier test's films
    points = ((9000.0, 25.0, 25.0), (14000.0, 25.0, 25.0), (9000.0, 25.0, 35.0),
              (0.0, 25.0, 25.0), (9000.0, 30.0, 25.0), (9000.0, 25.0, 25.0))
    got = [nominal_conditions(model, s, a, film_ambient_C=f).convection for s, a, f in points]
    want = [nominal_conditions(model.spec, s, a, film_ambient_C=f).convection
            for s, a, f in points]
    assert got == want
    assert got[1] != got[0] and got[2] != got[0] and got[3] != got[0]  # each one's own films
    assert got[4] != got[0] and {k: h for k, (h, _) in got[4].items()} == \
        {k: h for k, (h, _) in got[0].items()}  # the sink moves, the films stay
    assert got[5] == got[0]
    assert len(model.constants.films) == 4  # kept: the four (speed, film ambient) points
    assert not SpecConstants.of(model.spec).films  # another spec's constants: their own
