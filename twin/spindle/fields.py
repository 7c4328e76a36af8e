"""A temperature state of the spindle as field arrays: temperature, displacement, stress.

Values on the thermal (split) mesh vertices, so the temperature jump across the contact
interfaces is visible; displacement and stress live on the glued structural mesh and are
carried to the split nodes through the node map.  P2 mid-side values are dropped.  Names
and units are those of every field file (`twin.io.vtk`): temperature_C, displacement_um
(drift relative to a uniform start temperature), von_mises_MPa.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from twin.io.vtk import field_point_data, section_mesh
from twin.spindle.model import SpindleModel


def field_arrays(model: SpindleModel, T: np.ndarray,
                 T_initial_C: float | np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Point arrays on the thermal-mesh vertices (`twin.io.vtk` names and units).

    The displacement is relative to `T_initial_C` (the start of the run, the drift
    convention: a uniform temperature, or a warm start's field per thermal dof) when given,
    else to the stress-free T_ref; the stress is always the thermal stress relative to T_ref.
    """
    mesh = model.mesh
    n_vertices = mesh.thermal.p.shape[1]
    n_glued = mesh.glued.p.shape[1]
    elastic = model.elastic
    u_abs = elastic.solve(T)
    stress = elastic.stresses(u_abs, T)
    # the structure is linear in T − T_ref: the drift from T_initial is the solution for
    # the excess T − T_initial (one back-substitution instead of two)
    u = u_abs if T_initial_C is None else elastic.solve(T - T_initial_C + elastic.T_ref)
    nodes = mesh.node_map[:n_vertices]
    return field_point_data(T[:n_vertices], u[:, :n_glued][:, nodes],
                            stress["von_mises"][:n_glued][nodes])


def field_mesh(model: SpindleModel, T: np.ndarray,
               T_initial_C: float | np.ndarray | None = None) -> Any:
    """meshio.Mesh of the section with the arrays of `field_arrays` and the region number."""
    mesh = model.mesh
    region = np.zeros(mesh.n_cells, dtype=np.int32)
    for i, name in enumerate(sorted(model.spec.regions), start=1):
        region[mesh.regions[name]] = i
    return section_mesh(mesh.thermal.p, mesh.thermal.t, field_arrays(model, T, T_initial_C),
                        region)
