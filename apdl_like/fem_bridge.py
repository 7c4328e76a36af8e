"""From the APDL database to twin.fem: mesh, dof maps, loads, cached problems.

`FemModel` is built once per mesh topology.  It triangulates the APDL elements (a 4-node
quad becomes two triangles; PLANE55 with K = L is the 3-node triangle), builds a
`twin.fem.AxiMesh`, and keeps the maps APDL node → thermal dof / structural dof.  Quadratic
elements (PLANE77, PLANE183) run on P2 triangles: their mid-side nodes are the P2 edge dofs
(the geometry stays straight-sided, so a mid-side node off the edge midpoint is read as if it
sat on the midpoint).

Load sets map onto twin.fem by *entity sets*: the cells of one HGEN record become a region,
the faces of one CONV/HFLUX record a boundary.  A set is named once (an existing region or
boundary with exactly the same members keeps its name, e.g. the spindle's "bearing_front"),
so a window deck that re-applies loads on the same components reuses every operator that
`ThermalProblem` already assembled.  The sets a model names are its own: the first one
makes its mesh a view of the one it was given (`AxiMesh.view`), so the spindle model's
mesh, which the loop's sessions share, holds its own regions and boundaries only, and a
session's names never depend on what another session loaded.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from apdl_like.errors import ApdlError
from apdl_like.model import Database, element_corners, pair_keys
from twin.fem import AxiMesh


class FemModel:
    """The FEM view of one mesh topology (built from the database or given as an AxiMesh)."""

    def __init__(
        self,
        mesh: AxiMesh,
        vertex_node: np.ndarray,
        cell_element: np.ndarray,
        order: int,
        node_ids: np.ndarray,
        midside: np.ndarray | None = None,
    ) -> None:
        """
        vertex_node   thermal-mesh vertex -> index into the node table
        cell_element  cell -> index into the element table
        midside       (3, m) rows: node index, vertex a, vertex b of each mid-side node
        """
        self.mesh = mesh
        # False while `mesh` is the mesh given; the first set this model names makes it a
        # view of that mesh with registries of its own (`AxiMesh.view`): a mesh shared by
        # several sessions (the loop's spindle model) never holds one session's sets
        self.own_sets = False
        self.order = order
        self.vertex_node = vertex_node
        self.cell_element = cell_element
        n_nodes = len(node_ids)
        self.node_ids = node_ids
        self.node_vertex = np.full(n_nodes, -1, np.int64)
        self.node_vertex[vertex_node] = np.arange(vertex_node.size)
        thermal = mesh.thermal
        n_vert = thermal.p.shape[1]
        # thermal dofs: P1/P2 vertex dofs are the vertex numbers, P2 edge dofs follow
        self.thermal_dof = np.full(n_nodes, -1, np.int64)
        self.thermal_dof[vertex_node] = np.arange(vertex_node.size)
        glued_vertex = mesh.node_map
        self.glued_dof = np.full(n_nodes, -1, np.int64)
        self.glued_dof[vertex_node] = glued_vertex
        self.midside_nodes = np.zeros(0, np.int64)
        self.midside_ends = np.zeros((2, 0), np.int64)  # node indices of each edge's corners
        if midside is not None and midside.size:
            if order != 2:
                raise ApdlError("mid-side nodes need quadratic elements (PLANE77/PLANE183)")
            t_f = self._facets_of(thermal.facets, n_vert, midside[1], midside[2])
            g_f = self._facets_of(mesh.glued.facets, mesh.glued.p.shape[1],
                                  glued_vertex[midside[1]], glued_vertex[midside[2]])
            self.thermal_dof[midside[0]] = n_vert + t_f
            self.glued_dof[midside[0]] = mesh.glued.p.shape[1] + g_f
            self.midside_nodes = midside[0]
            self.midside_ends = vertex_node[midside[1:]]
        # exterior faces of the thermal mesh = the faces SF/SFE can load
        self.face_facets = thermal.boundary_facets()
        fv = thermal.facets[:, self.face_facets]
        self.face_nodes = vertex_node[fv]  # (2, n_faces) node indices
        self.face_keys = pair_keys(node_ids[self.face_nodes[0]], node_ids[self.face_nodes[1]])
        self._face_order = np.argsort(self.face_keys)
        self._region_names = {self._key(c): name for name, c in mesh.regions.items()}
        self._boundary_names = {self._key(f): name for name, f in mesh.boundaries.items()}
        self.version = 0
        self.used_materials: list[int] | None = None  # MAT numbers of the cells (solve.py)

    @staticmethod
    def _facets_of(facets: np.ndarray, n: int, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        keys = pair_keys(facets[0], facets[1])
        order = np.argsort(keys)
        want = pair_keys(a, b)
        pos = np.clip(np.searchsorted(keys[order], want), 0, keys.size - 1)
        if not np.array_equal(keys[order][pos], want):
            raise ApdlError("a mid-side node does not sit on an element edge")
        return order[pos]

    @staticmethod
    def _key(indices: np.ndarray) -> bytes:
        return np.ascontiguousarray(np.sort(np.asarray(indices, np.int64))).tobytes()

    # -------------------------------------------------------------- named sets
    def region_for(self, cells: np.ndarray) -> str:
        """A region name for exactly these cells (existing name if the set is known)."""
        return self._named(cells, self._region_names, "_cells", "region")

    def boundary_for(self, facets: np.ndarray) -> str:
        """A boundary name for exactly these facets (existing name if the set is known)."""
        return self._named(facets, self._boundary_names, "_faces", "boundary")

    def _named(self, indices: np.ndarray, names: dict[bytes, str], prefix: str,
               kind: str) -> str:
        key = self._key(indices)
        name = names.get(key)
        if name is None:
            if not self.own_sets:  # the mesh others may share stays as it was given
                self.mesh = self.mesh.view()
                self.own_sets = True
            mesh = self.mesh
            taken = mesh.regions if kind == "region" else mesh.boundaries
            name = f"{prefix}{len(names)}"
            while name in taken:
                name += "_"
            (mesh.add_region if kind == "region" else mesh.add_boundary)(name, indices)
            names[key] = name
        return name

    def cells_of_elements(self, element_mask: np.ndarray) -> np.ndarray:
        return np.nonzero(element_mask[self.cell_element])[0]

    def face_index(self, keys: np.ndarray) -> np.ndarray:
        """Exterior-face positions of packed node-pair keys; -1 where not an exterior face."""
        sorted_keys = self.face_keys[self._face_order]
        pos = np.clip(np.searchsorted(sorted_keys, keys), 0, max(sorted_keys.size - 1, 0))
        ok = sorted_keys[pos] == keys if sorted_keys.size else np.zeros(keys.shape, bool)
        return np.where(ok, self._face_order[pos], -1)

    # ----------------------------------------------------------- node values
    def thermal_nodal(self, T: np.ndarray) -> np.ndarray:
        """Nodal temperature per APDL node (NaN for nodes outside the elements)."""
        out = np.full(self.thermal_dof.size, np.nan)
        ok = self.thermal_dof >= 0
        out[ok] = T[self.thermal_dof[ok]]
        return out

    def glued_nodal(self, values: np.ndarray) -> np.ndarray:
        out = np.full(self.glued_dof.size, np.nan)
        ok = self.glued_dof >= 0
        out[ok] = values[self.glued_dof[ok]]
        return out

    def nodal_to_thermal(self, nodal: np.ndarray, base: np.ndarray) -> np.ndarray:
        """Thermal dof vector from per-node values (NaN keeps `base`); P2 edge dofs whose
        nodes were not given follow the mean of their two vertices where those were given."""
        T = np.array(base, dtype=float, copy=True)
        given = ~np.isnan(nodal) & (self.thermal_dof >= 0)
        T[self.thermal_dof[given]] = nodal[given]
        if self.order == 2:
            thermal = self.mesh.thermal
            n_vert = thermal.p.shape[1]
            vertex_given = np.zeros(n_vert, bool)
            vertex_given[self.thermal_dof[given & (self.node_vertex >= 0)]] = True
            edge_given = np.zeros(thermal.facets.shape[1], bool)
            mid = given & np.isin(np.arange(given.size), self.midside_nodes)
            edge_given[self.thermal_dof[mid] - n_vert] = True
            f = thermal.facets
            fill = vertex_given[f[0]] & vertex_given[f[1]] & ~edge_given
            T[n_vert + np.nonzero(fill)[0]] = 0.5 * (T[f[0, fill]] + T[f[1, fill]])
        return T


def triangulate(db: Database) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Cells (3, n) as node-table indices, cell → element index, mid-side rows, FEM order."""
    el = db.elements
    el.flush()
    if len(el.ids) == 0:
        raise ApdlError("the model has no elements to solve")
    types = {db.element_types[t].name for t in np.unique(el.type) if t in db.element_types}
    missing = [int(t) for t in np.unique(el.type) if t not in db.element_types]
    if missing:
        raise ApdlError(f"element type {missing[0]} is used by elements but never defined (ET)")
    quad = {db.element_types[t].quadratic for t in np.unique(el.type)}
    if len(quad) > 1:
        shown = ", ".join(sorted(types))
        raise ApdlError(f"mixing linear and quadratic element types is not supported ({shown})")
    order = 2 if quad.pop() else 1
    tri6 = np.array([db.element_types[t].triangle6 for t in el.type], bool)
    nodes = el.nodes
    idx = db.nodes.index(nodes.ravel()).reshape(nodes.shape)
    idx[nodes == 0] = -1
    corner = element_corners(db, idx, tri6)
    is_tri = corner[:, 2] == corner[:, 3]
    first = corner[:, [0, 1, 2]]
    second = corner[~is_tri][:, [0, 2, 3]]
    cells = np.vstack([first, second]).T
    cell_element = np.concatenate([np.arange(len(el.ids)), np.nonzero(~is_tri)[0]])
    # orient counter-clockwise and reject collapsed cells
    xy = db.nodes.xy
    a, b, c = xy[cells[0]], xy[cells[1]], xy[cells[2]]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    scale = max(float(np.ptp(xy[np.unique(cells)], axis=0).max()), 1e-300) ** 2
    if np.any(np.abs(det) <= 1e-12 * scale):
        bad = el.ids[cell_element[np.nonzero(np.abs(det) <= 1e-12 * scale)[0][0]]]
        raise ApdlError(f"element {bad} has zero area (check its node order and coordinates)")
    flip = det < 0
    cells[1, flip], cells[2, flip] = cells[2, flip], cells[1, flip].copy()
    midside = np.zeros((3, 0), np.int64)
    if order == 2:
        # (mid-side column, corner a, corner b); the degenerate quad (K = L = O) keeps
        # M on I-J, N on J-K and P on L-I = K-I
        quad_edges = [(4, 0, 1, ~tri6), (5, 1, 2, ~tri6), (6, 2, 3, ~tri6 & ~is_tri),
                      (7, 3, 0, ~tri6)]
        tri_edges = [(3, 0, 1, tri6), (4, 1, 2, tri6), (5, 2, 0, tri6)]
        rows = []
        for m, i, j, mask in quad_edges + tri_edges:
            sel = mask & (idx[:, m] >= 0)
            rows.append(np.vstack([idx[sel, m], corner[sel, i], corner[sel, j]]))
        midside = np.hstack(rows)
        if midside.size:
            _, first_seen = np.unique(midside[0], return_index=True)
            midside = midside[:, np.sort(first_seen)]
    return cells, cell_element, midside, order


def build_model(db: Database) -> FemModel:
    """A FemModel for the elements in the database (no contact interfaces)."""
    cells, cell_element, midside, order = triangulate(db)
    vertex_node = np.unique(cells)
    vertex_of = np.full(len(db.nodes.ids), -1, np.int64)
    vertex_of[vertex_node] = np.arange(vertex_node.size)
    points = db.nodes.xy[vertex_node].T
    if np.any(points[0] < -1e-9 * max(1.0, float(np.abs(points).max()))):
        bad = db.nodes.ids[vertex_node[np.argmin(points[0])]]
        raise ApdlError(f"node {bad} lies at negative X (radius) in an axisymmetric model")
    regions = {}
    mats = db.elements.mat[cell_element]
    for m in np.unique(mats):
        regions[f"MAT{int(m)}"] = np.nonzero(mats == m)[0]
    try:
        mesh = AxiMesh.from_arrays(points, vertex_of[cells], regions)
    except ValueError as exc:
        raise ApdlError(f"cannot build the mesh: {exc}") from None
    if midside.size:
        midside = np.vstack([midside[0], vertex_of[midside[1]], vertex_of[midside[2]]])
    return FemModel(mesh, vertex_node, cell_element, order, db.nodes.ids, midside)


def nearest_node(xy: np.ndarray, mask: np.ndarray, point: np.ndarray) -> int:
    """Index of the selected node nearest to `point`, -1 if none is selected."""
    idx = np.nonzero(mask)[0]
    if idx.size == 0:
        return -1
    if idx.size > 64:
        return int(idx[cKDTree(xy[idx]).query(point)[1]])
    return int(idx[np.argmin(((xy[idx] - point) ** 2).sum(axis=1))])
