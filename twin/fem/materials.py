"""Isotropic material constants for the thermal and the thermo-elastic problem."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Material:
    """Isotropic, temperature-independent material (SI units).

    k      conductivity, W/(m·K)
    rho    density, kg/m³
    c      specific heat capacity, J/(kg·K)
    E      Young's modulus, Pa
    nu     Poisson's ratio, −
    alpha  linear thermal expansion coefficient, 1/K
    name   optional label used in error messages
    """

    k: float
    rho: float
    c: float
    E: float = 210e9
    nu: float = 0.3
    alpha: float = 12e-6
    name: str = ""

    def __post_init__(self) -> None:
        label = f"material {self.name!r}" if self.name else "material"
        for field in ("k", "rho", "c", "E"):
            value = getattr(self, field)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"{label}: {field} must be positive and finite, got {value!r}")
        if not (math.isfinite(self.nu) and -1.0 < self.nu < 0.5):
            raise ValueError(f"{label}: nu must lie in (-1, 0.5), got {self.nu!r}")
        if not math.isfinite(self.alpha):
            raise ValueError(f"{label}: alpha must be finite, got {self.alpha!r}")

    @property
    def rho_c(self) -> float:
        """Volumetric heat capacity ρ·c, J/(m³·K)."""
        return self.rho * self.c

    @property
    def lame(self) -> tuple[float, float]:
        """Lamé constants (λ, μ) in Pa."""
        lam = self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))
        mu = self.E / (2.0 * (1.0 + self.nu))
        return lam, mu
