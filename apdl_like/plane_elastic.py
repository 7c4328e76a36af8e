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


def solve_elastic(mesh: PlaneMesh, mode: str, E: np.ndarray, nu: np.ndarray,
                  alpha: np.ndarray, dT: np.ndarray, fixed: tuple[np.ndarray, np.ndarray],
                  couplings: list[np.ndarray]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Displacements (2, n) and nodal stresses per scalar dof (rr/xx, zz/yy, tt/zz, rz/xy,
    von_mises) of the thermal strain dT (per scalar dof, K) with E, ν, α per element.

    fixed      (vector dofs c·n + i, values m); couplings  vector dof sets sharing a value
    """
    if mode not in MODES:
        raise ApdlError(f"unknown 2-D mode {mode!r}")
    n = mesh.n_dofs
    A = sp.csr_matrix((2 * n, 2 * n))
    f = np.zeros(2 * n)
    for part in mesh.parts:
        b, S = part.basis, part.to_global
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
    return disp, nodal_stress(mesh, mode, E, nu, alpha, dT, disp)


def nodal_stress(mesh: PlaneMesh, mode: str, E: np.ndarray, nu: np.ndarray,
                 alpha: np.ndarray, dT: np.ndarray, disp: np.ndarray) -> dict[str, np.ndarray]:
    """Stresses at the element corners, averaged at each corner dof."""
    n = mesh.n_dofs
    sums = np.zeros((4, n))
    counts = np.zeros(n)
    for part in mesh.parts:
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
