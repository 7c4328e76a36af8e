"""Open-loop warm-up of the reference spindle: 30 min at 9000 rpm, 25.3 °C ambient.

This is the twin without any correction: nominal Palmgren bearing heat, motor loss, film
coefficients from correlations and the Eq. 4 contact resistance. The reference paper
measured the rotor as the hottest part (57.0 °C) and 8.47 µm of nose drift after 30 min
(shared REFERENCE.md §1); our nominal model is not tuned to that spindle's unknown
dimensions, so the check is that it lands in the same range, and that the energy balance
of every step closes (a property of the discretisation, not of the tuning).
"""

import numpy as np

from twin.spindle import SpindleModel, simulate

model = SpindleModel.load()
result = simulate(model, speed_rpm=9000, minutes=30, ambient_C=25.3)

print(f"hottest: {result.max_temperature_C:.1f} °C in the {result.max_temperature_region}")
print(f"nose drift after 30 min: axial {result.disp_z_um[-1]:.2f} µm, "
      f"radial {result.disp_r_um[-1]:.2f} µm")
print("T1..T5 at 30 min:", np.round(result.sensors_C[-1], 2), "°C")
print(f"worst energy-balance residual: {result.relative_residual.max():.1e} of the heat input")

assert result.max_temperature_region == "rotor"
assert 40.0 < result.max_temperature_C < 70.0  # paper: 57.0 °C
assert 5.0 < result.disp_z_um[-1] < 15.0  # paper: 8.47 µm
assert result.relative_residual.max() < 1e-9
