"""The axisymmetric (r, z) mesh with named regions, boundaries and contact interfaces.

Coordinates are metres with x = r (radius) and y = z (axis).  Regions are cell sets,
boundaries are facet sets, interfaces are pairs of coincident facet sets.

Contact resistance is modelled with *zero-thickness interface elements*: the mesh is split
along each interface (the interface nodes are duplicated for the cells of one side), and a
conductance (1/R)·∫ (T⁺ − T⁻)(v⁺ − v⁻) 2πr ds couples the two faces (see
`twin.fem.thermal`).  A thin layer of low conductivity would need a row of very flat
elements for each bearing and a re-mesh whenever R changes its meaning; interface elements
keep R a plain coefficient.  The structure does not slip at the bearing seats, so it uses
the unsplit ("glued") mesh; both meshes share the cell numbering, which lets the thermal
strain be integrated cell by cell with each side's own temperature.

An interface must separate exactly two regions.  Where it ends on a third region, that
region stays attached to the unsplit side only, so interfaces should end on free
(convective or insulated) boundaries, as bearing outer rings do.
"""

from __future__ import annotations

import contextlib
import io
import logging
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

import numpy as np
from skfem import MeshTri

if TYPE_CHECKING:
    import meshio

T = TypeVar("T")


@dataclass(frozen=True)
class Interface:
    """Matched facet pairs across a split interface.

    facets_a[i] and facets_b[i] are the two coincident thermal-mesh facets of one
    interface segment; side "a" belongs to `regions[0]`, side "b" to `regions[1]`.
    """

    facets_a: np.ndarray
    facets_b: np.ndarray
    regions: tuple[str, str]


def _facet_keys(facets: np.ndarray, n_nodes: int) -> np.ndarray:
    """Order-independent integer key per facet (node pair)."""
    lo = np.minimum(facets[0], facets[1]).astype(np.int64)
    hi = np.maximum(facets[0], facets[1]).astype(np.int64)
    return lo * n_nodes + hi


def _named(table: Mapping[str, T], name: str, kind: str) -> T:
    """table[name], or a ValueError listing the known names of that kind."""
    try:
        return table[name]
    except KeyError:
        raise ValueError(f"unknown {kind} {name!r}; known: {', '.join(sorted(table))}") from None


def _lookup(sorted_keys: np.ndarray, order: np.ndarray, keys: np.ndarray, what: str) -> np.ndarray:
    pos = np.searchsorted(sorted_keys, keys)
    pos = np.clip(pos, 0, len(sorted_keys) - 1)
    if keys.size and not np.all(sorted_keys[pos] == keys):
        raise ValueError(
            f"{what}: {int(np.sum(sorted_keys[pos] != keys))} edges are not mesh edges"
        )
    return order[pos]


@dataclass
class AxiMesh:
    """Axisymmetric triangle mesh (r, z) in metres with named sets.

    thermal     MeshTri split along the contact interfaces (used for temperature)
    glued       MeshTri without splits, same cell numbering (used for displacement)
    node_map    thermal node index → glued node index
    regions     name → cell indices
    boundaries  name → facet indices of `thermal`
    interfaces  name → `Interface`
    """

    thermal: MeshTri
    glued: MeshTri
    node_map: np.ndarray
    regions: dict[str, np.ndarray] = field(default_factory=dict)
    boundaries: dict[str, np.ndarray] = field(default_factory=dict)
    interfaces: dict[str, Interface] = field(default_factory=dict)

    # ------------------------------------------------------------------ queries
    @property
    def n_cells(self) -> int:
        return self.thermal.t.shape[1]

    def region(self, name: str) -> np.ndarray:
        """Cell indices of region `name`."""
        return _named(self.regions, name, "region")

    def boundary(self, name: str) -> np.ndarray:
        """Facet indices (thermal mesh) of boundary `name`."""
        return _named(self.boundaries, name, "boundary")

    def interface(self, name: str) -> Interface:
        return _named(self.interfaces, name, "interface")

    def glued_facets(self, name: str) -> np.ndarray:
        """Facet indices of boundary `name` in the glued (structural) mesh."""
        facets = self.thermal.facets[:, self.boundary(name)]
        n = self.glued.p.shape[1]
        glued_keys = _facet_keys(self.glued.facets, n)
        order = np.argsort(glued_keys)
        keys = _facet_keys(self.node_map[facets], n)
        return np.unique(_lookup(glued_keys[order], order, keys, f"boundary {name!r}"))

    def add_region(self, name: str, cells: Iterable[int]) -> None:
        cells = np.unique(
            np.asarray(list(cells) if not isinstance(cells, np.ndarray) else cells, dtype=np.int64)
        )
        if cells.size and (cells.min() < 0 or cells.max() >= self.n_cells):
            raise ValueError(f"region {name!r}: cell index out of range")
        self.regions[name] = cells

    def add_boundary(self, name: str, facets: Iterable[int]) -> None:
        facets = np.unique(
            np.asarray(
                list(facets) if not isinstance(facets, np.ndarray) else facets, dtype=np.int64
            )
        )
        if facets.size and (facets.min() < 0 or facets.max() >= self.thermal.facets.shape[1]):
            raise ValueError(f"boundary {name!r}: facet index out of range")
        self.boundaries[name] = facets

    def view(self) -> AxiMesh:
        """This mesh with registries of named sets of its own: the same triangles, node
        map, interfaces and, to start with, the same regions and boundaries (the same
        arrays), while `add_region` / `add_boundary` on the view leave this mesh as it is
        (an owner that names sets of its own on a mesh others share)."""
        return AxiMesh(self.thermal, self.glued, self.node_map, dict(self.regions),
                       dict(self.boundaries), dict(self.interfaces))

    def facets_on_nodes(self, nodes: np.ndarray) -> np.ndarray:
        """Boundary facets of the thermal mesh whose two nodes are both in `nodes`."""
        mask = np.zeros(self.thermal.p.shape[1], dtype=bool)
        mask[np.asarray(nodes, dtype=np.int64)] = True
        bnd = self.thermal.boundary_facets()
        f = self.thermal.facets[:, bnd]
        return bnd[mask[f[0]] & mask[f[1]]]

    # ------------------------------------------------------------- constructors
    @classmethod
    def from_arrays(
        cls,
        points: np.ndarray,
        cells: np.ndarray,
        regions: Mapping[str, np.ndarray],
        lines: Mapping[str, np.ndarray] | None = None,
        interfaces: Iterable[str] = (),
    ) -> AxiMesh:
        """Build from raw arrays.

        points   (2, n_nodes) r, z in metres
        cells    (3, n_cells) node indices of linear triangles
        regions  name → cell indices
        lines    name → (2, n_edges) node pairs: boundaries, and interfaces if named in
                 `interfaces`
        """
        points = np.asarray(points, dtype=float)
        cells = np.asarray(cells, dtype=np.int64)
        if cells.ndim != 2 or cells.shape[0] != 3 or cells.shape[1] == 0:
            raise ValueError("mesh has no triangle cells")
        if points.ndim != 2 or points.shape[0] != 2:
            raise ValueError("points must have shape (2, n_nodes)")
        if cells.min() < 0 or cells.max() >= points.shape[1]:
            raise ValueError("cell refers to a node that does not exist")
        if np.any(points[0] < -1e-12 * max(1.0, np.abs(points[0]).max())):
            raise ValueError("axisymmetric mesh has nodes at negative radius")
        lines = dict(lines or {})
        interfaces = list(interfaces)
        for name in interfaces:
            if name not in lines:
                raise ValueError(f"unknown interface {name!r}: no such line group")

        # drop nodes no cell uses (gmsh keeps geometry points) and renumber
        used = np.unique(cells)
        renumber = -np.ones(points.shape[1], dtype=np.int64)
        renumber[used] = np.arange(used.size)
        points = points[:, used]
        cells = renumber[cells]
        for name, edges in lines.items():
            edges = renumber[np.asarray(edges, dtype=np.int64).reshape(2, -1)]
            if np.any(edges < 0):
                raise ValueError(f"line group {name!r} has nodes outside the triangle mesh")
            lines[name] = edges

        # Both meshes keep this vertex order per cell (sort_t=False): the thermal strain is
        # integrated with the temperature basis on one mesh and the displacement basis on
        # the other, so their quadrature points must coincide cell by cell.
        cells = np.ascontiguousarray(np.sort(cells, axis=0))
        points = np.ascontiguousarray(points)
        glued = MeshTri(points, cells, sort_t=False)
        n_glued = points.shape[1]
        g_keys = _facet_keys(glued.facets, n_glued)
        g_order = np.argsort(g_keys)
        g_sorted = g_keys[g_order]

        cell_region = np.full(cells.shape[1], "", dtype=object)
        region_sets: dict[str, np.ndarray] = {}
        for name, idx in regions.items():
            idx = np.unique(np.asarray(idx, dtype=np.int64))
            region_sets[name] = idx
            unset = cell_region[idx] == ""
            cell_region[idx[unset]] = name

        # split the nodes along every interface
        new_points = [points]
        new_cells = cells.copy()
        node_map = list(range(n_glued))
        split_info: dict[str, tuple[np.ndarray, tuple[str, str], np.ndarray]] = {}
        already_split = np.zeros(n_glued, dtype=bool)
        next_node = n_glued
        for name in interfaces:
            gf = _lookup(
                g_sorted, g_order, _facet_keys(lines[name], n_glued), f"interface {name!r}"
            )
            f2t = glued.f2t[:, gf]
            if np.any(f2t[1] < 0):
                raise ValueError(f"interface {name!r} lies on the outer boundary of the mesh")
            pair = sorted({str(r) for r in cell_region[f2t.ravel()]})
            if len(pair) != 2 or "" in pair:
                raise ValueError(
                    f"interface {name!r} must separate exactly two regions, found {pair}"
                )
            side_b = pair[1]
            nodes = np.unique(glued.facets[:, gf])
            if np.any(already_split[nodes]):
                raise ValueError(f"interface {name!r} shares nodes with another interface")
            already_split[nodes] = True
            copies = np.arange(next_node, next_node + nodes.size)
            next_node += nodes.size
            new_points.append(points[:, nodes])
            node_map.extend(nodes.tolist())
            # sized to every node so far: side-b cells may hold copies from an earlier split
            lookup = -np.ones(next_node, dtype=np.int64)
            lookup[nodes] = copies
            b_cells = np.where(cell_region == side_b)[0]
            sub = new_cells[:, b_cells]
            hit = lookup[sub] >= 0
            sub[hit] = lookup[sub[hit]]
            new_cells[:, b_cells] = sub
            split_info[name] = (gf, (pair[0], pair[1]), lookup)

        thermal = MeshTri(np.hstack(new_points), new_cells, sort_t=False) if interfaces else glued
        node_map_arr = np.asarray(node_map, dtype=np.int64)
        n_thermal = thermal.p.shape[1]
        t_keys = _facet_keys(thermal.facets, n_thermal)
        t_order = np.argsort(t_keys)
        t_sorted = t_keys[t_order]

        iface: dict[str, Interface] = {}
        for name, (gf, pair, lookup) in split_info.items():
            fa = glued.facets[:, gf]
            fb = lookup[fa]
            a = _lookup(t_sorted, t_order, _facet_keys(fa, n_thermal), f"interface {name!r}")
            b = _lookup(t_sorted, t_order, _facet_keys(fb, n_thermal), f"interface {name!r}")
            iface[name] = Interface(facets_a=a, facets_b=b, regions=pair)

        # boundary lines: each glued edge maps to the thermal facet(s) over it
        g_of_t = _facet_keys(node_map_arr[thermal.facets], n_glued)
        gt_order = np.argsort(g_of_t)
        gt_sorted = g_of_t[gt_order]
        boundaries: dict[str, np.ndarray] = {}
        for name, edges in lines.items():
            if name in split_info:
                continue
            keys = _facet_keys(edges, n_glued)
            lo = np.searchsorted(gt_sorted, keys, side="left")
            hi = np.searchsorted(gt_sorted, keys, side="right")
            if np.any(hi == lo):
                raise ValueError(
                    f"boundary {name!r}: {int(np.sum(hi == lo))} edges are not mesh edges"
                )
            found = np.concatenate([gt_order[s:e] for s, e in zip(lo, hi, strict=True)])
            boundaries[name] = np.unique(found)

        return cls(
            thermal=thermal,
            glued=glued,
            node_map=node_map_arr,
            regions=region_sets,
            boundaries=boundaries,
            interfaces=iface,
        )

    @classmethod
    def from_meshio(cls, mesh: meshio.Mesh, interfaces: Iterable[str] = (),
                    present_only: bool = False) -> AxiMesh:
        """Build from a meshio.Mesh with gmsh physical groups (2-D regions, 1-D lines);
        with `present_only`, the `interfaces` the mesh has no line group of are left out."""
        names = {(int(tag), int(dim)): name for name, (tag, dim) in mesh.field_data.items()}
        if present_only:
            interfaces = [n for n in interfaces if n in names.values()]
        phys = mesh.cell_data.get("gmsh:physical")
        if phys is None:
            raise ValueError("mesh has no gmsh physical groups")
        tri_blocks, regions, lines = [], {}, {}
        offset = 0
        for block, tags in zip(mesh.cells, phys, strict=True):
            if block.type == "triangle":
                tri_blocks.append(block.data.T)
                for tag in np.unique(tags):
                    name = names.get((int(tag), 2), f"region_{int(tag)}")
                    idx = offset + np.where(tags == tag)[0]
                    regions[name] = np.concatenate([regions.get(name, []), idx]).astype(np.int64)
                offset += block.data.shape[0]
            elif block.type == "line":
                for tag in np.unique(tags):
                    name = names.get((int(tag), 1), f"line_{int(tag)}")
                    edges = block.data[tags == tag].T
                    lines[name] = np.hstack([lines[name], edges]) if name in lines else edges
            elif block.type in ("triangle6", "quad", "line3"):
                raise ValueError(f"unsupported cell type {block.type!r}: mesh linear triangles")
        if not tri_blocks:
            raise ValueError("mesh has no triangle cells")
        return cls.from_arrays(
            mesh.points[:, :2].T, np.hstack(tri_blocks), regions, lines, interfaces
        )

    @classmethod
    def from_msh(cls, path: str | Path, interfaces: Iterable[str] = (),
                 present_only: bool = False) -> AxiMesh:
        """Read a gmsh .msh file (physical groups name regions, boundaries, interfaces;
        `present_only` as in `from_meshio`)."""
        import meshio

        # meshio's gmsh reader prints to stdout (a bare newline for our files), which would
        # end up in the output of `twin synth --quiet` and of pipes; keep it for the log
        captured = io.StringIO()
        with contextlib.redirect_stdout(captured), contextlib.redirect_stderr(captured):
            try:
                mesh = meshio.read(str(path))
            except (Exception, SystemExit) as exc:  # noqa: BLE001 - meshio's parsers fail in
                # many types (IndexError on a cut-short file) and exit on a file no reader
                # takes: a file that is not a mesh is bad input
                reason = " ".join(captured.getvalue().split()) or f"{type(exc).__name__}: {exc}"
                raise ValueError(f"not a readable gmsh mesh ({reason})") from None
        if captured.getvalue().strip():
            logging.getLogger(__name__).info("meshio: %s", captured.getvalue().strip())
        return cls.from_meshio(mesh, interfaces, present_only)

    @classmethod
    def structured(
        cls,
        r_edges: np.ndarray,
        z_edges: np.ndarray,
        regions: Mapping[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] | None = None,
        boundaries: Mapping[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] | None = None,
        interfaces: Mapping[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] | None = None,
    ) -> AxiMesh:
        """Tensor-product triangle mesh for verification problems and simple decks.

        regions     name → predicate(r, z) on cell centroids (default: one region "body")
        boundaries  name → predicate(r, z) on midpoints of outer-boundary facets
        interfaces  name → predicate(r, z) on midpoints of interior facets
        """
        base = MeshTri.init_tensor(np.asarray(r_edges, float), np.asarray(z_edges, float))
        centroid = base.p[:, base.t].mean(axis=1)
        region_sets = {
            name: np.where(pred(centroid[0], centroid[1]))[0]
            for name, pred in (regions or {"body": lambda r, z: np.ones_like(r, bool)}).items()
        }
        mid = base.p[:, base.facets].mean(axis=1)
        outer = base.boundary_facets()
        inner = np.where(base.f2t[1] >= 0)[0]
        lines = {}
        for name, pred in (boundaries or {}).items():
            sel = outer[pred(mid[0, outer], mid[1, outer])]
            lines[name] = base.facets[:, sel]
        for name, pred in (interfaces or {}).items():
            sel = inner[pred(mid[0, inner], mid[1, inner])]
            lines[name] = base.facets[:, sel]
        return cls.from_arrays(base.p, base.t, region_sets, lines, list(interfaces or {}))
