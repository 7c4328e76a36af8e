"""2-D heat conduction on a deck's own mesh: PLANE35/55/77 as MAPDL solves them.

The elements are scikit-fem's native ones: a 4-node quad is the bilinear quad
(`ElementQuad1`), a triangle (K = L) the collapsed quad whose shape functions are read at
interior Gauss points only; an 8-node PLANE77 is the serendipity quad (`ElementQuadS2`); a
model of only 6-node triangles (PLANE35, or PLANE77 with K = L = O) runs on P2 triangles.
Mid-side nodes carry the edge dofs; the geometry is straight-sided.

Linear elements (PLANE55) diagonalize their specific heat and convection surface matrices
(row sums), as MAPDL's PLANE55 does; quadratic ones keep them consistent.

Planar (KEYOPT(3) = 0, unit thickness) or axisymmetric (KEYOPT(3) = 1: x is the radius,
every integral carries 2πr, so reaction heats are for the full circumference as MAPDL
reports them).  Conductivity may be orthotropic (KXX, KYY in the global axes) and, like ρ
and c, depend on temperature (MP with C1..C4, or MPTEMP/MPDATA tables).

Nonlinear problems (k, ρc depending on T) are solved by Picard iteration: the operators are
assembled at the last iterate until it converges (`twin.fem.stepper.picard`): until the
largest nodal change of an iterate is at most 1e-8 × (1 + max |T|) °C (PICARD_TOLERANCE),
in at most 200 iterations (PICARD_ITERATIONS), else the SOLVE stops with a located error.
Steady and every transient substep iterate alike (MAPDL's NEQIT/CNVTOL are not read).

Transient load steps use twin.fem's θ-method (`twin.fem.stepper.theta_step`, `march_to`;
TINTP sets θ, 1 backward Euler by default).  With AUTOTS the first substep is DELTIM's
DTIME (or the span / NSBSTP), as MAPDL takes it; each next size is predicted from a
step-doubling estimate of the last step's local error (against `STEP_TOLERANCE` × the
temperature range of the problem: its start and loads, or the range its temperatures have
reached when wider, as in a heat-driven rise), growing at most 3× a step, between DTMIN
and DTMAX; a later substep is bisected when its estimate exceeds twice that or its Picard
iteration does not converge; the substeps land on the load step's end.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import (
    Basis,
    BilinearForm,
    ElementQuad1,
    ElementQuadS2,
    ElementTriP1,
    ElementTriP2,
    FacetBasis,
    LinearForm,
    MeshQuad1,
    MeshTri1,
)

from apdl_like.errors import ApdlError
from apdl_like.line_thermal import ThermalLinks
from apdl_like.model import PAIR_BASE, pair_keys
from twin.fem.stepper import (
    StepControl,
    SteppingError,
    ThetaSystem,
    march_to,
    picard,
    theta_step,
)

if TYPE_CHECKING:
    from skfem import DiscreteField
    from skfem.assembly.form.form import FormExtraParams

STEP_TOLERANCE = 1e-5

# k(T) [W/mK] etc. from temperature at quadrature points
Property = Callable[[np.ndarray], np.ndarray]


def row_sum_lumped(matrix: sp.spmatrix) -> sp.dia_matrix:
    """The row-sum diagonal of a capacity or film matrix: how MAPDL's linear thermal
    elements diagonalize them."""
    return sp.diags(np.asarray(matrix.sum(axis=1)).ravel())


@dataclass
class Part:
    """The elements of one shape (quads or triangles) as a scikit-fem basis."""

    basis: Basis
    to_global: sp.csr_matrix  # (n_global, n_local) selection: global = to_global @ local
    local_dofs: np.ndarray  # local dof -> global dof
    elements: np.ndarray  # cell -> element index of the deck's element table
    facet_keys: np.ndarray  # mesh facet -> packed corner node-number pair


@dataclass
class PlaneMesh:
    """A deck's elements as scikit-fem parts (quads, triangles) sharing one dof numbering.

    Global dofs: the corner nodes, then (quadratic) one per element edge; a mid-side node
    is the dof of its edge.
    """

    parts: list[Part]
    n_dofs: int
    node_dof: np.ndarray  # node index -> dof, -1 for nodes outside the elements
    axisymmetric: bool
    lumped: bool  # linear elements: MAPDL diagonalizes their specific heat matrix

    def nodal(self, T: np.ndarray) -> np.ndarray:
        """Per-node values (NaN outside the elements)."""
        out = np.full(self.node_dof.size, np.nan)
        ok = self.node_dof >= 0
        out[ok] = T[self.node_dof[ok]]
        return out


def build_mesh(xy: np.ndarray, node_ids: np.ndarray, corners: np.ndarray,
               midside: np.ndarray | None, axisymmetric: bool,
               solid: np.ndarray | None = None,
               point_nodes: np.ndarray | None = None) -> PlaneMesh:
    """corners (m, 4) node indices (K = L for a triangle); midside (m, 4) node indices of
    the mid-side nodes I-J, J-K, K-L, L-I (-1 none) for quadratic elements, else None;
    solid (m,) the elements to mesh (default all); point_nodes the nodes of line and point
    elements (`apdl_like.line_thermal`), which get a dof too."""
    solid = np.ones(corners.shape[0], bool) if solid is None else solid
    vertex_node = np.unique(corners[solid])
    if axisymmetric and vertex_node.size:
        x = xy[vertex_node, 0]
        if np.any(x < -1e-9 * max(1.0, float(np.abs(xy[vertex_node]).max()))):
            bad = node_ids[vertex_node[np.argmin(x)]]
            raise ApdlError(f"node {bad} lies at negative X (radius) in an axisymmetric model")
    node_dof = np.full(len(node_ids), -1, np.int64)
    node_dof[vertex_node] = np.arange(vertex_node.size)
    n_global = vertex_node.size
    edge_dof: dict[int, int] = {}
    tri = corners[:, 2] == corners[:, 3]
    parts = []
    for is_tri in (False, True):
        elements = np.nonzero((tri == is_tri) & solid)[0]
        if not elements.size:
            continue
        part_corners = corners[elements][:, :3] if is_tri else corners[elements]
        part_mid = None if midside is None else midside[elements]
        part, n_global = _part(xy, node_ids, node_dof, part_corners, part_mid, elements,
                               is_tri, edge_dof, n_global)
        parts.append(part)
    if point_nodes is not None:
        extra = np.setdiff1d(point_nodes, np.nonzero(node_dof >= 0)[0])
        node_dof[extra] = n_global + np.arange(extra.size)
        n_global += extra.size
    for part in parts:
        part.to_global = sp.csr_matrix(
            (np.ones(part.local_dofs.size), (part.local_dofs, np.arange(part.local_dofs.size))),
            shape=(n_global, part.local_dofs.size))
    return PlaneMesh(parts, n_global, node_dof, axisymmetric, midside is None)


def _part(xy: np.ndarray, node_ids: np.ndarray, node_dof: np.ndarray, corners: np.ndarray,
          midside: np.ndarray | None, elements: np.ndarray, is_tri: bool,
          edge_dof: dict[int, int], n_global: int) -> tuple[Part, int]:
    vertex_node = np.unique(corners)
    vertex_of = np.full(len(node_ids), -1, np.int64)
    vertex_of[vertex_node] = np.arange(vertex_node.size)
    p = xy[vertex_node].T
    t = vertex_of[corners].T.copy()
    # counter-clockwise cells: the signed area of the corner polygon, in coordinates scaled
    # to the model's extent (so that 1e300-sized models neither overflow nor lose the sign)
    extent = max(float(np.ptp(p, axis=1).max()), 1e-300)
    if extent > 1e150:  # areas and Jacobians (lengths squared) would overflow in float64
        raise ApdlError(f"node coordinates out of range: the model spans {extent:.3g} "
                        "(areas overflow)")
    x = (p[0][t] - p[0].min()) / extent
    y = (p[1][t] - p[1].min()) / extent
    area2 = (x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y).sum(axis=0)
    if np.any(np.abs(area2) <= 1e-12):
        bad = int(node_ids[corners[int(np.argmin(np.abs(area2))), 0]])
        raise ApdlError(f"an element at node {bad} has zero area (check its node order and "
                        "coordinates)")
    if not is_tri:
        # a bilinear quad's Jacobian keeps its sign only where every corner turns the way
        # of the whole: a re-entrant or crossed quad (a node moved after meshing) passed the
        # area check and failed in scikit-fem's inverse mapping, an internal error
        turn = ((np.roll(x, -1, axis=0) - x) * (np.roll(y, 1, axis=0) - y)
                - (np.roll(y, -1, axis=0) - y) * (np.roll(x, 1, axis=0) - x))
        bent = np.any(turn * np.sign(area2) < -1e-12, axis=0)
        if np.any(bent):
            bad = int(node_ids[corners[int(np.argmax(bent)), 0]])
            raise ApdlError(f"an element at node {bad} is not convex (its Jacobian changes "
                            "sign; check its node order and coordinates)")
    flip = area2 < 0
    t[:, flip] = t[::-1][:, flip]
    if is_tri:
        mesh = MeshTri1(p, t, validate=False, sort_t=False)
        element = ElementTriP2() if midside is not None else ElementTriP1()
    else:
        mesh = MeshQuad1(p, t, validate=False, sort_t=False)
        element = ElementQuadS2() if midside is not None else ElementQuad1()
    basis = Basis(mesh, element)
    local = np.full(basis.N, -1, np.int64)
    local[basis.nodal_dofs[0]] = node_dof[vertex_node]
    facet_keys = pair_keys(node_ids[vertex_node[mesh.facets[0]]],
                           node_ids[vertex_node[mesh.facets[1]]])
    if midside is not None:
        for f, key in enumerate(facet_keys.tolist()):
            dof = edge_dof.get(key)
            if dof is None:
                dof = edge_dof[key] = n_global
                n_global += 1
            local[basis.facet_dofs[0, f]] = dof
        # the mid-side nodes: the dofs of their edges, found by the corner pair
        edges = ((0, 1, 0), (1, 2, 1), (2, 0, 3)) if is_tri else \
            ((0, 1, 0), (1, 2, 1), (2, 3, 2), (3, 0, 3))
        for i, j, col in edges:
            has = midside[:, col] >= 0
            keys = pair_keys(node_ids[corners[has, i]], node_ids[corners[has, j]])
            for node, key in zip(midside[has, col].tolist(), keys.tolist(), strict=True):
                dof = edge_dof.get(key)
                if dof is None:
                    raise ApdlError(f"mid-side node {int(node_ids[node])} does not sit on an "
                                    "element edge")
                node_dof[node] = dof
    if np.any(local < 0):
        raise ApdlError("internal numbering error of the element dofs")  # pragma: no cover
    placeholder = sp.csr_matrix((0, 0))
    return Part(basis, placeholder, local, elements, facet_keys), n_global


def _refuse_zero_length(part: Part, facets: np.ndarray) -> None:
    """A face load needs faces of some length: two distinct nodes at one point (an element
    edge I-J of zero length) have no facet map to integrate it on."""
    mesh = part.basis.mesh
    ends = mesh.p[:, mesh.facets[:, facets]]  # (2 coordinates, 2 ends, n)
    length = np.hypot(*(ends[:, 1] - ends[:, 0]))
    extent = max(float(np.ptp(mesh.p, axis=1).max()), 1e-300)
    if np.any(length <= 1e-12 * extent):
        key = int(part.facet_keys[facets[int(np.argmin(length))]])
        raise ApdlError(f"a face load on the edge of nodes {key // int(PAIR_BASE)} and "
                        f"{key % int(PAIR_BASE)}, which lie at one point (zero length)")


# ----------------------------------------------------------------- the forms
def _radius(w: FormExtraParams) -> np.ndarray:
    return 2.0 * np.pi * w.x[0] if w.axisymmetric else np.ones_like(w.x[0])


@BilinearForm
def conduction(u: DiscreteField, v: DiscreteField, w: FormExtraParams) -> np.ndarray:
    """∫ (kxx ∂u/∂x ∂v/∂x + kyy ∂u/∂y ∂v/∂y) dV."""
    return (w.kxx * u.grad[0] * v.grad[0] + w.kyy * u.grad[1] * v.grad[1]) * _radius(w)


@BilinearForm
def mass(u: DiscreteField, v: DiscreteField, w: FormExtraParams) -> np.ndarray:
    """∫ c u v dV: the capacity on cells (c = ρc, J/(m³·K)), a film on faces (c = h)."""
    return w.c * u * v * _radius(w)


@LinearForm
def load(v: DiscreteField, w: FormExtraParams) -> np.ndarray:
    """∫ g v dV: a source on cells (g = HGEN, W/m³), on faces h·T_bulk or a heat flux."""
    return w.g * v * _radius(w)


@dataclass
class ThermalInputs:
    """One load state of the model on a `PlaneMesh` (see apdl_like.plane_solve).

    kxx, kyy, rho_c  per material number: property(T at quadrature points) callables
    hgen             per element of the deck's table, W/m³
    films            (face keys, h W/m²K, T_bulk °C) groups; keys: packed corner node numbers
    fluxes           (face keys, q W/m²) groups
    fixed            (dofs, values °C)
    nodal_heat       (dofs, heat flows W) of F,,HEAT, or None
    nodal_hgen       per dof the nodal heat generation rate of BF,Node,HGEN (W/m³; 0:
                     none), or None.  As MAPDL documents it, the rate "is multiplied by
                     the weighted nodal volume of each element adjacent to that node": the
                     node's load is q_n · Σ_e ∫_e N_n dV (N_n its shape function; 2πr dA in
                     an axisymmetric model), so a uniform rate loads as BFE does
    hf, specific_heat  per material MP,HF and MP,C callables (or None), for the links
    enthalpy         per material H(T) J/m³ (MPDATA,ENTH) or None: a transient step's
                     capacity is then the secant (H(T1) − H(T0)) / (T1 − T0), so a step
                     across a phase change takes in exactly its latent heat
    """

    kxx: list[Property]
    kyy: list[Property]
    rho_c: list[Property]
    hgen: np.ndarray
    films: list[tuple[np.ndarray, float, float]]
    fluxes: list[tuple[np.ndarray, float]]
    fixed: tuple[np.ndarray, np.ndarray]
    enthalpy: list[Property | None] | None = None
    hf: list[Property | None] | None = None
    specific_heat: list[Property | None] | None = None
    nodal_heat: tuple[np.ndarray, np.ndarray] | None = None
    nodal_hgen: np.ndarray | None = None


def weighted_nodal_volume(b: Basis, axisymmetric: bool) -> np.ndarray:
    """∫ N_i dV over the cells of `b`, per local dof (the weights of a nodal HGEN)."""
    return load.assemble(b, g=np.ones((b.nelems, b.X.shape[-1])), axisymmetric=axisymmetric)


class PlaneThermal:
    """Assembly and solves on one `PlaneMesh` with per-element material numbers."""

    def __init__(self, mesh: PlaneMesh, element_material: np.ndarray,
                 couplings: list[np.ndarray], links: ThermalLinks | None = None) -> None:
        self.mesh = mesh
        self.links = links if links is not None and links.size else None
        self.groups = []  # per part: material -> cells
        for part in mesh.parts:
            mats = element_material[part.elements]
            self.groups.append({int(m): np.nonzero(mats == m)[0] for m in np.unique(mats)})
        self._facet_bases: dict[tuple[int, bytes], FacetBasis] = {}
        self._reduce = coupling_map(mesh.n_dofs, couplings)
        self._linear_cache: tuple[ThermalInputs, tuple] | None = None

    # ---------------------------------------------------------------- pieces
    def _cell_field(self, k: int, props: list[Property], T_local: np.ndarray) -> np.ndarray:
        """A per-cell property at the quadrature points of part k, at temperature T."""
        Tq = np.asarray(self.mesh.parts[k].basis.interpolate(T_local))
        out = np.empty_like(Tq)
        for m, cells in self.groups[k].items():
            out[cells] = props[m](Tq[cells])
        return out

    def secant_capacity(self, inputs: ThermalInputs, T0: np.ndarray,
                        T1: np.ndarray) -> sp.csr_matrix:
        """The capacity matrix of a step T0 -> T1 with (H(T1) − H(T0)) / (T1 − T0) at each
        quadrature point where the material has an enthalpy table, ρc(T1) elsewhere and
        where the point's temperature does not change."""
        n = self.mesh.n_dofs
        C = sp.csr_matrix((n, n))
        ax = self.mesh.axisymmetric
        for k, part in enumerate(self.mesh.parts):
            b = part.basis
            T0q = np.asarray(b.interpolate(T0[part.local_dofs]))
            T1q = np.asarray(b.interpolate(T1[part.local_dofs]))
            c = np.empty_like(T1q)
            for m, cells in self.groups[k].items():
                a, z = T0q[cells], T1q[cells]
                c[cells] = inputs.rho_c[m](z)
                H = inputs.enthalpy[m] if inputs.enthalpy is not None else None
                if H is not None:
                    dT = z - a
                    moved = np.abs(dT) > 1e-12 * (1.0 + np.abs(z))
                    sec = (H(z) - H(a)) / np.where(moved, dT, 1.0)
                    c[cells] = np.where(moved, sec, c[cells])
            C = C + part.to_global @ mass.assemble(b, c=c, axisymmetric=ax) @ part.to_global.T
        if self.mesh.lumped:
            C = row_sum_lumped(C)
        if self.links is not None:
            C = C + self.links.capacity(T1, inputs.rho_c, inputs.specific_heat or [], n)
        return C.tocsr()

    def operators(self, inputs: ThermalInputs, T: np.ndarray,
                  nonlinear: bool = True) -> ThetaSystem:
        """(K conduction + films, C capacity, f loads) at temperature T.

        Without temperature dependence they are assembled once per `inputs` object."""
        cached = self._linear_cache
        if not nonlinear and cached is not None and cached[0] is inputs:
            return cached[1]  # type: ignore[return-value]
        ax = self.mesh.axisymmetric
        n = self.mesh.n_dofs
        K = sp.csr_matrix((n, n))
        C = sp.csr_matrix((n, n))
        f = np.zeros(n)
        for k, part in enumerate(self.mesh.parts):
            b, S = part.basis, part.to_global
            T_local = T[part.local_dofs]
            Kp = conduction.assemble(b, kxx=self._cell_field(k, inputs.kxx, T_local),
                                     kyy=self._cell_field(k, inputs.kyy, T_local),
                                     axisymmetric=ax)
            Cp = mass.assemble(b, c=self._cell_field(k, inputs.rho_c, T_local),
                                   axisymmetric=ax)
            K = K + S @ Kp @ S.T
            C = C + S @ Cp @ S.T
            q = inputs.hgen[part.elements]
            if np.any(q):
                qq = np.repeat(q[:, None], b.X.shape[-1], axis=1)
                f = f + S @ load.assemble(b, g=qq, axisymmetric=ax)
            if inputs.nodal_hgen is not None:
                f = f + S @ (weighted_nodal_volume(b, ax) * inputs.nodal_hgen[part.local_dofs])
            for keys, h, tb in inputs.films:
                fb = self._facet_basis(k, keys)
                if fb is not None:
                    Hf = mass.assemble(fb, c=h, axisymmetric=ax)
                    if self.mesh.lumped:
                        Hf = row_sum_lumped(Hf)
                    K = K + S @ Hf @ S.T
                    f = f + S @ load.assemble(fb, g=h * tb, axisymmetric=ax)
            for keys, flux in inputs.fluxes:
                fb = self._facet_basis(k, keys)
                if fb is not None:
                    f = f + S @ load.assemble(fb, g=flux, axisymmetric=ax)
        if inputs.nodal_heat is not None:
            f = f + np.bincount(inputs.nodal_heat[0], inputs.nodal_heat[1], minlength=n)
        if self.mesh.lumped:
            C = row_sum_lumped(C).tocsr()
        if self.links is not None:
            K = K + self.links.stiffness(T, inputs.kxx, inputs.hf or [], n)
            C = C + self.links.capacity(T, inputs.rho_c, inputs.specific_heat or [], n)
            f = f + self.links.heat_load(inputs.hgen, n)
        out = ThetaSystem(K.tocsr(), C.tocsr(), f)
        if not nonlinear:
            self._linear_cache = (inputs, out)
        return out

    def _facet_basis(self, k: int, keys: np.ndarray) -> FacetBasis | None:
        """The facets of part k with these node-pair keys (None if it has none)."""
        cache_key = (k, np.ascontiguousarray(keys).tobytes())
        if cache_key not in self._facet_bases:
            part = self.mesh.parts[k]
            facets = np.nonzero(np.isin(part.facet_keys, keys))[0]
            _refuse_zero_length(part, facets)
            self._facet_bases[cache_key] = FacetBasis(part.basis.mesh, part.basis.elem,
                                                      facets=facets) if facets.size else None
        return self._facet_bases[cache_key]

    def _solve(self, A: sp.csr_matrix, rhs: np.ndarray,
               fixed: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        x = solve_constrained(A, rhs, fixed, self._reduce)
        if not np.all(np.isfinite(x)):
            raise ApdlError("the thermal system is singular: fix a temperature (D,,TEMP) "
                            "or add convection (SF,,CONV)")
        return x

    # ---------------------------------------------------------------- solves
    def steady(self, inputs: ThermalInputs, T0: np.ndarray, nonlinear: bool) -> np.ndarray:
        """K(T) T = f(T), Picard iteration from T0 when properties depend on T."""

        def update(T: np.ndarray) -> np.ndarray:
            K, _, f = self.operators(inputs, T, nonlinear)
            return self._solve(K, f, inputs.fixed)

        try:
            return picard(update, T0, nonlinear)
        except SteppingError as exc:
            raise ApdlError(f"the nonlinear thermal solve {exc}") from None

    def step(self, inputs_old: ThermalInputs, inputs_new: ThermalInputs, T: np.ndarray,
             dt: float, theta: float, nonlinear: bool) -> np.ndarray:
        """One θ-step: (C/dt + θK1) T1 = (C/dt − (1−θ)K0) T0 + θ f1 + (1−θ) f0."""
        start = self.operators(inputs_old, T, nonlinear)

        def end_at(T1: np.ndarray) -> ThetaSystem:
            if nonlinear or inputs_new is not inputs_old:
                return self.operators(inputs_new, T1, nonlinear)
            return start

        def solve(A: sp.csr_matrix, rhs: np.ndarray) -> np.ndarray:
            return self._solve(A, rhs, inputs_new.fixed)

        capacity = None if inputs_new.enthalpy is None else \
            (lambda T1: self.secant_capacity(inputs_new, T, T1))
        # a SteppingError (Picard not converging) goes to `march`, which bisects the step
        return theta_step(T, dt, theta, start, end_at, solve, nonlinear, capacity)

    def element_heat(self, inputs: ThermalInputs, T: np.ndarray,
                     elements: int | np.ndarray) -> np.ndarray:
        """Heat flow (W) at the global dofs of some elements (indices of the deck's element
        table), summed over them, steady: their conduction and film matrices times T less
        their loads; the sum over the elements at a node with a fixed temperature is that
        node's reaction heat."""
        wanted = np.atleast_1d(np.asarray(elements, np.int64))
        out = np.zeros(self.mesh.n_dofs)
        found = np.zeros(wanted.size, bool)
        for k, part in enumerate(self.mesh.parts):
            cells = np.nonzero(np.isin(part.elements, wanted))[0]
            found |= np.isin(wanted, part.elements)
            if cells.size:
                out += part.to_global @ self._cells_heat(k, inputs, T, cells)
        if self.links is not None:
            which = np.isin(self.links.elements, wanted)
            found |= np.isin(wanted, self.links.elements)
            if which.any():
                out += self.links.nodal_heat(T, inputs.kxx, inputs.hf or [], inputs.hgen,
                                             which, self.mesh.n_dofs)
        if not found.all():
            raise ApdlError("the element is not part of the thermal mesh")
        return out

    def _cells_heat(self, k: int, inputs: ThermalInputs, T: np.ndarray,
                    cells: np.ndarray) -> np.ndarray:
        """Local-dof heat flow of some cells of part k (see `element_heat`)."""
        part = self.mesh.parts[k]
        ax = self.mesh.axisymmetric
        b = Basis(part.basis.mesh, part.basis.elem, elements=cells)
        T_local = T[part.local_dofs]
        mats = {m: np.nonzero(np.isin(cells, c))[0] for m, c in self.groups[k].items()}
        Tq = np.asarray(b.interpolate(T_local))

        def field(props: list[Property]) -> np.ndarray:
            out = np.empty_like(Tq)
            for m, idx in mats.items():
                out[idx] = props[m](Tq[idx])
            return out

        r = conduction.assemble(b, kxx=field(inputs.kxx), kyy=field(inputs.kyy),
                                axisymmetric=ax) @ T_local
        q = inputs.hgen[part.elements[cells]]
        if np.any(q):
            r = r - load.assemble(b, g=np.repeat(q[:, None], b.X.shape[-1], axis=1),
                                    axisymmetric=ax)
        if inputs.nodal_hgen is not None:
            r = r - weighted_nodal_volume(b, ax) * inputs.nodal_hgen[part.local_dofs]
        own = part.basis.mesh.t2f[:, cells].ravel()
        for keys, h, tb in inputs.films:
            facets = own[np.isin(part.facet_keys[own], keys)]
            if facets.size:
                fb = FacetBasis(part.basis.mesh, part.basis.elem, facets=facets)
                H = mass.assemble(fb, c=h, axisymmetric=ax)
                if self.mesh.lumped:
                    H = row_sum_lumped(H)
                r = r + H @ T_local - load.assemble(fb, g=h * tb, axisymmetric=ax)
        for keys, flux in inputs.fluxes:
            facets = own[np.isin(part.facet_keys[own], keys)]
            if facets.size:
                fb = FacetBasis(part.basis.mesh, part.basis.elem, facets=facets)
                r = r - load.assemble(fb, g=flux, axisymmetric=ax)
        return r

    def centroid_gradient(self, inputs: ThermalInputs, T: np.ndarray,
                          n_elements: int) -> tuple[np.ndarray, np.ndarray]:
        """Per element of the deck's table (n_elements rows; NaN outside the plane mesh) the
        temperature gradient ∇T (°C/m) and the heat flux −(KXX ∂T/∂x, KYY ∂T/∂y) (W/m², k at
        the centroid's temperature) at the element centroid: MAPDL's TG and TF items."""
        grad = np.full((n_elements, 2), np.nan)
        flux = np.full((n_elements, 2), np.nan)
        for k, part in enumerate(self.mesh.parts):
            tri = isinstance(part.basis.mesh, MeshTri1)
            centroid = np.full((2, 1), 1.0 / 3.0 if tri else 0.5)  # reference cells: [0,1]²
            b = Basis(part.basis.mesh, part.basis.elem, quadrature=(centroid, np.ones(1)))
            u = b.interpolate(T[part.local_dofs])
            g = u.grad[:, :, 0].T  # (cells, 2)
            grad[part.elements] = g
            for m, cells in self.groups[k].items():
                Tc = np.asarray(u)[cells]  # (cells, 1): the properties take quadrature-point arrays
                kx = np.broadcast_to(inputs.kxx[m](Tc), Tc.shape)[:, 0]
                ky = np.broadcast_to(inputs.kyy[m](Tc), Tc.shape)[:, 0]
                flux[part.elements[cells]] = -np.column_stack([kx * g[cells, 0],
                                                               ky * g[cells, 1]])
        return grad, flux

    def element_volume(self, n_elements: int) -> np.ndarray:
        """Per element of the deck's table (n_elements rows) its volume, MAPDL's ETABLE item
        VOLU: the area times unit thickness in a planar model, ∫ 2πr dA (the full 360°) in
        an axisymmetric one; A·L of a LINK32/33 bar (its area is on the full 360° already);
        NaN for the elements without one (LINK31/34, MASS71, SURF151)."""
        volume = np.full(n_elements, np.nan)
        for part in self.mesh.parts:
            b = part.basis
            dx = np.asarray(b.dx)  # |det J| × weights: (cells, quadrature points)
            if self.mesh.axisymmetric:
                dx = dx * 2.0 * np.pi * np.asarray(b.global_coordinates().value[0])
            volume[part.elements] = dx.sum(axis=1)
        links = self.links
        if links is not None:
            bars = links.kind == "conduction"
            volume[links.elements[bars]] = links.area[bars] * links.length[bars]
        return volume

    def film_heat(self, inputs: ThermalInputs, T: np.ndarray, keys: np.ndarray) -> np.ndarray:
        """Per exterior face (node-pair key) the heat its film takes out of the model,
        ∫ h (T − T_bulk) dA (W; consistent integral, 2πr in an axisymmetric model); 0 on a
        face without a film."""
        out = np.zeros(keys.size)
        ax = self.mesh.axisymmetric
        for part in self.mesh.parts:
            T_local = T[part.local_dofs]
            for group_keys, h, tb in inputs.films:
                for n in np.nonzero(np.isin(keys, group_keys))[0]:
                    facets = np.nonzero(part.facet_keys == keys[n])[0]
                    if not facets.size:
                        continue
                    fb = FacetBasis(part.basis.mesh, part.basis.elem, facets=facets[:1])
                    H = mass.assemble(fb, c=h, axisymmetric=ax)
                    out[n] += float((H @ T_local).sum()
                                    - load.assemble(fb, g=h * tb, axisymmetric=ax).sum())
        return out

    def reaction(self, inputs: ThermalInputs, T: np.ndarray) -> np.ndarray:
        """Heat flow into the model at each dof (W; nonzero at fixed temperatures), steady."""
        K, _, f = self.operators(inputs, T, nonlinear=True)
        return K @ T - f


def solve_constrained(A: sp.csr_matrix, rhs: np.ndarray, fixed: tuple[np.ndarray, np.ndarray],
                      P: sp.csr_matrix) -> np.ndarray:
    """A x = rhs with fixed dofs and coupled sets (P: each set shares one unknown)."""
    Ar = (P.T @ A @ P).tocsr()
    br = P.T @ rhs
    n = Ar.shape[0]
    x = np.zeros(n)
    dofs, values = fixed
    rdofs = P[dofs].indices if len(dofs) else np.zeros(0, np.int64)
    if rdofs.size:
        x[rdofs] = values
    free = np.ones(n, bool)
    free[rdofs] = False
    if free.any():
        rhs_free = br[free] - Ar[free][:, ~free] @ x[~free]
        try:
            # SuperLU reports an exactly singular matrix either way: raise or warn and
            # return NaN; the warning would reach the user's console before the error
            with warnings.catch_warnings():
                warnings.simplefilter("error", spla.MatrixRankWarning)
                x[free] = spla.spsolve(Ar[free][:, free].tocsc(), rhs_free)
        except (RuntimeError, spla.MatrixRankWarning):
            x[free] = np.nan  # singular: the caller names what is missing
    return P @ x


def coupling_map(n: int, couplings: list[np.ndarray]) -> sp.csr_matrix:
    """P (n × n_reduced): the dofs of a coupled set share one column."""
    rep = np.arange(n)
    for dofs in couplings:
        dofs = dofs[dofs >= 0]
        if dofs.size > 1:
            rep[dofs] = rep[dofs].min()
    # resolve chains (a set touching another set)
    for _ in range(n):
        nxt = rep[rep]
        if np.array_equal(nxt, rep):
            break
        rep = nxt
    unique, column = np.unique(rep, return_inverse=True)
    return sp.csr_matrix((np.ones(n), (np.arange(n), column.ravel())), shape=(n, unique.size))


def march(model: PlaneThermal, inputs_at: Callable[[float], ThermalInputs], T0: np.ndarray,
          t0: float, t1: float, dt: float, theta: float, nonlinear: bool,
          adaptive: bool, dt_min: float, dt_max: float,
          scale: float) -> tuple[list[float], list[np.ndarray]]:
    """Substeps from t0 to t1: fixed `dt` (the last one shortened to land on t1) or, with
    `adaptive`, a first substep of `dt` and then sizes predicted from a step-doubling error
    estimate, bisected when it is too large, within [dt_min, dt_max]
    (`twin.fem.stepper.march_to`; `scale`, °C, the range the start and loads span)."""
    inputs_at = functools.lru_cache(maxsize=4)(inputs_at)  # a half step's end starts the next

    def step(T: np.ndarray, t: float, t_next: float, h: float) -> np.ndarray:
        return model.step(inputs_at(t), inputs_at(t_next), T, h, theta, nonlinear)

    control = StepControl(dt_min, dt_max, STEP_TOLERANCE, scale) if adaptive else None
    try:
        return march_to(step, T0, t0, t1, dt, control)
    except SteppingError as exc:
        raise ApdlError(f"the transient thermal load step: {exc}") from None
