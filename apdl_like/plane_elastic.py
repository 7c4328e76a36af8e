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

import numpy as np
import scipy.sparse as sp
from skfem import Basis, BilinearForm, LinearForm

from apdl_like.errors import ApdlError
from apdl_like.plane_thermal import PlaneMesh, coupling_map, solve_constrained

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


def _strain(phi, component: int, mode: str, x: np.ndarray) -> list:  # noqa: ANN001
    """(ε1, ε2, ε3, γ12) of the test/trial function phi in displacement `component`."""
    zero = 0.0 * phi.value
    hoop = phi.value / x if mode == "axisymmetric" else zero
    if component == 0:
        return [phi.grad[0], zero, hoop, phi.grad[1]]
    return [zero, phi.grad[1], zero, phi.grad[0]]


def _weight(mode: str, x: np.ndarray) -> np.ndarray:
    return 2.0 * np.pi * x if mode == "axisymmetric" else np.ones_like(x)


@cache
def stiffness_form(mode: str, a: int, b: int) -> BilinearForm:
    """∫ ε(v; b)ᵀ D ε(u; a) dV for displacement components a (trial) and b (test)."""

    def form(u, v, w):  # noqa: ANN001, ANN202 - a scikit-fem form
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

    def form(v, w):  # noqa: ANN001, ANN202
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


def _corner_dofs(part) -> np.ndarray:  # noqa: ANN001 - plane_thermal.Part
    """(cells, corners) global scalar dofs of the corners of each cell."""
    return part.local_dofs[part.basis.nodal_dofs[0]][part.basis.mesh.t].T


def solve_elastic(mesh: PlaneMesh, mode: str, E: np.ndarray, nu: np.ndarray,
                  alpha: np.ndarray, dT: np.ndarray, fixed: tuple[np.ndarray, np.ndarray],
                  couplings: list[np.ndarray],
                  enhanced: np.ndarray | None = None) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Displacements (2, n) and nodal stresses per scalar dof (rr/xx, zz/yy, tt/zz, rz/xy,
    von_mises) of the thermal strain dT (per scalar dof, K) with E, ν, α per element.

    fixed      (vector dofs c·n + i, values m); couplings  vector dof sets sharing a value
    enhanced   per element: PLANE182 with enhanced strain (bilinear quads only)
    """
    if mode not in MODES:
        raise ApdlError(f"unknown 2-D mode {mode!r}")
    n = mesh.n_dofs
    A = sp.csr_matrix((2 * n, 2 * n))
    f = np.zeros(2 * n)
    recovery = {}
    for k, part in enumerate(mesh.parts):
        b, S = part.basis, part.to_global
        if enhanced is not None and part.basis.mesh.t.shape[0] == 4 and \
                b.N == part.basis.mesh.p.shape[1] and np.any(enhanced[part.elements]):
            g = _corner_dofs(part)
            xy = np.moveaxis(part.basis.mesh.p[:, part.basis.mesh.t], 0, -1).swapaxes(0, 1)
            el = part.elements
            Ke, fe, recover = enhanced_quads(xy, mode, E[el], nu[el], alpha[el][:, None] * dT[g])
            idx = np.hstack([g, g + n])
            rows = np.repeat(idx, 8, axis=1).ravel()
            cols = np.tile(idx, (1, 8)).ravel()
            A = A + sp.csr_matrix((Ke.ravel(), (rows, cols)), shape=(2 * n, 2 * n))
            np.add.at(f, idx.ravel(), fe.ravel())
            recovery[k] = (recover, idx, g)
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
                b, E=E_q, nu=nu_q, alpha=a_q, dT=b.interpolate(dT_local).value)
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
            recover, idx, g = recovery[k]
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
        T = b.interpolate(dT[loc]).value
        x = b.global_coordinates().value[0]
        eps = [ur.grad[0], uz.grad[1], np.zeros_like(x), ur.grad[1] + uz.grad[0]]
        if mode == "axisymmetric":
            on_axis = np.abs(x) < 1e-12 * max(1.0, float(np.abs(x).max()))
            eps[2] = np.where(on_axis, ur.grad[0], ur.value / np.where(on_axis, 1.0, x))
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


# ----------------------------------------------- PLANE182 enhanced strain (KEYOPT(1) = 2)
_GAUSS = 1.0 / np.sqrt(3.0)
_CORNERS = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])


def _quad_shapes(xi: float, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear N (4,) and dN/d(ξ, η) (2, 4) at a reference point."""
    N = 0.25 * (1 + xi * _CORNERS[:, 0]) * (1 + eta * _CORNERS[:, 1])
    dN = 0.25 * np.array([_CORNERS[:, 0] * (1 + eta * _CORNERS[:, 1]),
                          _CORNERS[:, 1] * (1 + xi * _CORNERS[:, 0])])
    return N, dN


def _enhanced_matrices(xy: np.ndarray, mode: str, xi: float, eta: float,
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """At (ξ, η) for every element (xy: (ne, 4, 2) corners): B (ne, 4, 8) of the corner
    displacements [u1..u4, v1..v4], G (ne, 4, 4) of the incompatible modes (1−ξ², 1−η²)
    per component (Taylor's centre-Jacobian form), det J and the radius."""
    N, dN = _quad_shapes(xi, eta)
    J = np.einsum("ak,ekb->eab", dN, xy)  # (ne, 2, 2): d(x, y)/d(ξ, η)
    det = np.linalg.det(J)
    dNdx = np.linalg.solve(J, np.broadcast_to(dN, (xy.shape[0], 2, 4)))  # (ne, 2, 4)
    r = xy[:, :, 0] @ N
    _, dN0 = _quad_shapes(0.0, 0.0)
    J0 = np.einsum("ak,ekb->eab", dN0, xy)
    det0 = np.linalg.det(J0)
    dP = np.array([[-2.0 * xi, 0.0], [0.0, -2.0 * eta]])  # d(P1, P2)/d(ξ, η): rows ξ, η
    # scaled by dV0/dV so that ∫ G dV = 0 and the element passes the patch test; the volume
    # element of an axisymmetric ring carries the radius (r0 at the centre)
    scale = det0 / det
    if mode == "axisymmetric":
        N0, _ = _quad_shapes(0.0, 0.0)
        scale = scale * (xy[:, :, 0] @ N0) / np.where(r == 0.0, 1.0, r)
    dPdx = np.linalg.solve(J0, np.broadcast_to(dP, (xy.shape[0], 2, 2))) * scale[:, None, None]
    ne = xy.shape[0]
    B = np.zeros((ne, 4, 8))
    G = np.zeros((ne, 4, 4))
    B[:, 0, :4] = dNdx[:, 0]
    B[:, 1, 4:] = dNdx[:, 1]
    B[:, 3, :4] = dNdx[:, 1]
    B[:, 3, 4:] = dNdx[:, 0]
    G[:, 0, :2] = dPdx[:, 0]
    G[:, 1, 2:] = dPdx[:, 1]
    G[:, 3, :2] = dPdx[:, 1]
    G[:, 3, 2:] = dPdx[:, 0]
    if mode == "axisymmetric":
        r_safe = np.where(r == 0.0, 1.0, r)  # on the axis the caller takes ε3 = ε1
        B[:, 2, :4] = N[None, :] / r_safe[:, None]
        # the incompatible modes add no hoop strain: with it the element fails the patch
        # test (a uniform strain state would not be reproduced)
    return B, G, det, r


def enhanced_quads(xy: np.ndarray, mode: str, E: np.ndarray, nu: np.ndarray,
                   th: np.ndarray) -> tuple[np.ndarray, np.ndarray, object]:
    """Condensed element stiffness (ne, 8, 8) and thermal load (ne, 8) of bilinear quads with
    four incompatible modes (MAPDL's PLANE182 enhanced strain), and a recovery function
    u_e (ne, 8) -> stresses (4, ne, 4 corners).  th: thermal strain α ΔT at the corners.

    MAPDL's theory reference gives KEYOPT(1) = 3 these four internal DOFs (against shear
    locking) and KEYOPT(1) = 2 a fifth one against volumetric locking, without its form;
    both KEYOPTs run as this four-mode element.  The nodal stresses follow MAPDL's default
    (ERESX,DEFA for elastic elements): the 2 × 2 point values extrapolated to the corners,
    then averaged over the elements at each node."""
    D = np.moveaxis(elasticity_matrix(E, nu, mode), -1, 0)  # (ne, 4, 4)
    normal = 2 if mode == "plane_stress" else 3
    ne = xy.shape[0]
    Kuu, Kua, Kaa = np.zeros((ne, 8, 8)), np.zeros((ne, 8, 4)), np.zeros((ne, 4, 4))
    fu, fa = np.zeros((ne, 8)), np.zeros((ne, 4))
    for xi in (-_GAUSS, _GAUSS):
        for eta in (-_GAUSS, _GAUSS):
            B, G, det, r = _enhanced_matrices(xy, mode, xi, eta)
            w = det * (2.0 * np.pi * r if mode == "axisymmetric" else 1.0)
            N, _ = _quad_shapes(xi, eta)
            eps_th = np.zeros((ne, 4))
            eps_th[:, :normal] = (th @ N)[:, None]
            DB, DG = D @ B, D @ G
            Kuu += np.einsum("eia,eib,e->eab", B, DB, w)
            Kua += np.einsum("eia,eib,e->eab", B, DG, w)
            Kaa += np.einsum("eia,eib,e->eab", G, DG, w)
            s_th = np.einsum("eij,ej->ei", D, eps_th)
            fu += np.einsum("eia,ei,e->ea", B, s_th, w)
            fa += np.einsum("eia,ei,e->ea", G, s_th, w)
    Kaa_inv = np.linalg.inv(Kaa)
    K = Kuu - Kua @ Kaa_inv @ np.swapaxes(Kua, 1, 2)
    f = fu - np.einsum("eab,ebc,ec->ea", Kua, Kaa_inv, fa)

    def recover(u_e: np.ndarray) -> np.ndarray:
        alpha = np.einsum("eab,eb->ea", Kaa_inv,
                          fa - np.einsum("eab,eb->ea", np.swapaxes(Kua, 1, 2), u_e))
        # stresses at the 2 × 2 integration points, extrapolated to the corners (MAPDL's
        # nodal solution of linear elements)
        gauss = np.zeros((4, ne, 4))
        for k, (xi, eta) in enumerate(_CORNERS * _GAUSS):
            B, G, _, _ = _enhanced_matrices(xy, mode, xi, eta)
            N, _ = _quad_shapes(xi, eta)
            eps = np.einsum("eia,ea->ei", B, u_e) + np.einsum("eia,ea->ei", G, alpha)
            eps[:, :normal] -= (th @ N)[:, None]
            sig = np.einsum("eij,ej->ei", D, eps)
            if mode == "plane_stress":
                sig[:, 2] = 0.0
            gauss[:, :, k] = sig.T
        extrapolate = np.array([_quad_shapes(*(c / _GAUSS))[0] for c in _CORNERS])
        return np.einsum("sek,ck->sec", gauss, extrapolate)

    return K, f, recover
