"""Axisymmetric thermal-structural finite elements on scikit-fem (the ANSYS stand-in).

mesh        AxiMesh: (r, z) triangles with named regions, boundaries, split interfaces
materials   Material: isotropic constants, validated
forms       the weak forms (2πr-weighted), plain scikit-fem forms
combine     PatternCombination: K(θ) = Σ θ_i K_i on one sparsity pattern
elements    P1/P2 Lagrange triangles
linalg      symmetric factorization, Dirichlet elimination, low-rank (Woodbury) updates
probes      point-evaluation matrices
loads       ThermalLoads: one validated load set
balance     HeatBalance: the discrete heat balance of a step
thermal     ThermalProblem: operators by region/boundary/interface, steady and transient
stepper     the θ-method: ThermalStepper (fixed loads, `march(T, n)` yields each step), and
            theta_step / picard / march_to for re-assembled systems (k(T), AUTOTS)
structural  ElasticProblem: factorized once, thermal load operator, stresses, probes
"""

from twin.fem.loads import ThermalLoads
from twin.fem.materials import Material
from twin.fem.mesh import AxiMesh, Interface
from twin.fem.stepper import ThermalStepper
from twin.fem.structural import ElasticProblem, von_mises
from twin.fem.thermal import ThermalProblem

__all__ = [
    "AxiMesh",
    "ElasticProblem",
    "Interface",
    "Material",
    "ThermalLoads",
    "ThermalProblem",
    "ThermalStepper",
    "von_mises",
]
