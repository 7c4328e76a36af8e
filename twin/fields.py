"""A temperature state of the spindle as a field mesh: temperature, displacement, stress.

The section is written as it is modelled, x = r and y = z (axial) in metres, on the
thermal (split) mesh so the temperature jump across the contact interfaces is visible.
Displacement and stress live on the glued structural mesh and are carried to the split
nodes through the node map.  Vertex values only (P2 mid-side values are dropped).
"""

from __future__ import annotations

import numpy as np

from twin.spindle.model import SpindleModel


def field_arrays(model: SpindleModel, T: np.ndarray, T_initial_C: float | None = None) -> dict:
    """Point arrays on the thermal-mesh vertices.

    temperature_C, displacement_um (r, z, 0) — relative to a uniform `T_initial_C` when
    given (the replay's drift convention), else to the stress-free T_ref — and
    von_mises_MPa.
    """
    mesh = model.mesh
    n_vertices = mesh.thermal.p.shape[1]
    n_glued = mesh.glued.p.shape[1]
    elastic = model.elastic
    u_abs = elastic.solve(T)
    stress = elastic.stresses(u_abs, T)
    # the structure is linear in T − T_ref: the drift from a uniform T_initial is the
    # solution for the excess T − T_initial (one back-substitution instead of two)
    u = u_abs if T_initial_C is None else elastic.solve(T - T_initial_C + elastic.T_ref)
    nodes = mesh.node_map[:n_vertices]
    disp = np.zeros((n_vertices, 3))
    disp[:, 0] = 1e6 * u[0, :n_glued][nodes]
    disp[:, 1] = 1e6 * u[1, :n_glued][nodes]
    return {
        "temperature_C": np.asarray(T[:n_vertices], float),
        "displacement_um": disp,
        "von_mises_MPa": 1e-6 * stress["von_mises"][:n_glued][nodes],
    }


def field_mesh(model: SpindleModel, T: np.ndarray, T_initial_C: float | None = None):  # noqa: ANN201
    """meshio.Mesh of the section with the arrays of `field_arrays` and a region id."""
    import meshio

    mesh = model.mesh
    points = np.zeros((mesh.thermal.p.shape[1], 3))
    points[:, :2] = mesh.thermal.p.T
    region_id = np.zeros(mesh.n_cells, dtype=np.int32)
    for i, name in enumerate(sorted(model.spec.regions), start=1):
        region_id[mesh.regions[name]] = i
    return meshio.Mesh(
        points,
        [("triangle", mesh.thermal.t.T.astype(np.int64))],
        point_data=field_arrays(model, T, T_initial_C),
        cell_data={"region": [region_id]},
    )
