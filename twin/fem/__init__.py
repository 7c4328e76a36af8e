"""Axisymmetric thermal-structural finite elements on scikit-fem (the ANSYS stand-in).

mesh        AxiMesh: (r, z) triangles with named regions, boundaries, split interfaces
materials   Material: isotropic constants, validated
forms       the weak forms (2πr-weighted), plain scikit-fem forms
combine     PatternCombination: K(θ) = Σ θ_i K_i on one sparsity pattern
thermal     ThermalProblem, ThermalLoads, ThermalStepper, energy balance, probes
structural  ElasticProblem: factorized once, thermal load operator, stresses, probes
"""

from twin.fem.materials import Material
from twin.fem.mesh import AxiMesh, Interface
from twin.fem.structural import ElasticProblem, von_mises
from twin.fem.thermal import ThermalLoads, ThermalProblem, ThermalStepper

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
