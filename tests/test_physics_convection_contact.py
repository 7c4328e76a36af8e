"""Film coefficients and contact resistance against hand calculations."""

import math

import pytest

from twin.physics import (
    air_gap_h,
    contact_resistance_initial,
    contact_resistance_thermal,
    coolant_h,
    fit_pressure_MPa,
    natural_convection_h,
    radiation_h,
    rotating_cylinder_h,
    rotating_disk_h,
)
from twin.physics.contact import harmonic_mean, thermal_interference_um


def test_coolant_dittus_boelter_reference_example():
    # REFERENCE.md §3: 8 mm channel, 5 L/min water. Square 8x8 mm: D = 8 mm,
    # u = 8.333e-5 / 64e-6 = 1.302 m/s, Re = 1.302·0.008/0.66e-6 = 15783,
    # Nu = 0.023 · 15783^0.8 · 7^0.4 = 0.023 · 2282.6 · 2.178 = 114.4, h = 114.4·0.6/0.008
    assert coolant_h(5.0, 8.0, 8.0) == pytest.approx(8578.0, rel=1e-3)


def test_coolant_laminar_value_and_continuity():
    # 12 x 8 mm: D = 4·96/40 = 9.6 mm; laminar Nu = 3.66 → h = 3.66·0.6/0.0096 = 228.75
    assert coolant_h(0.2, 12.0, 8.0) == pytest.approx(228.75, rel=1e-12)
    # continuous across the transition band: no jump bigger than the flow step implies
    flows = [0.5 + 0.01 * i for i in range(700)]
    hs = [coolant_h(f, 12.0, 8.0) for f in flows]
    assert all(b >= a for a, b in zip(hs, hs[1:], strict=False))
    assert max(b - a for a, b in zip(hs, hs[1:], strict=False)) < 60.0


def test_natural_convection_hand_calculation():
    # vertical wall L = 0.2 m, Δt = 10 K, surface 30 °C → film 298.15 K
    # Gr = 9.81/298.15 · 0.008 · 10 / (1.48e-5)² = 1.2016e7, Ra = 0.71·Gr = 8.532e6 (laminar)
    # Nu = 0.59 · Ra^0.25 = 0.59 · 54.05 = 31.89, h = 31.89·0.0267/0.2 = 4.257
    h = natural_convection_h(10.0, 0.2, orientation="vertical", surface_C=30.0)
    assert h == pytest.approx(4.257, rel=2e-3)
    assert natural_convection_h(0.0, 0.2) == 0.0


def test_radiation_linearisation():
    # ε σ (Ts² + Ta²)(Ts + Ta) at 300/300 K = 4 ε σ T³ = 4·0.85·5.670e-8·2.7e7 = 5.205
    assert radiation_h(26.85, 26.85, 0.85) == pytest.approx(5.2053, rel=1e-3)


def test_air_gap_hand_calculation():
    # 9000 rpm, D = 0.11 m, δ = 0.5 mm: u = 51.84 m/s, Re = 51.84·5e-4/1.48e-5 = 1751.4
    # Nu = 0.23 · (1e-3/0.11)^0.25 · 1751.4^0.5 = 0.23 · 0.30878 · 41.85 = 2.9722
    # h = 2.9722 · 0.0267 / 5e-4 = 158.7
    assert air_gap_h(9000, 0.11, 5e-4) == pytest.approx(158.7, rel=1e-3)
    # standstill: conduction across the gap
    assert air_gap_h(0.0, 0.11, 5e-4) == pytest.approx(0.0267 / 5e-4)


def test_rotating_disk_laminar_is_radius_independent():
    # laminar: h = 0.36 λ sqrt(ω/ν), independent of R; 3000 rpm → 0.36·0.0267·4606.4 = 44.28
    assert rotating_disk_h(3000, 0.05) == pytest.approx(44.28, rel=1e-3)
    assert rotating_disk_h(3000, 0.03) == pytest.approx(rotating_disk_h(3000, 0.05), rel=1e-12)


def test_rotating_cylinder_hand_calculation():
    # 3000 rpm, D = 0.1 m: Re = 314.16·0.01/1.48e-5 = 212270,
    # Nu = 0.133 · 212270^(2/3) · 0.71^(1/3) = 0.133 · 3558.0 · 0.8921 = 422.2, h = 112.7
    assert rotating_cylinder_h(3000, 0.1) == pytest.approx(112.7, rel=2e-3)


def test_contact_resistance_eq4_hand_calculation():
    # r = 1 (µm), k = 40, P/E = 1 MPa / 200 GPa = 5e-6, (5e-6)^0.68 = 2.4848e-4
    # R = 1 / (40 · 10^5.6 · 2.4848e-4) = 1 / 3957.0 = 2.527e-4 m²K/W
    assert contact_resistance_initial(1.0, 40.0, 1.0, 200.0) == pytest.approx(2.527e-4, rel=1e-3)
    # the "about 1e-4 m²K/W" magnitude of REFERENCE.md for ground steel fits
    r = contact_resistance_initial(0.8, harmonic_mean(40.1, 49.8), 2.0, 207.0)
    assert 3e-5 < r < 3e-4


def test_lame_fit_pressure_limits():
    # solid shaft in an infinite plate, same E: P = E·δ/(2b)
    p = fit_pressure_MPa(5.0, 0.0, 50.0, 5e7, 200.0)
    assert p == pytest.approx(200e3 * 5e-3 / (2 * 50.0), rel=1e-6)
    assert fit_pressure_MPa(-2.0, 40.0, 50.0, 70.0, 200.0) == 0.0
    with pytest.raises(ValueError, match="radii"):
        fit_pressure_MPa(1.0, 50.0, 40.0, 70.0, 200.0)


def test_contact_resistance_eq5_interpretation():
    assert contact_resistance_thermal(1e-4, 2.0, 0.0) == pytest.approx(1e-4)
    # doubling the pressure lowers R by 2^-0.68 = 0.6242 (Eq. 4 re-evaluated)
    assert contact_resistance_thermal(1e-4, 2.0, 2.0) == pytest.approx(1e-4 * 2**-0.68)
    # an opening fit is floored at min_pressure_fraction·P0
    assert contact_resistance_thermal(1e-4, 2.0, -10.0, min_pressure_fraction=0.1) == (
        pytest.approx(1e-4 * 0.1**-0.68))
    # a ring hotter than its sleeve tightens the fit: b·(α_r Δt_r − α_s Δt_s)
    assert thermal_interference_um(55.0, 10.0, 0.0, 13.3e-6, 12.2e-6) == pytest.approx(7.315)
    assert thermal_interference_um(55.0, 0.0, 10.0, 13.3e-6, 12.2e-6) < 0


@pytest.mark.parametrize("value", [math.nan, -1.0])
def test_bad_arguments_name_the_argument(value):
    with pytest.raises(ValueError, match="speed_rpm"):
        air_gap_h(value, 0.1, 5e-4)
