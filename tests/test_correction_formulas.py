"""The analytic corrections (Eq. 2, 3, 5, 6) against hand-worked numbers and the paper's Table 1."""

import math

import numpy as np
import pytest

from twin.correction.formulas import (
    ContactFit,
    RatioGuard,
    RatioGuards,
    contact_drop_ratio,
    contact_pressure_factor,
    guarded_ratio,
    heat_first_correction,
    heat_second_correction,
    limit_to_nominal,
    resistance_first_correction,
    resistance_second_correction,
    total_rise_ratio,
    window_rise_ratio,
)

# the paper's Table 1, front bearing, 9000 rpm, ambient 25.34 °C, initial H 1.64e6 W/m³:
# (t s, measured °C, simulated °C, corrected H W/m³)
TABLE1 = [
    (60, 28.02, 27.66, 1.723e6),
    (120, 28.62, 28.92, 1.574e6),
    (1680, 31.37, 31.31, 1.667e6),
    (1740, 31.43, 31.25, 1.679e6),
    (1800, 31.49, 31.46, 1.642e6),
]
AMBIENT = 25.34
H0 = 1.64e6


def test_eq2_hand_worked_table1_row_60s():
    # (28.02 − 25.34)/(27.66 − 25.34) = 2.68/2.32 = 1.155172…; × 1.64e6 = 1.894483e6
    H1 = heat_first_correction(H0, 28.02, 27.66, AMBIENT)
    assert H1 == pytest.approx(1.64e6 * 2.68 / 2.32, rel=1e-12)
    assert H1 == pytest.approx(1.894483e6, rel=1e-6)


def test_eq3_hand_worked():
    # rises over a window of 0.60 K measured and 0.48 K simulated: C_H = 1.25
    C_H = window_rise_ratio(0.60, 0.48, RatioGuards(window=RatioGuard(0.1, (0.5, 2.0))))
    assert C_H == pytest.approx(1.25)
    assert heat_second_correction(1.8e6, C_H) == pytest.approx(2.25e6)


def test_table1_magnitudes_are_plausible():
    # Where the spindle approaches balance (last three rows) the corrections are small and
    # Eq. 2 on the paper's own temperatures lands within 1 % of its corrected heat.
    for t, measured, simulated, H_paper in TABLE1[2:]:
        H1 = heat_first_correction(H0, measured, simulated, AMBIENT)
        assert H1 == pytest.approx(H_paper, rel=0.01), t
    # the paper's corrections stay within about ±5 %; so does the ratio on settled rows
    for _t, measured, simulated, _H in TABLE1[2:]:
        assert abs(total_rise_ratio(measured, simulated, AMBIENT) - 1) < 0.05


def test_guards_neutral_for_tiny_negative_or_missing_denominators():
    g = RatioGuards()
    # first seconds: simulated rise 0.1 K < 0.5 K floor
    assert total_rise_ratio(25.5, 25.44, 25.34, g) == 1.0
    # cooling measured while the model heats: opposite signs carry no ratio
    assert window_rise_ratio(-0.3, 0.4, g) == 1.0
    # missing sensor
    assert contact_drop_ratio(np.nan, 0.5, g) == 1.0
    assert total_rise_ratio(30.0, np.inf, 25.0, g) == 1.0
    # two falls over a window: cooling faster than the twin means less heat, not 1.1×
    assert window_rise_ratio(-0.22, -0.2, g) == 1.0


def test_eq2_holds_below_ambient_where_the_ratio_runs_backwards():
    # a cold jacket holds the ring below ambient: measured −1.0 K, twin −0.6 K (the ring is
    # colder than the twin) gave 1.67, raising the heat; a twin rise below the floor or
    # negative carries no heat ratio
    g = RatioGuards()
    assert total_rise_ratio(24.0, 24.4, 25.0, g) == 1.0
    assert total_rise_ratio(22.6, 20.8, 25.0, g) == 1.0  # warmer than the twin: not 0.57
    assert heat_first_correction(1e6, 24.0, 24.4, 25.0, g) == 1e6
    # above ambient Eq. 2 is unchanged, also with the measured ring still below it
    assert total_rise_ratio(26.0, 27.0, 25.0, g) == pytest.approx(0.5)
    assert total_rise_ratio(24.9, 26.0, 25.0, g) == 1.0


def test_eq6_reads_two_negative_drops_as_a_resistance_ratio():
    # the drop is heat flux × resistance in either direction of the flux (a sleeve warmer
    # than its ring while the spindle cools): −0.55 against −0.50 K is still R 1.1× the twin's
    g = RatioGuards()
    assert contact_drop_ratio(-0.55, -0.50, g) == pytest.approx(1.1)
    assert contact_drop_ratio(0.55, -0.50, g) == 1.0


def test_guards_clip_to_limits():
    g = RatioGuards()
    assert total_rise_ratio(40.0, 26.0, 25.0, g) == g.total.limits[1]
    assert window_rise_ratio(0.01, 1.0, g) == g.window.limits[0]
    assert guarded_ratio(3.0, 1.0, RatioGuard(0.1, (0.5, 2.0))) == 2.0


def test_corrections_never_non_positive():
    g = RatioGuards()
    rng = np.random.default_rng(1)
    m = rng.normal(25, 10, 1000)
    s = rng.normal(25, 10, 1000)
    H = heat_second_correction(heat_first_correction(1e6, m, s, 25.0, g),
                               window_rise_ratio(m - 25, s - 25, g))
    assert np.all(H > 0)
    limited = limit_to_nominal(np.array([-1.0, 0.0, np.nan, 1e9]), 1e6, g)
    assert np.all(limited > 0)
    assert limited[2] == 1e6


def test_eq5_pressure_factor_hand_worked():
    fit = ContactFit(fit_radius_m=0.05, interference_m=5e-6, alpha_ring_per_K=13e-6,
                     alpha_sleeve_per_K=12e-6)
    # ring +6 K, sleeve +5 K: Δδ = 0.05·(78e-6 − 60e-6) = 0.9 µm; P'/P = 1.18
    f = contact_pressure_factor(6.0, 5.0, fit)
    assert f == pytest.approx(1.18 ** -0.68, rel=1e-12)
    assert f < 1  # tighter fit, lower resistance
    # uniform warming of equal materials changes nothing
    same = ContactFit(alpha_ring_per_K=12e-6, alpha_sleeve_per_K=12e-6)
    assert contact_pressure_factor(7.0, 7.0, same) == pytest.approx(1.0)
    # a fit that would open is held at the documented floor, not infinite
    g = RatioGuards()
    opening = contact_pressure_factor(0.0, 100.0, fit, g)
    assert opening == pytest.approx(g.min_relative_pressure ** -0.68)
    R1 = resistance_first_correction(1e-4, f, 1.0)
    assert R1 == pytest.approx(1e-4 * 1.18 ** -0.68)


def test_eq6_hand_worked():
    # ring-to-sleeve drop 0.55 K measured, 0.50 K simulated: C_C = 1.1
    C_C = contact_drop_ratio(0.55, 0.50)
    assert C_C == pytest.approx(1.1)
    assert resistance_second_correction(1e-4, C_C) == pytest.approx(1.1e-4)


def test_bad_guards_rejected():
    with pytest.raises(ValueError, match="value_limits"):
        RatioGuards(value_limits=(1.5, 2.0))
    with pytest.raises(ValueError, match="min_denominator"):
        RatioGuard(0.0, (0.5, 2.0))
    with pytest.raises(ValueError, match="limits"):
        RatioGuard(0.5, (1.2, 2.0))
    assert math.isclose(RatioGuards().value_limits[0], 0.2)
