"""2-D thermo-elastic statics on a deck's own mesh: PLANE182/183 as MAPDL solves them.

Same elements as `apdl_like.plane_thermal` (one `PlaneMesh`): each displacement component
is a scalar field on it, so the stiffness is a 2 × 2 block of scalar forms.  Strains
(ε1, ε2, ε3, γ12) are (∂u/∂x, ∂v/∂y, u/r, ∂u/∂y + ∂v/∂x) axisymmetric (x = r, ε3 the hoop
strain), with ε3 = 0 in plane strain; plane stress drops σ3.  Isotropic E, ν, α; the
thermal strain is α (T − TREF) in the three normal directions.

Nodal stresses are evaluated at each element's corners and averaged over the elements that
share the node, as MAPDL's nodal solution (PRNSOL, *GET,,NODE,,S) averages them.
"""

from __future__ import annotations

from functools import cache
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from skfem import Basis, BilinearForm, LinearForm

from apdl_like.errors import ApdlError
from apdl_like.plane_thermal import Part, PlaneMesh, coupling_map, solve_constrained

if TYPE_CHECKING:
    from skfem import DiscreteField
    from skfem.assembly.form.form import FormExtraParams

MODES = ("axisymmetric", "plane_stress", "plane_strain")


def elasticity_matrix(E: np.ndarray, nu: np.ndarray, mode: str) -> np.ndarray:
    """D (4, 4, ...) relating (ε1, ε2, ε3, γ12) to (σ1, σ2, σ3, τ12)."""
    D = np.zeros((4, 4, *np.shape(E)))
    if mode == "plane_stress":
        c = E / (1.0 - nu**2)
        D[0, 0] = D[1, 1] = c
        D[0, 1] = D[1, 0] = c * nu
        D[3, 3] = c * (1.0 - nu) / 2.0
        return D
    c = E / ((1.0 + nu) * (1.0 - 2.0 * nu))
    for i in range(3):
        for j in range(3):
            D[i, j] = c * (1.0 - nu) if i == j else c * nu
    D[3, 3] = c * (1.0 - 2.0 * nu) / 2.0
    return D


def _strain(phi: DiscreteField, component: int, mode: str, x: np.ndarray) -> list:
    """(ε1, ε2, ε3, γ12) of the test/trial function phi in displacement `component`."""
    zero = 0.0 * np.asarray(phi)
    hoop = np.asarray(phi) / x if mode == "axisymmetric" else zero
    if component == 0:
        return [phi.grad[0], zero, hoop, phi.grad[1]]
    return [zero, phi.grad[1], zero, phi.grad[0]]


def _weight(mode: str, x: np.ndarray) -> np.ndarray:
    return 2.0 * np.pi * x if mode == "axisymmetric" else np.ones_like(x)


@cache
def stiffness_form(mode: str, a: int, b: int) -> BilinearForm:
    """∫ ε(v; b)ᵀ D ε(u; a) dV for displacement components a (trial) and b (test)."""

    def form(u: DiscreteField, v: DiscreteField, w: FormExtraParams) -> np.ndarray:
        x = w.x[0]
        eu, ev = _strain(u, a, mode, x), _strain(v, b, mode, x)
        D = elasticity_matrix(w.E, w.nu, mode)
        total = 0.0
        for i in range(4):
            for j in range(4):
                total = total + ev[i] * D[i, j] * eu[j]
        return total * _weight(mode, x)

    return BilinearForm(form)


@cache
def thermal_load_form(mode: str, b: int) -> LinearForm:
    """∫ ε(v; b)ᵀ D ε_th dV, ε_th = α ΔT (1, 1, 1, 0) (plane stress: (1, 1, 0, 0))."""
    normal = 2 if mode == "plane_stress" else 3

    def form(v: DiscreteField, w: FormExtraParams) -> np.ndarray:
        x = w.x[0]
        ev = _strain(v, b, mode, x)
        D = elasticity_matrix(w.E, w.nu, mode)
        th = w.alpha * w.dT
        total = 0.0
        for i in range(4):
            for j in range(normal):
                total = total + ev[i] * D[i, j] * th
        return total * _weight(mode, x)

    return LinearForm(form)


def _corner_dofs(part: Part) -> np.ndarray:
    """(cells, corners) global scalar dofs of the corners of each cell."""
    return part.local_dofs[part.basis.nodal_dofs[0]][part.basis.mesh.t].T


def solve_elastic(mesh: PlaneMesh, mode: str, E: np.ndarray, nu: np.ndarray,
                  alpha: np.ndarray, dT: np.ndarray, fixed: tuple[np.ndarray, np.ndarray],
                  couplings: list[np.ndarray],
                  technology: np.ndarray | None = None,
                  ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Displacements (2, n) and nodal stresses per scalar dof (rr/xx, zz/yy, tt/zz, rz/xy,
    von_mises) of the thermal strain dT (per scalar dof, K) with E, ν, α per element.

    fixed       (vector dofs c·n + i, values m); couplings  vector dof sets sharing a value
    technology  per element: the PLANE182 element technology (`PLANE182_TECHNOLOGY`) of a
                bilinear quad, "" for elements integrated as plain isoparametric ones
    """
    if mode not in MODES:
        raise ApdlError(f"unknown 2-D mode {mode!r}")
    n = mesh.n_dofs
    A = sp.csr_matrix((2 * n, 2 * n))
    f = np.zeros(2 * n)
    recovery = {}
    for k, part in enumerate(mesh.parts):
        b, S = part.basis, part.to_global
        bilinear = part.basis.mesh.t.shape[0] == 4 and b.N == part.basis.mesh.p.shape[1]
        techs = technology[part.elements] if technology is not None and bilinear else None
        if techs is not None and np.any(techs != ""):
            if np.any(techs == ""):
                raise ApdlError("PLANE182 quads share a mesh part with other bilinear quads")
            g = _corner_dofs(part)
            xy = np.moveaxis(part.basis.mesh.p[:, part.basis.mesh.t], 0, -1).swapaxes(0, 1)
            el = part.elements
            groups = []
            for tech in np.unique(techs):
                sel = np.nonzero(techs == tech)[0]
                Ke, fe, recover = plane182_quads(xy[sel], mode, E[el[sel]], nu[el[sel]],
                                                 alpha[el[sel]][:, None] * dT[g[sel]], tech)
                idx = np.hstack([g[sel], g[sel] + n])
                rows = np.repeat(idx, 8, axis=1).ravel()
                cols = np.tile(idx, (1, 8)).ravel()
                A = A + sp.csr_matrix((Ke.ravel(), (rows, cols)), shape=(2 * n, 2 * n))
                np.add.at(f, idx.ravel(), fe.ravel())
                groups.append((recover, idx, g[sel]))
            recovery[k] = groups
            continue
        el = part.elements
        nq = b.X.shape[-1]
        E_q, nu_q, a_q = (np.repeat(x[el][:, None], nq, axis=1) for x in (E, nu, alpha))
        dT_local = dT[part.local_dofs]
        blocks = [[None, None], [None, None]]
        for ia in range(2):
            for ib in range(2):
                Kab = stiffness_form(mode, ia, ib).assemble(b, E=E_q, nu=nu_q)
                blocks[ib][ia] = S @ Kab @ S.T
            f[ia * n:(ia + 1) * n] += S @ thermal_load_form(mode, ia).assemble(
                b, E=E_q, nu=nu_q, alpha=a_q, dT=np.asarray(b.interpolate(dT_local)))
        A = A + sp.bmat(blocks).tocsr()
    P = coupling_map(2 * n, couplings)
    u = solve_constrained(A.tocsr(), f, fixed, P)
    if not np.all(np.isfinite(u)):
        raise ApdlError("the structure is not held (singular stiffness): constrain it")
    disp = u.reshape(2, n)
    return disp, nodal_stress(mesh, mode, E, nu, alpha, dT, disp, recovery, u)


def nodal_stress(mesh: PlaneMesh, mode: str, E: np.ndarray, nu: np.ndarray,
                 alpha: np.ndarray, dT: np.ndarray, disp: np.ndarray,
                 recovery: dict | None = None,
                 u: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Stresses at the element corners, averaged at each corner dof."""
    n = mesh.n_dofs
    sums = np.zeros((4, n))
    counts = np.zeros(n)
    for k, part in enumerate(mesh.parts):
        if recovery and k in recovery:
            for recover, idx, g in recovery[k]:
                sig = recover(u[idx])  # (4, cells, corners)
                for i in range(4):
                    np.add.at(sums[i], g.ravel(), sig[i].ravel())
                np.add.at(counts, g.ravel(), 1.0)
            continue
        corners = part.basis.mesh.t.shape[0]
        ref = part.basis.elem.doflocs[:corners].T  # reference corner points
        b = Basis(part.basis.mesh, part.basis.elem, quadrature=(ref, np.ones(corners)))
        loc = part.local_dofs
        ur, uz = b.interpolate(disp[0][loc]), b.interpolate(disp[1][loc])
        T = np.asarray(b.interpolate(dT[loc]))
        x = np.asarray(b.global_coordinates())[0]
        eps = [ur.grad[0], uz.grad[1], np.zeros_like(x), ur.grad[1] + uz.grad[0]]
        if mode == "axisymmetric":
            on_axis = np.abs(x) < 1e-12 * max(1.0, float(np.abs(x).max()))
            eps[2] = np.where(on_axis, ur.grad[0], np.asarray(ur) / np.where(on_axis, 1.0, x))
        el = part.elements
        D = elasticity_matrix(E[el][:, None], nu[el][:, None], mode)
        th = alpha[el][:, None] * T
        normal = 2 if mode == "plane_stress" else 3
        sig = []
        for i in range(4):
            s_i = sum(D[i, j] * eps[j] for j in range(4))
            s_i = s_i - sum(D[i, j] * th for j in range(normal))
            sig.append(s_i)
        if mode == "plane_stress":
            sig[2] = np.zeros_like(x)
        # corner k of cell e is mesh vertex t[k, e]: its scalar dof is the part's vertex dof
        vdofs = loc[part.basis.nodal_dofs[0]][part.basis.mesh.t].T  # (cells, corners)
        for i in range(4):
            np.add.at(sums[i], vdofs.ravel(), sig[i].ravel())
        np.add.at(counts, vdofs.ravel(), 1.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        avg = sums / counts
    sx, sy, sz, sxy = avg
    vm = np.sqrt(0.5 * ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2) + 3.0 * sxy**2)
    return {"rr": sx, "zz": sy, "tt": sz, "rz": sxy, "von_mises": vm}


# ------------------------------------------------------- PLANE182 bilinear quads
# KEYOPT(1) -> element technology (MAPDL theory reference, PLANE182): 0 the B-bar method,
# 2 enhanced strain with 5 internal dofs (shear and volumetric locking), 3 with 4 (shear
# locking only).  KEYOPT(1) = 1 (uniform reduced integration with hourglass control) is not
# implemented.
PLANE182_TECHNOLOGY = {0: "bbar", 2: "enhanced", 3: "enhanced_shear"}
_GAUSS = 1.0 / np.sqrt(3.0)
_CORNERS = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])


def plane182_technology(keyopt1: int, label: str) -> str:
    """The element technology of PLANE182 KEYOPT(1) (`label` names the element type)."""
    if keyopt1 not in PLANE182_TECHNOLOGY:
        raise ApdlError(f"{label}: PLANE182 KEYOPT(1) = {keyopt1} is not supported (0 B-bar, "
                        "2 enhanced strain, 3 simplified enhanced strain)")
    return PLANE182_TECHNOLOGY[keyopt1]


def _quad_shapes(xi: float, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear N (4,) and dN/d(ξ, η) (2, 4) at a reference point."""
    N = 0.25 * (1 + xi * _CORNERS[:, 0]) * (1 + eta * _CORNERS[:, 1])
    dN = 0.25 * np.array([_CORNERS[:, 0] * (1 + eta * _CORNERS[:, 1]),
                          _CORNERS[:, 1] * (1 + xi * _CORNERS[:, 0])])
    return N, dN


def _internal_modes(mode: str, technology: str) -> int:
    """How many internal (enhanced strain) dofs a PLANE182 quad condenses out."""
    if technology == "enhanced_shear" or (technology == "enhanced" and mode != "axisymmetric"):
        return 4
    return 5 if technology == "enhanced" else 0


def _quad_point(xy: np.ndarray, mode: str, xi: float, eta: float, modes: int,
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """At (ξ, η) for every element (xy: (ne, 4, 2) corners): B (ne, 4, 8) of the corner
    displacements [u1..u4, v1..v4], G (ne, 4, modes) of the enhanced strains and the volume
    weight (ne,) (det J, times 2πr in an axisymmetric ring).

    The enhanced strains are Simo & Rifai's (1990): in the parametric frame ε_ξξ = ξ,
    ε_ηη = η, 2ε_ξη = ξ, η (the gradients of Wilson's 1 − ξ², 1 − η² in both displacement
    components, as Taylor's QM6), mapped with the centre's Jacobian J0 and scaled by
    (det J0 r0)/(det J r) so that each has zero mean over the element: the element passes
    the patch test.  The fifth, for an axisymmetric ring, is their hoop strain ε_θ = ξη,
    against volumetric locking."""
    N, dN = _quad_shapes(xi, eta)
    J = np.einsum("ak,ekb->eab", dN, xy)  # (ne, 2, 2): d(x, y)/d(ξ, η)
    det = np.linalg.det(J)
    dNdx = np.linalg.solve(J, np.broadcast_to(dN, (xy.shape[0], 2, 4)))  # (ne, 2, 4)
    r = xy[:, :, 0] @ N
    ne = xy.shape[0]
    B = np.zeros((ne, 4, 8))
    B[:, 0, :4] = dNdx[:, 0]
    B[:, 1, 4:] = dNdx[:, 1]
    B[:, 3, :4] = dNdx[:, 1]
    B[:, 3, 4:] = dNdx[:, 0]
    axisymmetric = mode == "axisymmetric"
    r_safe = np.where(r == 0.0, 1.0, r)  # on the axis the caller takes ε3 = ε1
    if axisymmetric:
        B[:, 2, :4] = N[None, :] / r_safe[:, None]
    G = np.zeros((ne, 4, modes))
    if modes:
        N0, dN0 = _quad_shapes(0.0, 0.0)
        J0 = np.einsum("ak,ekb->eab", dN0, xy)
        scale = np.linalg.det(J0) / det
        if axisymmetric:
            scale = scale * (xy[:, :, 0] @ N0) / r_safe
        dP = np.array([[-2.0 * xi, 0.0], [0.0, -2.0 * eta]])  # d(P1, P2)/d(ξ, η): rows ξ, η
        dPdx = np.linalg.solve(J0, np.broadcast_to(dP, (ne, 2, 2))) * scale[:, None, None]
        G[:, 0, :2] = dPdx[:, 0]
        G[:, 1, 2:4] = dPdx[:, 1]
        G[:, 3, :2] = dPdx[:, 1]
        G[:, 3, 2:4] = dPdx[:, 0]
        if modes == 5:
            G[:, 2, 4] = xi * eta * scale
    weight = det * (2.0 * np.pi * r if axisymmetric else 1.0)
    return B, G, weight


def _gauss_points() -> np.ndarray:
    """The 2 × 2 points, in corner order (point k is nearest corner k)."""
    return _CORNERS * _GAUSS


def plane182_quads(xy: np.ndarray, mode: str, E: np.ndarray, nu: np.ndarray,
                   th: np.ndarray, technology: str) -> tuple[np.ndarray, np.ndarray, object]:
    """Element stiffness (ne, 8, 8) and thermal load (ne, 8) of PLANE182 bilinear quads (xy:
    (ne, 4, 2) corners, th: thermal strain α ΔT at the corners, interpolated bilinearly to
    the 2 × 2 points as MAPDL's element temperature) and a recovery function u_e (ne, 8)
    -> stresses (4, ne, 4 corners).

    technology: "bbar" (KEYOPT(1) = 0): the dilatation ε1 + ε2 + ε3 at each point replaced
    by its element mean (Hughes; plane stress has no incompressibility constraint and keeps
    the plain strains); "enhanced" / "enhanced_shear" (KEYOPT(1) = 2 / 3): enhanced strains
    condensed out, see `_quad_point` (the fifth exists for the axisymmetric ring only: the
    form of MAPDL's plane one is not published).  The nodal stresses follow MAPDL's default
    (ERESX,DEFA for elastic elements): the 2 × 2 point values extrapolated to the corners;
    the caller averages them over the elements at each node."""
    modes = _internal_modes(mode, technology)
    D = np.moveaxis(elasticity_matrix(E, nu, mode), -1, 0)  # (ne, 4, 4)
    normal = 2 if mode == "plane_stress" else 3
    ne = xy.shape[0]
    points = [(xi, eta, *_quad_point(xy, mode, xi, eta, modes)) for xi, eta in _gauss_points()]
    th_points = [th @ _quad_shapes(xi, eta)[0] for xi, eta in _gauss_points()]
    if technology == "bbar" and mode != "plane_stress":
        # B-bar is the mixed u-p element with a pressure constant per element (Hughes): the
        # constraint is the element mean of the dilatation less the thermal one, so both
        # are averaged (a pointwise thermal dilatation against an averaged total one gives
        # the bulk modulus times their difference as a spurious pressure)
        w = np.array([p[-1] for p in points])  # (4 points, ne)
        dilatation = np.array([B[:, 0] + B[:, 1] + B[:, 2] for _, _, B, _, _ in points])
        mean = np.einsum("ke,kea->ea", w, dilatation) / w.sum(axis=0)[:, None]
        for d, (_, _, B, _, _) in zip(dilatation, points, strict=True):
            B[:, :3] += ((mean - d) / 3.0)[:, None, :]
        th_points = [np.einsum("ke,ke->e", w, np.array(th_points)) / w.sum(axis=0)] * 4
    Kuu, Kua, Kaa = np.zeros((ne, 8, 8)), np.zeros((ne, 8, modes)), np.zeros((ne, modes, modes))
    fu, fa = np.zeros((ne, 8)), np.zeros((ne, modes))

    def thermal(k: int) -> np.ndarray:
        eps_th = np.zeros((ne, 4))
        eps_th[:, :normal] = th_points[k][:, None]
        return eps_th

    for k, (_, _, B, G, w) in enumerate(points):
        DB, DG = D @ B, D @ G
        Kuu += np.einsum("eia,eib,e->eab", B, DB, w)
        Kua += np.einsum("eia,eib,e->eab", B, DG, w)
        Kaa += np.einsum("eia,eib,e->eab", G, DG, w)
        s_th = np.einsum("eij,ej->ei", D, thermal(k))
        fu += np.einsum("eia,ei,e->ea", B, s_th, w)
        fa += np.einsum("eia,ei,e->ea", G, s_th, w)
    Kaa_inv = np.linalg.inv(Kaa)
    K = Kuu - Kua @ Kaa_inv @ np.swapaxes(Kua, 1, 2)
    f = fu - np.einsum("eab,ebc,ec->ea", Kua, Kaa_inv, fa)
    extrapolate = np.array([_quad_shapes(*(c / _GAUSS))[0] for c in _CORNERS])

    def recover(u_e: np.ndarray) -> np.ndarray:
        alpha = np.einsum("eab,eb->ea", Kaa_inv,
                          fa - np.einsum("eab,eb->ea", np.swapaxes(Kua, 1, 2), u_e))
        gauss = np.zeros((4, ne, 4))
        for k, (_, _, B, G, _) in enumerate(points):
            eps = np.einsum("eia,ea->ei", B, u_e) + np.einsum("eia,ea->ei", G, alpha)
            sig = np.einsum("eij,ej->ei", D, eps - thermal(k))
            if mode == "plane_stress":
                sig[:, 2] = 0.0
            gauss[:, :, k] = sig.T
        return np.einsum("sek,ck->sec", gauss, extrapolate)

    return K, f, recover
