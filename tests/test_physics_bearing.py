"""Palmgren bearing heat, oil viscosity and motor losses against hand calculations."""

import math

import pytest

from twin.physics import (
    bearing_heat_palmgren,
    bearing_heat_W,
    equivalent_dynamic_load_N,
    friction_torque_Nmm,
    kinematic_viscosity_mm2_s,
    load_factor_f1,
    motor_heat_split_W,
    motor_loss_W,
)


def test_viscosity_is_exact_at_the_grade_points_and_thins_with_heat():
    assert kinematic_viscosity_mm2_s(40.0, 32.0, 5.4) == pytest.approx(32.0, rel=1e-12)
    assert kinematic_viscosity_mm2_s(100.0, 32.0, 5.4) == pytest.approx(5.4, rel=1e-12)
    temps = [0.0, 20.0, 40.0, 60.0, 100.0]
    nus = [kinematic_viscosity_mm2_s(t, 10.0, 2.6) for t in temps]
    assert all(a > b for a, b in zip(nus, nus[1:], strict=False))
    # ISO VG 10 spindle oil at 25 °C: handbook viscosity-temperature charts give ~16–18
    assert 15.0 < kinematic_viscosity_mm2_s(25.0, 10.0, 2.6) < 19.0


def test_viscosity_rejects_impossible_grades():
    with pytest.raises(ValueError, match="nu40"):
        kinematic_viscosity_mm2_s(40.0, 5.0, 10.0)


def test_friction_torque_hand_calculation():
    # n = 9000 rpm, ν = 12 mm²/s → ν·n = 108000, (ν·n)^(2/3) = 2267.9 (hand: e^(2/3·ln 108000))
    # M1 = 1e-7 · 1.0 · 2267.9 · 90³ = 165.33 N·mm;  M2 = 3e-4 · 1000 N · 90 mm = 27 N·mm
    m = friction_torque_Nmm(9000.0, 12.0, 1.0, 90.0, 3e-4, 1000.0)
    assert m == pytest.approx(165.33 + 27.0, rel=2e-4)


def test_friction_torque_low_speed_branch_is_continuous_enough():
    # below ν·n = 2000 the viscous torque is 160e-7·f0·Dm³; at the switch
    # 2000^(2/3) = 158.74, so the two branches differ by under 1 %
    below = friction_torque_Nmm(199.0, 10.0, 2.0, 50.0, 0.0, 0.0)
    assert below == pytest.approx(160e-7 * 2.0 * 50.0**3, rel=1e-12)
    above = friction_torque_Nmm(200.0, 10.0, 2.0, 50.0, 0.0, 0.0)
    assert above == pytest.approx(below, rel=0.01)


def test_palmgren_volumetric_heat_eq1():
    # H = 1.047e-4 · n · M / V: 3000 rpm, 100 N·mm, 1e-4 m³ → 3.1416e5 W/m³ (ω·M / V)
    h = bearing_heat_palmgren(3000.0, 100.0, 1e-4)
    assert h == pytest.approx(2 * math.pi * 3000 / 60 * 0.1 / 1e-4, rel=1e-12)
    assert h == pytest.approx(1.047e-4 * 3000 * 100 / 1e-4, rel=5e-4)


def test_load_factors():
    # f1 = 0.0012·(P0/C0)^0.33; P0/C0 = 0.01 → 0.0012 · 0.2188 = 2.626e-4
    assert load_factor_f1(340.0, 34000.0) == pytest.approx(0.0012 * 0.01**0.33, rel=1e-12)
    # 15°: cot = 3.732; 0.9·800·3.732 = 2687 N (> Fa) ; with Fr = 1000 N: 2587 N
    assert equivalent_dynamic_load_N(800.0, 0.0, 15.0) == pytest.approx(2687.1, rel=1e-4)
    assert equivalent_dynamic_load_N(800.0, 1000.0, 15.0) == pytest.approx(2587.1, rel=1e-4)
    # steep contact angle: the axial load itself dominates
    assert equivalent_dynamic_load_N(800.0, 0.0, 60.0) == 800.0


def test_bearing_heat_falls_as_the_oil_warms_and_grows_with_speed():
    kw = dict(pitch_diameter_mm=90.0, f0=1.0, nu40_mm2_s=10.0, nu100_mm2_s=2.6,
              preload_N=800.0, radial_load_N=0.0, contact_angle_deg=15.0,
              static_load_rating_N=34000.0)
    assert bearing_heat_W(9000, 25.0, **kw) > bearing_heat_W(9000, 40.0, **kw)
    speeds = [1000, 3000, 6000, 9000, 12000, 15000]
    heats = [bearing_heat_W(n, 30.0, **kw) for n in speeds]
    assert all(a < b for a, b in zip(heats, heats[1:], strict=False))
    assert bearing_heat_W(0.0, 30.0, **kw) == 0.0


def test_motor_loss_hand_calculation_and_split():
    # 15 kW at full load above base speed: 15000 · 0.1 · 0.88 = 1320 W
    q = motor_loss_W(12000, rated_power_W=15000, base_speed_rpm=9000, load_fraction=1.0)
    assert q == pytest.approx(1320.0, rel=1e-12)
    # constant torque below base speed: half the speed, half the power
    q_half = motor_loss_W(4500, rated_power_W=15000, base_speed_rpm=9000, load_fraction=1.0)
    assert q_half == pytest.approx(660.0, rel=1e-12)
    split = motor_heat_split_W(1320.0)
    assert split["rotor"] == pytest.approx(440.0)
    assert split["stator"] == pytest.approx(880.0)
    with pytest.raises(ValueError, match="efficiency"):
        motor_loss_W(1000, rated_power_W=1, base_speed_rpm=1, load_fraction=1, efficiency=0)
