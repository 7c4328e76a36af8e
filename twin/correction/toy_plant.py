"""A five-node lumped thermal model of two bearings in a housing, for tests and benchmarks.

Not the twin (that is the FEM spindle model): a small linear network with the same sensors
(T1 front ring, T2 front sleeve, T3 rear ring, T4 rear sleeve, T5 housing) whose bearing
heat H [W/m³] and ring/sleeve contact resistance R [m²K/W] enter exactly as in the twin, so
the corrections and networks can be exercised on curves with a known truth.

Nodes and conductances (W/K): ring -(A_c/R)- sleeve -(G_sh)- housing -(G_ha)- ambient,
sleeve -(G_sa)- ambient; the motor loss heats the housing.  `contact_metal_W_K` puts the
metal between the sensors and the contact in series with it (ring -(1/(R/A_c + 1/G_m))-
sleeve): the ring-to-sleeve drop is then inelastic to R, d log drop = G_m/(G_m + A_c/R) ·
d log R, as on the spindle, where the sensors sit millimetres from the contact.
Magnitudes are chosen so that a run at 9000 rpm rises about 6 K at the front ring in
30 min, like the paper's Table 1.
Backward Euler, so the result does not depend on stability limits of the step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class ToyPlant:
    bearing_volume_m3: tuple[float, float] = (2.0e-5, 1.2e-5)
    contact_area_m2: tuple[float, float] = (6.9e-3, 5.0e-3)
    ring_capacity_J_K: tuple[float, float] = (400.0, 250.0)
    sleeve_capacity_J_K: tuple[float, float] = (3000.0, 2000.0)
    housing_capacity_J_K: float = 40000.0
    sleeve_housing_W_K: tuple[float, float] = (8.0, 6.0)
    sleeve_ambient_W_K: tuple[float, float] = (1.5, 1.0)
    housing_ambient_W_K: float = 12.0
    motor_loss_W_per_krpm: float = 4.0
    contact_metal_W_K: tuple[float, float] | None = None
    """Conductance of the metal in series with each contact (front, rear); None: the drop
    is all contact."""

    def nominal_heat_W_m3(self, speed_rpm: ArrayLike) -> np.ndarray:
        """Front and rear bearing heat (N, 2) growing with speed like Palmgren's n·M."""
        n = np.asarray(speed_rpm, dtype=float)[..., None] / 9000.0
        return np.array([1.64e6, 0.9e6]) * np.abs(n) ** 1.5

    def nominal_resistance_m2K_W(self, speed_rpm: ArrayLike) -> np.ndarray:
        """Front and rear contact resistance (N, 2); independent of speed here."""
        n = np.asarray(speed_rpm, dtype=float)[..., None]
        return np.broadcast_to(np.array([1.0e-4, 1.2e-4]), n.shape[:-1] + (2,)).copy()

    def simulate(
        self,
        time_s: ArrayLike,
        speed_rpm: ArrayLike,
        ambient_C: ArrayLike,
        heat_W_m3: ArrayLike,
        resistance_m2K_W: ArrayLike,
        initial_C: ArrayLike | None = None,
    ) -> np.ndarray:
        """T1..T5 (N, 5) at `time_s`; the inputs at sample i act over (t_{i−1}, t_i]."""
        t = np.asarray(time_s, dtype=float)
        speed = np.broadcast_to(np.asarray(speed_rpm, dtype=float), t.shape)
        amb = np.broadcast_to(np.asarray(ambient_C, dtype=float), t.shape)
        heat = np.broadcast_to(np.asarray(heat_W_m3, dtype=float), t.shape + (2,))
        res = np.broadcast_to(np.asarray(resistance_m2K_W, dtype=float), t.shape + (2,))
        cap = np.array([self.ring_capacity_J_K[0], self.sleeve_capacity_J_K[0],
                        self.ring_capacity_J_K[1], self.sleeve_capacity_J_K[1],
                        self.housing_capacity_J_K])
        T = np.empty((t.size, 5))
        T[0] = amb[0] if initial_C is None else np.asarray(initial_C, dtype=float)
        for i in range(1, t.size):
            dt = t[i] - t[i - 1]
            G = np.zeros((5, 5))
            b = np.zeros(5)

            def link(a: int, c: int, g: float, G: np.ndarray = G) -> None:
                G[a, a] += g
                G[c, c] += g
                G[a, c] -= g
                G[c, a] -= g

            for k, (ring, sleeve) in enumerate(((0, 1), (2, 3))):
                g_contact = self.contact_area_m2[k] / res[i, k]
                if self.contact_metal_W_K is not None:  # in series: resistances add
                    g_contact = 1.0 / (1.0 / g_contact + 1.0 / self.contact_metal_W_K[k])
                link(ring, sleeve, g_contact)
                link(sleeve, 4, self.sleeve_housing_W_K[k])
                G[sleeve, sleeve] += self.sleeve_ambient_W_K[k]
                b[sleeve] += self.sleeve_ambient_W_K[k] * amb[i]
                b[ring] += heat[i, k] * self.bearing_volume_m3[k]
            G[4, 4] += self.housing_ambient_W_K
            b[4] += self.housing_ambient_W_K * amb[i] + self.motor_loss_W_per_krpm * speed[i] / 1e3
            A = np.diag(cap / dt) + G
            T[i] = np.linalg.solve(A, cap / dt * T[i - 1] + b)
        return T
