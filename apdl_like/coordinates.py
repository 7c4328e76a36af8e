"""Coordinate systems of a 2-D model: global Cartesian (0), global cylindrical (1) and the
local systems LOCAL and CLOCAL define (numbers ≥ 11).

The database stores every coordinate global Cartesian (x = r, y = z for an axisymmetric
model); commands that take or report coordinates (N, K, FILL, NGEN, KGEN, L, NSEL/KSEL/LSEL
LOC, *GET NODE LOC, NX/NY, NODE()) convert through the active system (CSYS), as MAPDL does.

A system is an origin (x, y) and a rotation θxy about Z (degrees, +X toward +Y); a
cylindrical one reads its fields as (R, θ in degrees) about that origin, θ measured from its
rotated X axis, reported in (-180°, 180°].  Only rotations in the XY plane exist in 2-D.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CoordinateSystem:
    cylindrical: bool = False
    origin: tuple[float, float] = (0.0, 0.0)
    theta_xy_deg: float = 0.0  # rotation of the system's X axis from the global X, degrees

    def to_global(self, a: float, b: float) -> tuple[float, float]:
        """Global (x, y) of the point whose coordinates in this system are (a, b)
        (X, Y, or R, θ in degrees)."""
        if self.cylindrical:
            t = math.radians(b)
            a, b = a * math.cos(t), a * math.sin(t)
        rot = math.radians(self.theta_xy_deg)
        c, s = math.cos(rot), math.sin(rot)
        return self.origin[0] + c * a - s * b, self.origin[1] + s * a + c * b

    def from_global(self, xy: np.ndarray) -> np.ndarray:
        """Coordinates (n, 2) in this system of global points xy (n, 2)."""
        xy = np.asarray(xy, float).reshape(-1, 2)
        rot = math.radians(self.theta_xy_deg)
        c, s = math.cos(rot), math.sin(rot)
        dx, dy = xy[:, 0] - self.origin[0], xy[:, 1] - self.origin[1]
        a, b = c * dx + s * dy, -s * dx + c * dy
        if self.cylindrical:
            return np.column_stack([np.hypot(a, b), np.degrees(np.arctan2(b, a))])
        return np.column_stack([a, b])


GLOBAL_SYSTEMS = {0: CoordinateSystem(), 1: CoordinateSystem(cylindrical=True)}
FIRST_LOCAL = 11  # MAPDL numbers local systems from 11 (0..10 are predefined)
