"""Film coefficients h [W/m²K] for the spindle's convective surfaces.

REFERENCE.md §2 (air gap, coolant, housing) and §3 (natural-convection table, forced water
cooling); rotating surfaces use the classic correlations for a cylinder rotating in still
air (Kays & Bjorklund) and a free rotating disk (Cobb & Saunders).  Fluid properties default
to the values quoted in REFERENCE.md: air λ = 0.0267 W/mK, ν = 1.48e-5 m²/s, Pr = 0.71;
water λ = 0.6 W/mK, ν = 0.66e-6 m²/s, Pr = 7.
"""

from __future__ import annotations

import math

AIR_CONDUCTIVITY_W_per_mK = 0.0267
AIR_VISCOSITY_m2_s = 1.48e-5
AIR_PRANDTL = 0.71
WATER_CONDUCTIVITY_W_per_mK = 0.6
WATER_VISCOSITY_m2_s = 0.66e-6
WATER_PRANDTL = 7.0
GRAVITY_m_s2 = 9.81
STEFAN_BOLTZMANN = 5.670374e-8

# Channel flow: laminar below Re = 2300, fully turbulent (Dittus–Boelter) above 1e4.
_RE_LAMINAR = 2300.0
_RE_TURBULENT = 1.0e4
_NU_LAMINAR = 3.66  # fully developed laminar flow, constant wall temperature


def _positive(name: str, value: float) -> None:
    if not math.isfinite(value) or value <= 0.0:
        raise ValueError(f"{name} must be a finite positive number, got {value}")


def _non_negative(name: str, value: float) -> None:
    if not math.isfinite(value) or value < 0.0:
        raise ValueError(f"{name} must be a finite non-negative number, got {value}")


def coolant_h(flow_L_min: float, channel_width_mm: float, channel_height_mm: float, *,
              parallel_channels: int = 1,
              conductivity_W_per_mK: float = WATER_CONDUCTIVITY_W_per_mK,
              viscosity_m2_s: float = WATER_VISCOSITY_m2_s,
              prandtl: float = WATER_PRANDTL) -> float:
    """Forced convection in a rectangular coolant channel (REFERENCE.md §2, §3).

    D = 4A/X (hydraulic diameter), u = flow / (channels · A), Re = u·D/ν;
    Nu = 0.023·Re^0.8·Pr^0.4 (Dittus–Boelter, heated fluid) for Re ≥ 1e4, Nu = 3.66 for
    laminar flow (Re ≤ 2300) and a linear bridge in Re in between, so h is continuous in
    the flow rate; h = Nu·λ/D.
    """
    _non_negative("flow_L_min", flow_L_min)
    _positive("channel_width_mm", channel_width_mm)
    _positive("channel_height_mm", channel_height_mm)
    if parallel_channels < 1:
        raise ValueError(f"parallel_channels must be >= 1, got {parallel_channels}")
    area_m2 = channel_width_mm * channel_height_mm * 1e-6
    perimeter_m = 2.0 * (channel_width_mm + channel_height_mm) * 1e-3
    diameter_m = 4.0 * area_m2 / perimeter_m
    velocity_m_s = flow_L_min / 60.0 * 1e-3 / (parallel_channels * area_m2)
    reynolds = velocity_m_s * diameter_m / viscosity_m2_s
    nu_turbulent = 0.023 * max(reynolds, _RE_TURBULENT) ** 0.8 * prandtl**0.4
    if reynolds >= _RE_TURBULENT:
        nusselt = 0.023 * reynolds**0.8 * prandtl**0.4
    elif reynolds <= _RE_LAMINAR:
        nusselt = _NU_LAMINAR
    else:
        w = (reynolds - _RE_LAMINAR) / (_RE_TURBULENT - _RE_LAMINAR)
        nusselt = (1.0 - w) * _NU_LAMINAR + w * nu_turbulent
    return nusselt * conductivity_W_per_mK / diameter_m


# (C, n, upper Rayleigh limit) per orientation, REFERENCE.md §3; the horizontal cylinder
# (a spindle housing) follows Morgan's table.
_NATURAL_TABLE: dict[str, list[tuple[float, float, float]]] = {
    "vertical": [(0.59, 0.25, 1e9), (0.12, 1.0 / 3.0, math.inf)],
    "horizontal_up": [(0.54, 0.25, 1e7), (0.14, 1.0 / 3.0, math.inf)],
    "horizontal_down": [(0.27, 0.25, math.inf)],
    "horizontal_cylinder": [(0.48, 0.25, 1e7), (0.125, 1.0 / 3.0, math.inf)],
}


def natural_convection_h(delta_T_K: float, length_m: float, *, orientation: str = "vertical",
                         surface_C: float = 30.0,
                         conductivity_W_per_mK: float = AIR_CONDUCTIVITY_W_per_mK,
                         viscosity_m2_s: float = AIR_VISCOSITY_m2_s,
                         prandtl: float = AIR_PRANDTL) -> float:
    """Natural convection Nu = C·(Gr·Pr)^n, h = Nu·λ/L (REFERENCE.md §3).

    Gr = g·β·L³·Δt/ν² with β = 1/T_film (ideal gas; the film temperature is taken as the
    surface temperature minus Δt/2).  `orientation`: vertical, horizontal_up (hot face
    up), horizontal_down (hot face down) or horizontal_cylinder (L = diameter).
    """
    _non_negative("delta_T_K", delta_T_K)
    _positive("length_m", length_m)
    if orientation not in _NATURAL_TABLE:
        raise ValueError(
            f"orientation must be one of {sorted(_NATURAL_TABLE)}, got {orientation!r}"
        )
    if delta_T_K == 0.0:
        return 0.0
    film_K = surface_C - 0.5 * delta_T_K + 273.15
    grashof = GRAVITY_m_s2 / film_K * length_m**3 * delta_T_K / viscosity_m2_s**2
    rayleigh = grashof * prandtl
    for c, n, upper in _NATURAL_TABLE[orientation]:
        if rayleigh <= upper:
            return c * rayleigh**n * conductivity_W_per_mK / length_m
    raise AssertionError("unreachable: the last table row has no upper limit")


def radiation_h(surface_C: float, surroundings_C: float, emissivity: float) -> float:
    """Linearised radiation coefficient ε·σ·(Ts² + T∞²)·(Ts + T∞) in W/m²K.

    A painted housing (ε ≈ 0.8–0.9) loses about as much by radiation as by natural
    convection, so the housing's film coefficient adds both.
    """
    if not 0.0 <= emissivity <= 1.0:
        raise ValueError(f"emissivity must be in [0, 1], got {emissivity}")
    ts, ta = surface_C + 273.15, surroundings_C + 273.15
    return emissivity * STEFAN_BOLTZMANN * (ts**2 + ta**2) * (ts + ta)


def air_gap_h(speed_rpm: float, rotor_diameter_m: float, gap_m: float, *,
              conductivity_W_per_mK: float = AIR_CONDUCTIVITY_W_per_mK,
              viscosity_m2_s: float = AIR_VISCOSITY_m2_s) -> float:
    """Rotor–stator air gap (REFERENCE.md §2): Nu = 0.23·(2δ/D2)^0.25·Re^0.5.

    u = π·n·d/60 (rotor surface speed), Re = u·δ/ν, h = Nu·λ/δ (the gap width is the
    length scale of both Re and Nu).  Nu is floored at 1: at standstill the gap still
    conducts, h = λ/δ.
    """
    _non_negative("speed_rpm", speed_rpm)
    _positive("rotor_diameter_m", rotor_diameter_m)
    _positive("gap_m", gap_m)
    velocity = math.pi * speed_rpm * rotor_diameter_m / 60.0
    reynolds = velocity * gap_m / viscosity_m2_s
    nusselt = 0.23 * (2.0 * gap_m / rotor_diameter_m) ** 0.25 * reynolds**0.5
    return max(nusselt, 1.0) * conductivity_W_per_mK / gap_m


def rotating_cylinder_h(speed_rpm: float, diameter_m: float, *,
                        conductivity_W_per_mK: float = AIR_CONDUCTIVITY_W_per_mK,
                        viscosity_m2_s: float = AIR_VISCOSITY_m2_s,
                        prandtl: float = AIR_PRANDTL) -> float:
    """A cylinder rotating in still air (Kays & Bjorklund): Nu = 0.133·Re^(2/3)·Pr^(1/3).

    Re = ω·D²/ν, h = Nu·λ/D.  Used for the shaft surfaces and the spindle nose
    ("rotor head–air" in REFERENCE.md §2).
    """
    _non_negative("speed_rpm", speed_rpm)
    _positive("diameter_m", diameter_m)
    omega = 2.0 * math.pi * speed_rpm / 60.0
    reynolds = omega * diameter_m**2 / viscosity_m2_s
    nusselt = 0.133 * reynolds ** (2.0 / 3.0) * prandtl ** (1.0 / 3.0)
    return nusselt * conductivity_W_per_mK / diameter_m


def rotating_disk_h(speed_rpm: float, radius_m: float, *,
                    conductivity_W_per_mK: float = AIR_CONDUCTIVITY_W_per_mK,
                    viscosity_m2_s: float = AIR_VISCOSITY_m2_s) -> float:
    """Mean h of a free disk rotating in still air (Cobb & Saunders), W/m²K.

    Re = ω·R²/ν; laminar (Re < 2.4e5) Nu = 0.36·Re^0.5, turbulent Nu = 0.015·Re^0.8;
    h = Nu·λ/R.  Used for the rotor's end faces and the shaft's end faces.
    """
    _non_negative("speed_rpm", speed_rpm)
    _positive("radius_m", radius_m)
    omega = 2.0 * math.pi * speed_rpm / 60.0
    reynolds = omega * radius_m**2 / viscosity_m2_s
    nusselt = 0.36 * reynolds**0.5 if reynolds < 2.4e5 else 0.015 * reynolds**0.8
    return nusselt * conductivity_W_per_mK / radius_m
