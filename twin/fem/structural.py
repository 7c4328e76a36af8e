"""Axisymmetric linear thermo-elasticity: (u_r, u_z) with hoop strain u_r/r.

    σ = λ tr(ε − εₜ) I + 2μ (ε − εₜ),   εₜ = α (T − T_ref) (1, 1, 1, 0)

The stiffness is assembled and factorized once per model.  The thermal load is linear in
the temperature, f = G (T − T_ref) with G assembled once (temperature basis on the split
thermal mesh, displacement basis on the glued mesh: both share cell numbering, so each
cell sees its own side's temperature).  A displacement probe is therefore a fixed vector:
u_probe = pᵀ K⁻¹ G (T − T_ref) = wᵀ (T − T_ref) with w = Gᵀ K⁻¹ p solved once (adjoint),
which makes the per-step nose drift a dot product.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import scipy.sparse.linalg as spla
from skfem import Basis, ElementVector, asm, condense

from twin.fem.elements import element_for
from twin.fem.forms import capacity, elasticity, thermal_strain_load, unit_load_weighted
from twin.fem.linalg import factorize_symmetric
from twin.fem.materials import Material
from twin.fem.mesh import AxiMesh
from twin.fem.probes import probe_matrix

COMPONENTS = {"r": 0, "z": 1}


class ElasticProblem:
    """Assembled, factorized axisymmetric thermo-elastic problem.

    materials    region → Material (E, nu, alpha used); must cover every cell once
    constraints  boundary → "r", "z" or "rz": displacement components held at zero
    T_ref        stress-free temperature, °C
    order        1 (P1) or 2 (P2); must match the ThermalProblem whose T is passed in
    """

    def __init__(
        self,
        mesh: AxiMesh,
        materials: Mapping[str, Material],
        constraints: Mapping[str, str],
        T_ref: float = 20.0,
        order: int = 1,
    ) -> None:
        if not math.isfinite(T_ref):
            raise ValueError(f"reference temperature must be finite, got {T_ref!r}")
        self.mesh, self.T_ref, self.order = mesh, float(T_ref), order
        scalar = element_for(order)
        intorder = 2 * order + 1
        self.basis = Basis(mesh.glued, ElementVector(scalar), intorder=intorder)
        self.scalar_basis = Basis(mesh.glued, scalar, intorder=intorder)
        self.temperature_basis = Basis(mesh.thermal, scalar, intorder=intorder)

        lam, mu, beta = self._cell_constants(materials)
        nqp = self.basis.X.shape[1]
        as_qp = {
            k: np.repeat(v[:, None], nqp, axis=1)
            for k, v in {"lam": lam, "mu": mu, "beta": beta}.items()
        }
        self._lam, self._mu = as_qp["lam"], as_qp["mu"]
        self._alpha = as_qp["beta"] / (3.0 * self._lam + 2.0 * self._mu)
        self.K = asm(elasticity, self.basis, lam=as_qp["lam"], mu=as_qp["mu"])
        # G: temperature (trial, thermal mesh) → displacement load (test, glued mesh)
        self.G = asm(
            thermal_strain_load, self.temperature_basis, self.basis, beta=as_qp["beta"]
        ).tocsr()

        fixed = []
        for boundary, comps in constraints.items():
            comps = comps.lower()
            if not comps or set(comps) - set(COMPONENTS):
                raise ValueError(
                    f"constraint on {boundary!r} must be 'r', 'z' or 'rz', got {comps!r}"
                )
            facets = mesh.glued_facets(boundary)
            dofs = self.basis.get_dofs(facets=facets)
            for c in comps:
                fixed.append(dofs.nodal[f"u^{COMPONENTS[c] + 1}"])
                if order > 1:
                    fixed.append(dofs.facet[f"u^{COMPONENTS[c] + 1}"])
        if not any(c for c in constraints.values() if "z" in c.lower()):
            raise ValueError("structure needs an axial (z) constraint to remove the rigid motion")
        self.fixed_dofs = np.unique(np.concatenate(fixed)) if fixed else np.zeros(0, int)
        K_free, _, self.free_dofs = condense(self.K, D=self.fixed_dofs)
        # K is symmetric only to round-off: convert, rather than read CSR arrays as CSC
        self._lu = factorize_symmetric(K_free.tocsc())
        self._stress_mass = None

    def _cell_constants(
        self, materials: Mapping[str, Material]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = self.mesh.n_cells
        lam, mu, beta = np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
        for region, mat in materials.items():
            cells = self.mesh.region(region)
            l, m = mat.lame
            lam[cells], mu[cells] = l, m
            beta[cells] = (3.0 * l + 2.0 * m) * mat.alpha
        if np.any(np.isnan(lam)):
            raise ValueError(f"{int(np.isnan(lam).sum())} cells have no material")
        return lam, mu, beta

    # ------------------------------------------------------------------ solves
    def load(self, T: np.ndarray) -> np.ndarray:
        """Thermal load vector (N) for nodal temperatures T (°C)."""
        return self.G @ (np.asarray(T, float) - self.T_ref)

    def solve_vector(self, T: np.ndarray) -> np.ndarray:
        """Displacement dof vector (m) for nodal temperature T (°C)."""
        f = self.load(T)
        u = np.zeros(self.basis.N)
        u[self.free_dofs] = self._lu.solve(f[self.free_dofs])
        return u

    def solve(self, T: np.ndarray) -> np.ndarray:
        """Displacements (2, n_scalar_dofs): rows u_r, u_z in m."""
        return self.components(self.solve_vector(T))

    def components(self, u: np.ndarray) -> np.ndarray:
        return np.vstack([u[0::2], u[1::2]])

    def displacement_probe(self, point_rz: np.ndarray, component: str = "z") -> np.ndarray:
        """Vector w with u_component(point) = w @ (T − T_ref), in m per K (adjoint solve)."""
        c = COMPONENTS[component]
        p_scalar = probe_matrix(self.scalar_basis, np.asarray(point_rz, float).reshape(2, 1))
        p = np.zeros(self.basis.N)
        p[c::2] = p_scalar.toarray().ravel()
        z = np.zeros(self.basis.N)
        z[self.free_dofs] = self._lu.solve(p[self.free_dofs])  # K symmetric
        return self.G.T @ z

    def stresses(self, u: np.ndarray, T: np.ndarray) -> dict[str, np.ndarray]:
        """Nodal stresses (Pa) by L2 projection: rr, zz, tt (hoop), rz, von_mises.

        u: the (2, n) array from `solve` or the flat dof vector.
        """
        u = np.asarray(u, float)
        if u.ndim == 2:
            flat = np.empty(self.basis.N)
            flat[0::2], flat[1::2] = u[0], u[1]
            u = flat
        uh = self.basis.interpolate(u)
        du = uh.grad
        r = np.asarray(self.basis.global_coordinates())[0]
        eth = self._alpha * (np.asarray(self.temperature_basis.interpolate(T)) - self.T_ref)
        e_rr, e_zz, e_tt = du[0, 0] - eth, du[1, 1] - eth, np.asarray(uh)[0] / r - eth
        g_rz = du[0, 1] + du[1, 0]
        tr = e_rr + e_zz + e_tt
        qp = {
            "rr": self._lam * tr + 2.0 * self._mu * e_rr,
            "zz": self._lam * tr + 2.0 * self._mu * e_zz,
            "tt": self._lam * tr + 2.0 * self._mu * e_tt,
            "rz": self._mu * g_rz,
        }
        if self._stress_mass is None:
            M = asm(capacity, self.scalar_basis).tocsc()
            self._stress_mass = spla.splu(M)
        out = {
            k: self._stress_mass.solve(asm(unit_load_weighted, self.scalar_basis, s=v))
            for k, v in qp.items()
        }
        out["von_mises"] = von_mises(out["rr"], out["zz"], out["tt"], out["rz"])
        return out


def von_mises(rr: np.ndarray, zz: np.ndarray, tt: np.ndarray, rz: np.ndarray) -> np.ndarray:
    """Equivalent (von Mises) stress from axisymmetric components."""
    return np.sqrt(0.5 * ((rr - zz) ** 2 + (zz - tt) ** 2 + (tt - rr) ** 2) + 3.0 * rz**2)
