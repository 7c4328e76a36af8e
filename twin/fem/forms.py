"""Axisymmetric weak forms as plain scikit-fem forms.

Every integral carries the axisymmetric volume element 2πr dr dz (and 2πr ds on facets),
so assembled matrices and vectors are in true 3-D units: W/K, J/K and W.  Material
coefficients are *not* inside the forms: operators are assembled with unit coefficients
per region/boundary/interface and combined linearly (`twin.fem.combine`), so changing a
film coefficient or a heat source never re-assembles anything.
"""

from __future__ import annotations

import numpy as np
from skfem import BilinearForm, DiscreteField, LinearForm
from skfem.assembly.form.form import FormExtraParams  # `w`: the form's x, h and fields
from skfem.helpers import dot, grad

TWO_PI = 2.0 * np.pi


@BilinearForm
def conduction(u: DiscreteField, v: DiscreteField, w: FormExtraParams) -> np.ndarray:
    """∫ ∇u·∇v 2πr dA (unit conductivity)."""
    return dot(grad(u), grad(v)) * TWO_PI * w.x[0]


@BilinearForm
def capacity(u: DiscreteField, v: DiscreteField, w: FormExtraParams) -> np.ndarray:
    """∫ u v 2πr dA (unit volumetric heat capacity); also the facet mass on FacetBasis."""
    return u * v * TWO_PI * w.x[0]


@LinearForm
def unit_load(v: DiscreteField, w: FormExtraParams) -> np.ndarray:
    """∫ v 2πr dA (unit source density), or ∫ v 2πr ds on a FacetBasis (unit flux)."""
    return v * TWO_PI * w.x[0]


@LinearForm
def unit_load_weighted(v: DiscreteField, w: FormExtraParams) -> np.ndarray:
    """∫ s v 2πr dA for a quadrature-point field w.s (used by L2 projection)."""
    return w.s * v * TWO_PI * w.x[0]


def _strain(u: DiscreteField, r: np.ndarray) -> tuple[np.ndarray, ...]:
    """Axisymmetric engineering strain (ε_rr, ε_zz, ε_θθ, γ_rz) of a vector field (u_r, u_z)."""
    du = grad(u)
    return (du[0, 0], du[1, 1], u[0] / r, du[0, 1] + du[1, 0])


@BilinearForm
def elasticity(u: DiscreteField, v: DiscreteField, w: FormExtraParams) -> np.ndarray:
    """∫ σ(u):ε(v) 2πr dA with per-cell Lamé constants w.lam, w.mu (Pa)."""
    r = w.x[0]
    eu = _strain(u, r)
    ev = _strain(v, r)
    tr_u = eu[0] + eu[1] + eu[2]
    tr_v = ev[0] + ev[1] + ev[2]
    normal = 2.0 * w.mu * (eu[0] * ev[0] + eu[1] * ev[1] + eu[2] * ev[2])
    shear = w.mu * eu[3] * ev[3]
    return (w.lam * tr_u * tr_v + normal + shear) * TWO_PI * r


@BilinearForm
def thermal_strain_load(t: DiscreteField, v: DiscreteField,
                        w: FormExtraParams) -> np.ndarray:
    """∫ (3λ + 2μ) α t tr ε(v) 2πr dA: the load of a temperature rise t on the structure.

    Trial space: scalar temperature; test space: displacement.  w.beta = (3λ+2μ)·α per cell.
    """
    r = w.x[0]
    ev = _strain(v, r)
    return w.beta * t * (ev[0] + ev[1] + ev[2]) * TWO_PI * r
