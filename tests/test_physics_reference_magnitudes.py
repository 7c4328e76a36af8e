"""REFERENCE.md magnitudes from our physics functions, each within a stated factor.

The §2 numbers belong to a different machine (a grinding spindle at 3000 rpm) and §1's
to the BPNN twin's spindle at 9000 rpm; our reference spindle is a ~15 kW, 15000 rpm
design.  So agreement is expected in magnitude only; the factor allowed for each quantity
and the reason are stated next to it.  Ours come from `nominal_conditions` on the bundled
spindle_spec (cold start: bearings at ambient).
"""

import pytest

from twin.physics import coolant_h, motor_heat_split_W, motor_loss_W
from twin.spindle import nominal_conditions


@pytest.fixture(scope="module")
def bc3000(spindle_spec):
    return nominal_conditions(spindle_spec, 3000.0, 20.0)


def within(value, reference, factor):
    return reference / factor <= value <= reference * factor


def test_front_bearing_heat_matches_bpnn_paper_at_9000_rpm(spindle_spec):
    # §1 Table 1: H = 1.64e6 W/m³ at 9000 rpm, 25.34 °C.  Same formula, similar bearing
    # size; the difference is lubricant/f0 data we do not know.  Factor 1.5.
    for t_bearing in (25.34, 31.5):  # start and end temperature of the paper's T1
        bc = nominal_conditions(spindle_spec, 9000.0, 25.34, T_bearings_C=t_bearing)
        assert within(bc.H_front, 1.64e6, 1.5), bc.H_front


def test_front_bearing_heat_at_3000_rpm(bc3000):
    # §2: 9.824e4 W/m³ at 3000 rpm.  The two papers disagree with each other by ~3x after
    # Palmgren's speed scaling (n^(5/3): 1.64e6 at 9000 → 2.6e5 at 3000); ours sits on
    # the §1 side.  Factor 6.  (§2's rear value, 8x below its front, reflects a
    # different rear bearing; ours has two similar bearings, so it is not compared.)
    assert within(bc3000.H_front, 9.824e4, 6.0), bc3000.H_front


def test_motor_heat_density(spindle_spec, bc3000):
    # §2 densities are a motor at its rated power at 3000 rpm.  Ours at 3000 rpm is in the
    # constant-torque range (1/4 of rated power), so compare our rated-power loss over our
    # rotor and stator volumes: factor 3 (motor size and efficiency differ).
    m = spindle_spec.motor
    split = motor_heat_split_W(motor_loss_W(m.base_speed_rpm, rated_power_W=m.rated_power_W,
                                            base_speed_rpm=m.base_speed_rpm, load_fraction=1.0))
    rotor = split["rotor"] / spindle_spec.region_volume_m3(m.rotor)
    stator = split["stator"] / spindle_spec.region_volume_m3(m.stator)
    assert within(rotor, 1.279e6, 3.0), rotor
    assert within(stator, 8.633e5, 3.0), stator
    # the 1/3 : 2/3 split over the volumes gives the same rotor/stator ratio: factor 1.2
    ratio = bc3000.motor_heat[m.rotor] / bc3000.motor_heat[m.stator]
    assert within(ratio, 1.279e6 / 8.633e5, 1.2), ratio


@pytest.mark.parametrize(
    ("boundary", "reference"),
    [
        ("rotor_end_front", 68.42),
        ("rotor_end_rear", 61.28),
        ("nose_outer", 133.2),  # "rotor head–air"
        ("housing_outer", 9.7),  # "shell–air"
        ("air_gap_rotor", 138.6),
    ],
)
def test_film_coefficients_at_3000_rpm(bc3000, boundary, reference):
    # Same correlations family, similar diameters and speed: factor 2.
    h, _ = bc3000.convection[boundary]
    assert within(h, reference, 2.0), (boundary, h)


def test_stator_coolant_coefficient(spindle_spec, bc3000):
    # §2 quotes 400.51 W/m²K for stator–coolant.  That is a laminar-flow magnitude: our
    # channel in laminar flow gives 229 (factor 2).  Our nominal 4 L/min is turbulent
    # (Re ≈ 1e4) and gives ~5000 W/m²K, i.e. 12x the quoted value: the reference spindle
    # is cooled much less intensely than ours.
    ch = spindle_spec.coolant_channels[0]
    laminar = coolant_h(0.3, ch.z_end_mm - ch.z_start_mm, ch.r_outer_mm - ch.r_inner_mm)
    assert within(laminar, 400.51, 2.0), laminar
    h, t_inf = bc3000.convection["coolant"]
    assert 5.0 < h / 400.51 < 20.0
    assert t_inf == 20.0  # coolant defaults to the ambient
