"""Heat sources, film coefficients and contact resistance of the motorized spindle.

Every function restates a formula of the shared REFERENCE.md (section named in its
docstring) and takes plain floats in the units its argument names say.  They know nothing
about meshes: `twin.spindle.conditions` turns their results into FEM loads.

Modules: `lubricant` (viscosity vs temperature), `bearing` (Palmgren friction heat),
`motor` (motor loss split), `convection` (film coefficients), `contact` (bearing outer
ring / sleeve contact resistance, Eq. 4 and Eq. 5).
"""

from twin.physics.bearing import (
    bearing_heat_palmgren,
    bearing_heat_W,
    equivalent_dynamic_load_N,
    friction_torque_Nmm,
    load_factor_f1,
)
from twin.physics.contact import (
    contact_resistance_initial,
    contact_resistance_thermal,
    fit_pressure_MPa,
)
from twin.physics.convection import (
    air_gap_h,
    coolant_h,
    natural_convection_h,
    radiation_h,
    rotating_cylinder_h,
    rotating_disk_h,
)
from twin.physics.lubricant import kinematic_viscosity_mm2_s
from twin.physics.motor import motor_heat_split_W, motor_loss_W

__all__ = [
    "air_gap_h",
    "bearing_heat_W",
    "bearing_heat_palmgren",
    "contact_resistance_initial",
    "contact_resistance_thermal",
    "coolant_h",
    "equivalent_dynamic_load_N",
    "fit_pressure_MPa",
    "friction_torque_Nmm",
    "kinematic_viscosity_mm2_s",
    "load_factor_f1",
    "motor_heat_split_W",
    "motor_loss_W",
    "natural_convection_h",
    "radiation_h",
    "rotating_cylinder_h",
    "rotating_disk_h",
]
