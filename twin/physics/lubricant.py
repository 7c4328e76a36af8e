"""Kinematic viscosity of a lubricating oil as a function of temperature.

Palmgren's viscous friction torque (REFERENCE.md §1, Eq. 1) depends on ν·n, so the bearing
heat falls as the bearing warms and its oil thins.  We use the Walther equation (the basis
of ASTM D341 viscosity-temperature charts):

    log10(log10(ν + 0.7)) = A − B·log10(T_K),

with A and B fixed by the two viscosities an oil grade is sold with (ν at 40 °C and at
100 °C, ISO 3448).  It is accurate to a few per cent for mineral oils between about 0 and
150 °C, which covers a running spindle.
"""

from __future__ import annotations

import math

_KELVIN = 273.15


def _walther_constants(nu40_mm2_s: float, nu100_mm2_s: float) -> tuple[float, float]:
    if not (nu40_mm2_s > nu100_mm2_s > 0.0):
        raise ValueError(
            f"viscosities must satisfy nu40 > nu100 > 0, got nu40={nu40_mm2_s}, "
            f"nu100={nu100_mm2_s} mm²/s"
        )
    y40 = math.log10(math.log10(nu40_mm2_s + 0.7))
    y100 = math.log10(math.log10(nu100_mm2_s + 0.7))
    x40 = math.log10(40.0 + _KELVIN)
    x100 = math.log10(100.0 + _KELVIN)
    slope_B = (y40 - y100) / (x100 - x40)
    return y40 + slope_B * x40, slope_B


def kinematic_viscosity_mm2_s(temperature_C: float, nu40_mm2_s: float, nu100_mm2_s: float) -> float:
    """Kinematic viscosity ν [mm²/s] of an oil at `temperature_C` (Walther / ASTM D341).

    `nu40_mm2_s`, `nu100_mm2_s`: the grade's viscosities at 40 °C and 100 °C (e.g. ISO VG
    10 spindle oil: 10 and about 2.6 mm²/s).  Exact at those two temperatures.
    """
    if not math.isfinite(temperature_C) or temperature_C <= -_KELVIN:
        raise ValueError(f"temperature_C must be a finite temperature, got {temperature_C}")
    a, b = _walther_constants(nu40_mm2_s, nu100_mm2_s)
    y = a - b * math.log10(temperature_C + _KELVIN)
    return 10.0 ** (10.0**y) - 0.7
