"""Bearing friction heat after Palmgren (REFERENCE.md §1 Eq. 1 and §3).

The friction torque of a rolling bearing is split into a load-independent (viscous) part
M1 and a load-dependent part M2, both in N·mm:

    M1 = 1e-7 · f0 · (ν·n)^(2/3) · Dm³      if ν·n ≥ 2000
    M1 = 160e-7 · f0 · Dm³                  otherwise
    M2 = f1 · P1 · Dm,   f1 = 0.0012 · (P0/C0)^0.33

with n in rpm, ν the lubricant's kinematic viscosity in mm²/s at the bearing temperature,
Dm the pitch diameter in mm, P1 the dynamic equivalent load for friction and P0/C0 the
static load ratio.  The heat is the friction power ω·M = 2π·n/60 · M·1e-3 W
= 1.047e-4 · n · M W, and the volumetric rate used by the FEM is that power over the
bearing volume V [m³] (Eq. 1: H = 1.047e-4 · n · M / V, W/m³).

f0 for angular-contact ball bearings: about 1 with oil-air or oil-jet lubrication,
2 with grease, 3–4 with oil mist (REFERENCE.md §3).
"""

from __future__ import annotations

import math

from twin.physics.lubricant import kinematic_viscosity_mm2_s

# 2π/60 · 1e-3: converts n [rpm] · M [N·mm] into W (the 1.047e-4 of Eq. 1).
_RPM_NMM_TO_W = 2.0 * math.pi / 60.0 * 1e-3


def _require(name: str, value: float, *, positive: bool = False) -> None:
    if not math.isfinite(value) or value < 0.0 or (positive and value == 0.0):
        kind = "positive" if positive else "non-negative"
        raise ValueError(f"{name} must be a finite {kind} number, got {value}")


def equivalent_dynamic_load_N(axial_load_N: float, radial_load_N: float,
                              contact_angle_deg: float) -> float:
    """P1 for the load torque of an angular-contact ball bearing (REFERENCE.md §3).

    P1 = max(Fa, 0.9·Fa·cot α − 0.1·Fr): the axial (pre)load dominates a spindle bearing,
    amplified by cot α because it acts through the contact angle.
    """
    _require("axial_load_N", axial_load_N)
    _require("radial_load_N", radial_load_N)
    if not 0.0 < contact_angle_deg < 90.0:
        raise ValueError(f"contact_angle_deg must be in (0, 90), got {contact_angle_deg}")
    cot = 1.0 / math.tan(math.radians(contact_angle_deg))
    return max(axial_load_N, 0.9 * axial_load_N * cot - 0.1 * radial_load_N)


def load_factor_f1(static_equivalent_load_N: float, static_load_rating_N: float) -> float:
    """f1 = 0.0012 · (P0/C0)^0.33, the handbook form for ball bearings (REFERENCE.md §3)."""
    _require("static_equivalent_load_N", static_equivalent_load_N)
    _require("static_load_rating_N", static_load_rating_N, positive=True)
    return 0.0012 * (static_equivalent_load_N / static_load_rating_N) ** 0.33


def friction_torque_Nmm(speed_rpm: float, viscosity_mm2_s: float, f0: float,
                        pitch_diameter_mm: float, f1: float, load_P1_N: float) -> float:
    """Palmgren friction torque M = M1 + M2 in N·mm (REFERENCE.md §1 Eq. 1)."""
    _require("speed_rpm", speed_rpm)
    _require("viscosity_mm2_s", viscosity_mm2_s, positive=True)
    _require("f0", f0, positive=True)
    _require("pitch_diameter_mm", pitch_diameter_mm, positive=True)
    _require("f1", f1)
    _require("load_P1_N", load_P1_N)
    dm3 = pitch_diameter_mm**3
    nu_n = viscosity_mm2_s * speed_rpm
    if nu_n >= 2000.0:
        m1 = 1e-7 * f0 * nu_n ** (2.0 / 3.0) * dm3
    else:
        # Below ν·n = 2000 the viscous torque no longer falls with speed (boundary film).
        m1 = 160e-7 * f0 * dm3
    m2 = f1 * load_P1_N * pitch_diameter_mm
    return m1 + m2


def bearing_heat_palmgren(speed_rpm: float, torque_Nmm: float, volume_m3: float) -> float:
    """Volumetric bearing heat H = 1.047e-4 · n · M / V in W/m³ (REFERENCE.md §1 Eq. 1)."""
    _require("speed_rpm", speed_rpm)
    _require("torque_Nmm", torque_Nmm)
    _require("volume_m3", volume_m3, positive=True)
    return _RPM_NMM_TO_W * speed_rpm * torque_Nmm / volume_m3


def bearing_heat_W(speed_rpm: float, temperature_C: float, *, pitch_diameter_mm: float,
                   f0: float, nu40_mm2_s: float, nu100_mm2_s: float, preload_N: float,
                   radial_load_N: float, contact_angle_deg: float,
                   static_load_rating_N: float, static_axial_factor_Y0: float = 0.46) -> float:
    """Friction power [W] of an angular-contact ball bearing at `temperature_C`.

    Chains the pieces: oil viscosity at the bearing temperature (Walther), the static
    equivalent load P0 = max(Fr, 0.5·Fr + Y0·Fa) → f1, the dynamic equivalent load P1 from
    the axial preload Fa and radial load Fr, Palmgren's torque and ω·M.
    `static_axial_factor_Y0`: 0.46 for a 15° contact angle, 0.38 for 25° (ISO 76).
    """
    nu = kinematic_viscosity_mm2_s(temperature_C, nu40_mm2_s, nu100_mm2_s)
    p0 = max(radial_load_N, 0.5 * radial_load_N + static_axial_factor_Y0 * preload_N)
    f1 = load_factor_f1(p0, static_load_rating_N)
    p1 = equivalent_dynamic_load_N(preload_N, radial_load_N, contact_angle_deg)
    torque = friction_torque_Nmm(speed_rpm, nu, f0, pitch_diameter_mm, f1, p1)
    return _RPM_NMM_TO_W * speed_rpm * torque
