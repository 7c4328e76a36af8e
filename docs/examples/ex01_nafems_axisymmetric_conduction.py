"""NAFEMS axisymmetric steady conduction benchmark (thermal set, 1986).

A hollow cylinder r ∈ [0.02, 0.1] m, z ∈ [0, 0.14] m with k = 52 W/(m·K). A heat flux of
5e5 W/m² enters the bore for z ∈ [0.04, 0.1]; the rest of the bore is insulated; the
bottom, top and outer faces are held at 0 °C. The published answer is
T(r = 0.04 m, z = 0.04 m) = 59.82 °C (332.97 K); see shared REFERENCE.md §6.

The point sits on the line z = 0.04 where the imposed flux starts, a corner of the load,
so the mesh lines go through it and the error falls as the mesh is refined.
"""

import numpy as np

from twin.fem import AxiMesh, Material, ThermalLoads, ThermalProblem

PUBLISHED_T_C = 59.82
R_IN, R_OUT, HEIGHT = 0.02, 0.1, 0.14
STEEL_52 = Material(k=52.0, rho=7800.0, c=460.0, name="NAFEMS k = 52")


def solve(cells_per_20mm: int, order: int) -> float:
    """T at (0.04, 0.04) m in °C on a tensor mesh with the given density."""
    r_edges = np.linspace(R_IN, R_OUT, 4 * cells_per_20mm + 1)
    z_edges = np.linspace(0.0, HEIGHT, 7 * cells_per_20mm + 1)
    mesh = AxiMesh.structured(
        r_edges,
        z_edges,
        boundaries={
            "heated_bore": lambda r, z: np.isclose(r, R_IN) & (z > 0.04) & (z < 0.1),
            "held_faces": lambda r, z: (
                np.isclose(z, 0.0) | np.isclose(z, HEIGHT) | np.isclose(r, R_OUT)
            ),
        },
    )
    problem = ThermalProblem(mesh, {"body": STEEL_52}, order=order)
    loads = ThermalLoads(flux={"heated_bore": 5e5}, fixed_temperature={"held_faces": 0.0})
    T = problem.steady(loads)
    return float((problem.probe(np.array([[0.04], [0.04]])) @ T)[0])


if __name__ == "__main__":
    for order in (1, 2):
        for density in (2, 4, 8):
            T = solve(density, order)
            print(f"P{order}, {density} cells per 20 mm: T = {T:.3f} °C "
                  f"({100 * (T / PUBLISHED_T_C - 1):+.2f} % of the published value)")
    T_fine = solve(8, 2)
    assert abs(T_fine - PUBLISHED_T_C) < 0.005 * PUBLISHED_T_C, T_fine
