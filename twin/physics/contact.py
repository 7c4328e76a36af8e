"""Thermal contact resistance between a bearing outer ring and its sleeve.

REFERENCE.md §1, Eq. 4 and Eq. 5 of the BPNN-twin paper.

Eq. 4 (initial value), read as   r / (R·k) = 10^5.6 · (P/E)^0.68,   i.e.

    R = r / (k · 10^5.6 · (P/E)^0.68)      [m²K/W]

Interpretation (the printed units are ambiguous, REFERENCE.md says so):
  * r is the combined RMS roughness of the two faces, √(r1² + r2²), entered as a number of
    micrometres.  Taken in metres R would be ~1e-10 m²K/W (no resistance at all); the
    micrometre reading gives ~1e-4 m²K/W, the magnitude measured for ground steel fits.
  * k is the harmonic mean 2·k1·k2/(k1 + k2) of the two conductivities (W/mK).
  * P/E is dimensionless: the contact pressure over the harmonic-mean modulus
    2·E1·E2/(E1 + E2), both in the same unit.

Eq. 5 (correction for thermal expansion; the printed equation is garbled).  We re-evaluate
Eq. 4 at the pressure the fit has when ring and sleeve are warm:

    P' = P0 + ΔP,   ΔP = (dP/dδ) · δ_th,   δ_th = b · (α_ring·Δt_ring − α_sleeve·Δt_sleeve)

with Δt measured from the assembly temperature, b the interface radius and dP/dδ the
Lamé stiffness of the shrink fit (`fit_pressure_MPa` per unit interference), so

    R' = R0 · (P'/P0)^(−0.68) = R0 · (1 + ΔP/P0)^(−0.68),

the "(1 + ΔP/P)^0.68-like form" of the paper.  A ring running hotter than its sleeve
tightens the fit and lowers R; a hotter sleeve loosens it.  P' is floored at
`min_pressure_fraction`·P0: a fit that opens does not give an infinite resistance (the
ring is still held by the preload and the oil film).
"""

from __future__ import annotations

import math

EQ4_CONSTANT = 10.0**5.6
EQ4_EXPONENT = 0.68


def _positive(name: str, value: float) -> None:
    if not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite positive number, got {value}")


def harmonic_mean(a: float, b: float) -> float:
    """2ab/(a + b): the effective conductivity or modulus of two bodies in contact."""
    _positive("a", a)
    _positive("b", b)
    return 2.0 * a * b / (a + b)


def contact_resistance_initial(roughness_um: float, conductivity_W_per_mK: float,
                               pressure_MPa: float, modulus_GPa: float) -> float:
    """Eq. 4: R = r / (k · 10^5.6 · (P/E)^0.68) in m²K/W (r as µm, see the module doc)."""
    _positive("roughness_um", roughness_um)
    _positive("conductivity_W_per_mK", conductivity_W_per_mK)
    _positive("pressure_MPa", pressure_MPa)
    _positive("modulus_GPa", modulus_GPa)
    ratio = pressure_MPa / (modulus_GPa * 1e3)
    return roughness_um / (conductivity_W_per_mK * EQ4_CONSTANT * ratio**EQ4_EXPONENT)


def fit_pressure_MPa(radial_interference_um: float, ring_inner_radius_mm: float,
                     interface_radius_mm: float, sleeve_outer_radius_mm: float,
                     modulus_GPa: float) -> float:
    """Lamé pressure of a ring (a..b) shrunk into a sleeve (b..c) of the same modulus.

    P = E·δ·(b² − a²)·(c² − b²) / (2·b³·(c² − a²)) with δ the radial interference (same
    Poisson ratio on both sides, so it cancels).  Negative δ (clearance) gives 0.
    """
    a, b, c = ring_inner_radius_mm, interface_radius_mm, sleeve_outer_radius_mm
    if not (0.0 <= a < b < c):
        raise ValueError(f"radii must satisfy 0 <= a < b < c, got a={a}, b={b}, c={c} mm")
    _positive("modulus_GPa", modulus_GPa)
    delta_mm = max(radial_interference_um, 0.0) * 1e-3
    e_MPa = modulus_GPa * 1e3
    return e_MPa * delta_mm * (b * b - a * a) * (c * c - b * b) / (2.0 * b**3 * (c * c - a * a))


def thermal_interference_um(interface_radius_mm: float, ring_rise_K: float,
                            sleeve_rise_K: float, ring_alpha_per_K: float,
                            sleeve_alpha_per_K: float) -> float:
    """Radial interference gained by the fit when ring and sleeve warm: b·(α_r·Δt_r − α_s·Δt_s)."""
    return interface_radius_mm * 1e3 * (ring_alpha_per_K * ring_rise_K
                                        - sleeve_alpha_per_K * sleeve_rise_K)


def contact_resistance_thermal(initial_resistance_m2K_W: float, initial_pressure_MPa: float,
                               pressure_change_MPa: float, *,
                               min_pressure_fraction: float = 0.05) -> float:
    """Eq. 5 as interpreted in the module doc: R' = R0 · (max(P0 + ΔP, f·P0)/P0)^(−0.68)."""
    _positive("initial_resistance_m2K_W", initial_resistance_m2K_W)
    _positive("initial_pressure_MPa", initial_pressure_MPa)
    if not math.isfinite(pressure_change_MPa):
        raise ValueError(f"pressure_change_MPa must be finite, got {pressure_change_MPa}")
    if not 0.0 < min_pressure_fraction <= 1.0:
        raise ValueError(f"min_pressure_fraction must be in (0, 1], got {min_pressure_fraction}")
    ratio = max(1.0 + pressure_change_MPa / initial_pressure_MPa, min_pressure_fraction)
    return initial_resistance_m2K_W * ratio ** (-EQ4_EXPONENT)
