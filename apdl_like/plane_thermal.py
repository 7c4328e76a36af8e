"""2-D heat conduction on a deck's own mesh: PLANE35/55/77 as MAPDL solves them.

The elements are scikit-fem's native ones: a 4-node quad is the bilinear quad
(`ElementQuad1`), a triangle (K = L) the collapsed quad whose shape functions are read at
interior Gauss points only; an 8-node PLANE77 is the serendipity quad (`ElementQuadS2`); a
model of only 6-node triangles (PLANE35, or PLANE77 with K = L = O) runs on P2 triangles.
Mid-side nodes carry the edge dofs; the geometry is straight-sided.

Planar (KEYOPT(3) = 0, unit thickness) or axisymmetric (KEYOPT(3) = 1: x is the radius,
every integral carries 2πr, so reaction heats are for the full circumference as MAPDL
reports them).  Conductivity may be orthotropic (KXX, KYY in the global axes) and, like ρ
and c, depend on temperature (MP with C1..C4, or MPTEMP/MPDATA tables).

Nonlinear problems (k, ρc depending on T) are solved by Picard iteration: the operators are
assembled at the last iterate until the largest temperature change is at most
`PICARD_TOLERANCE` × (1 + the largest |T|); at most `PICARD_ITERATIONS` iterations.

Transient load steps use the θ-method (TINTP; θ = 1 backward Euler by default).  With
AUTOTS the step size follows a step-doubling estimate of the local error (at most
`STEP_TOLERANCE` × the temperature scale of the problem), between DTMIN and DTMAX.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

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

PICARD_TOLERANCE = 1e-8
PICARD_ITERATIONS = 200
STEP_TOLERANCE = 1e-4
MAX_SUBSTEPS = 200_000
PAIR_BASE = np.int64(1) << 31

# k(T) [W/mK] etc. from temperature at quadrature points
Property = Callable[[np.ndarray], np.ndarray]


def pair_keys(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    lo, hi = np.minimum(a, b).astype(np.int64), np.maximum(a, b).astype(np.int64)
    return lo * PAIR_BASE + hi


@dataclass
class PlaneMesh:
    """The scikit-fem view of a deck's elements and the node -> dof map."""

    basis: Basis
    node_dof: np.ndarray  # node index -> dof, -1 for nodes outside the elements
    cell_element: np.ndarray  # cell -> element index
    vertex_node: np.ndarray  # mesh vertex -> node index
    facet_keys: np.ndarray  # mesh facet -> packed corner node-number pair
    axisymmetric: bool

    @property
    def n_dofs(self) -> int:
        return self.basis.N

    def nodal(self, T: np.ndarray) -> np.ndarray:
        """Per-node values (NaN outside the elements)."""
        out = np.full(self.node_dof.size, np.nan)
        ok = self.node_dof >= 0
        out[ok] = T[self.node_dof[ok]]
        return out


def build_mesh(xy: np.ndarray, node_ids: np.ndarray, corners: np.ndarray,
               midside: np.ndarray | None, axisymmetric: bool) -> PlaneMesh:
    """corners (m, 4) node indices (K = L for a triangle); midside (m, 4) node indices of
    the mid-side nodes I-J, J-K, K-L, L-I (-1 none) for quadratic elements, else None."""
    tri = corners[:, 2] == corners[:, 3]
    vertex_node = np.unique(corners)
    vertex_of = np.full(len(node_ids), -1, np.int64)
    vertex_of[vertex_node] = np.arange(vertex_node.size)
    p = xy[vertex_node].T
    if axisymmetric and np.any(p[0] < -1e-9 * max(1.0, float(np.abs(p).max()))):
        bad = node_ids[vertex_node[np.argmin(p[0])]]
        raise ApdlError(f"node {bad} lies at negative X (radius) in an axisymmetric model")
    all_tri = bool(tri.all())
    if all_tri:
        t = vertex_of[corners[:, :3]].T.copy()
    else:
        t = vertex_of[corners].T.copy()
    # counter-clockwise cells: the signed area from the corner polygon
    pts = p[:, t]
    x, y = pts[0], pts[1]
    area2 = (x * np.roll(y, -1, axis=0) - np.roll(x, -1, axis=0) * y).sum(axis=0)
    scale = max(float(np.ptp(p, axis=1).max()), 1e-300) ** 2
    if np.any(np.abs(area2) <= 1e-12 * scale):
        raise ApdlError(f"element with zero area (cell {int(np.argmin(np.abs(area2)))}: check "
                        "its node order and coordinates)")
    flip = area2 < 0
    t[:, flip] = t[::-1][:, flip] if all_tri else t[[0, 3, 2, 1]][:, flip]
    if all_tri:
        mesh = MeshTri1(p, t, validate=False, sort_t=False)
        element = ElementTriP2() if midside is not None else ElementTriP1()
    else:
        mesh = MeshQuad1(p, t, validate=False, sort_t=False)
        element = ElementQuadS2() if midside is not None else ElementQuad1()
    basis = Basis(mesh, element)
    node_dof = np.full(len(node_ids), -1, np.int64)
    node_dof[vertex_node] = basis.nodal_dofs[0]
    facet_keys = pair_keys(node_ids[vertex_node[mesh.facets[0]]],
                           node_ids[vertex_node[mesh.facets[1]]])
    if midside is not None:
        order = np.argsort(facet_keys)
        edges = ((0, 1), (1, 2), (2, 3), (3, 0))
        for col, (i, j) in enumerate(edges):
            has = midside[:, col] >= 0
            if all_tri and col == 2:
                continue  # the collapsed edge K-L of a degenerate quad
            if all_tri and col == 3:
                i, j = 2, 0
            keys = pair_keys(node_ids[corners[has, i]], node_ids[corners[has, j]])
            pos = np.clip(np.searchsorted(facet_keys[order], keys), 0, facet_keys.size - 1)
            if not np.array_equal(facet_keys[order][pos], keys):
                raise ApdlError("a mid-side node does not sit on an element edge")
            node_dof[midside[has, col]] = basis.facet_dofs[0, order[pos]]
    return PlaneMesh(basis, node_dof, np.arange(corners.shape[0]), vertex_node, facet_keys,
                     axisymmetric)


# ----------------------------------------------------------------- the forms
def _radius(w) -> np.ndarray:  # noqa: ANN001 - skfem FormExtraParams
    return 2.0 * np.pi * w.x[0] if w.axisymmetric else np.ones_like(w.x[0])


@BilinearForm
def conduction(u, v, w):  # noqa: ANN001, ANN201 - a scikit-fem form
    """∫ (kxx ∂u/∂x ∂v/∂x + kyy ∂u/∂y ∂v/∂y) dV."""
    return (w.kxx * u.grad[0] * v.grad[0] + w.kyy * u.grad[1] * v.grad[1]) * _radius(w)


@BilinearForm
def capacity(u, v, w):  # noqa: ANN001, ANN201
    """∫ ρc u v dV."""
    return w.rho_c * u * v * _radius(w)


@LinearForm
def source(v, w):  # noqa: ANN001, ANN201
    """∫ q v dV (q: HGEN, W/m³)."""
    return w.q * v * _radius(w)


@BilinearForm
def film(u, v, w):  # noqa: ANN001, ANN201
    """∫ h u v dA on a face."""
    return w.h * u * v * _radius(w)


@LinearForm
def face_load(v, w):  # noqa: ANN001, ANN201
    """∫ g v dA on a face (g = h·T_bulk or a heat flux)."""
    return w.g * v * _radius(w)


@dataclass
class ThermalInputs:
    """One load state of the model on a `PlaneMesh` (see `plane_loads` in apdl_like.solve).

    kxx, kyy, rho_c  per cell: property(T at quadrature points) callables
    hgen             per cell, W/m³
    films            (facets, h W/m²K, T_bulk °C) groups
    fluxes           (facets, q W/m²) groups
    fixed            (dofs, values °C)
    """

    kxx: list[Property]
    kyy: list[Property]
    rho_c: list[Property]
    hgen: np.ndarray
    films: list[tuple[np.ndarray, float, float]]
    fluxes: list[tuple[np.ndarray, float]]
    fixed: tuple[np.ndarray, np.ndarray]


class PlaneThermal:
    """Assembly and solves on one `PlaneMesh` with per-cell material properties."""

    def __init__(self, mesh: PlaneMesh, cell_material: np.ndarray,
                 couplings: list[np.ndarray]) -> None:
        self.mesh = mesh
        self.basis = mesh.basis
        self.cell_material = cell_material
        self.groups = {int(m): np.nonzero(cell_material == m)[0]
                       for m in np.unique(cell_material)}
        self._facet_bases: dict[bytes, FacetBasis] = {}
        self._reduce = _coupling_map(self.basis.N, couplings)

    # ---------------------------------------------------------------- pieces
    def _cell_field(self, props: list[Property], T: np.ndarray) -> np.ndarray:
        """A per-cell property at the quadrature points, evaluated at temperature T."""
        Tq = self.basis.interpolate(T).value
        out = np.empty_like(Tq)
        for m, cells in self.groups.items():
            out[cells] = props[m](Tq[cells])
        return out

    def operators(self, inputs: ThermalInputs, T: np.ndarray) -> tuple[sp.csr_matrix,
                                                                          sp.csr_matrix,
                                                                          np.ndarray]:
        """(K conduction + films, C capacity, f loads) at temperature T."""
        b = self.basis
        ax = self.mesh.axisymmetric
        K = conduction.assemble(b, kxx=self._cell_field(inputs.kxx, T),
                                kyy=self._cell_field(inputs.kyy, T), axisymmetric=ax)
        C = capacity.assemble(b, rho_c=self._cell_field(inputs.rho_c, T), axisymmetric=ax)
        q = np.repeat(inputs.hgen[:, None], b.X.shape[-1], axis=1)
        f = source.assemble(b, q=q, axisymmetric=ax) if np.any(inputs.hgen) else \
            np.zeros(b.N)
        for facets, h, tb in inputs.films:
            fb = self._facet_basis(facets)
            K = K + film.assemble(fb, h=h, axisymmetric=ax)
            f = f + face_load.assemble(fb, g=h * tb, axisymmetric=ax)
        for facets, flux in inputs.fluxes:
            f = f + face_load.assemble(self._facet_basis(facets), g=flux, axisymmetric=ax)
        return K.tocsr(), C.tocsr(), f

    def _facet_basis(self, facets: np.ndarray) -> FacetBasis:
        key = np.ascontiguousarray(facets).tobytes()
        fb = self._facet_bases.get(key)
        if fb is None:
            fb = FacetBasis(self.basis.mesh, self.basis.elem, facets=facets)
            self._facet_bases[key] = fb
        return fb

    def _solve(self, A: sp.csr_matrix, rhs: np.ndarray,
               fixed: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        """A x = rhs with fixed dofs and coupled sets (each set shares one unknown)."""
        P = self._reduce
        Ar = (P.T @ A @ P).tocsr()
        br = P.T @ rhs
        n = Ar.shape[0]
        x = np.zeros(n)
        dofs, values = fixed
        rdofs = P[dofs].indices if dofs.size else np.zeros(0, np.int64)
        if rdofs.size:
            x[rdofs] = values
        free = np.ones(n, bool)
        free[rdofs] = False
        if not free.any():
            return P @ x
        rhs_free = br[free] - Ar[free][:, ~free] @ x[~free]
        A_free = Ar[free][:, free].tocsc()
        try:
            x[free] = spla.spsolve(A_free, rhs_free)
        except RuntimeError as exc:
            raise ApdlError(f"the thermal system is singular ({exc}): fix a temperature or "
                            "add convection") from None
        if not np.all(np.isfinite(x)):
            raise ApdlError("the thermal system is singular: fix a temperature (D,,TEMP) "
                            "or add convection (SF,,CONV)")
        return P @ x

    # ---------------------------------------------------------------- solves
    def steady(self, inputs: ThermalInputs, T0: np.ndarray, nonlinear: bool) -> np.ndarray:
        """K(T) T = f(T), Picard iteration from T0 when properties depend on T."""
        T = T0
        for _ in range(PICARD_ITERATIONS if nonlinear else 1):
            K, _, f = self.operators(inputs, T)
            T_new = self._solve(K, f, inputs.fixed)
            change = float(np.max(np.abs(T_new - T))) if T.size else 0.0
            T = T_new
            if not nonlinear or change <= PICARD_TOLERANCE * (1.0 + float(np.max(np.abs(T)))):
                return T
        raise ApdlError(f"the nonlinear thermal solve did not converge in {PICARD_ITERATIONS} "
                        "Picard iterations")

    def step(self, inputs_old: ThermalInputs, inputs_new: ThermalInputs, T: np.ndarray,
             dt: float, theta: float, nonlinear: bool) -> np.ndarray:
        """One θ-step: (C/dt + θK) T1 = (C/dt − (1−θ)K) T0 + θ f1 + (1−θ) f0."""
        K0, C0, f0 = self.operators(inputs_old, T)
        T1 = T
        for _ in range(PICARD_ITERATIONS if nonlinear else 1):
            K1, C1, f1 = self.operators(inputs_new, T1) if nonlinear or inputs_new is not \
                inputs_old else (K0, C0, f0)
            C = 0.5 * (C0 + C1) if nonlinear else C0
            A = C / dt + theta * K1
            rhs = C @ T / dt - (1.0 - theta) * (K0 @ T) + theta * f1 + (1.0 - theta) * f0
            T_new = self._solve(A.tocsr(), rhs, inputs_new.fixed)
            change = float(np.max(np.abs(T_new - T1)))
            T1 = T_new
            if not nonlinear or change <= PICARD_TOLERANCE * (1.0 + float(np.max(np.abs(T1)))):
                return T1
        raise ApdlError(f"the nonlinear thermal step did not converge in {PICARD_ITERATIONS} "
                        "Picard iterations")

    def reaction(self, inputs: ThermalInputs, T: np.ndarray) -> np.ndarray:
        """Heat flow into the model at each dof (W; nonzero at fixed temperatures), steady."""
        K, _, f = self.operators(inputs, T)
        return K @ T - f


def _coupling_map(n: int, couplings: list[np.ndarray]) -> sp.csr_matrix:
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
    `adaptive`, sizes from a step-doubling error estimate within [dt_min, dt_max]."""
    times, temps = [], []
    t, T = t0, T0
    tol = STEP_TOLERANCE * max(scale, 1.0)
    h = dt
    while t < t1 - 1e-12 * max(1.0, abs(t1)):
        if len(times) >= MAX_SUBSTEPS:
            raise ApdlError(f"more than {MAX_SUBSTEPS} substeps in one load step")
        h = min(h, t1 - t)
        old = inputs_at(t)
        if not adaptive:
            T = model.step(old, inputs_at(t + h), T, h, theta, nonlinear)
            t += h
            times.append(t)
            temps.append(T)
            continue
        mid = inputs_at(t + 0.5 * h)
        new = inputs_at(t + h)
        full = model.step(old, new, T, h, theta, nonlinear)
        half = model.step(old, mid, T, 0.5 * h, theta, nonlinear)
        half = model.step(mid, new, half, 0.5 * h, theta, nonlinear)
        error = float(np.max(np.abs(full - half)))
        if error > tol and h > dt_min * (1 + 1e-9):
            h = max(dt_min, h * max(0.2, 0.9 * np.sqrt(tol / error)))
            continue
        t += h
        T = half  # the more accurate of the two
        times.append(t)
        temps.append(T)
        grow = 2.0 if error == 0.0 else min(2.0, 0.9 * np.sqrt(tol / error))
        h = min(dt_max, max(dt_min, h * max(grow, 0.5)))
    if times:
        times[-1] = t1
    return times, temps
