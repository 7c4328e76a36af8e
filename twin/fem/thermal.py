"""Axisymmetric transient heat conduction with sources, convection, flux, fixed
temperatures and contact resistance across split interfaces.

    ρc ∂T/∂t = ∇·(k∇T) + q          in the body (r, z), volume element 2πr dr dz
    −k ∂T/∂n = h (T − T∞)            on convective boundaries
    −k ∂T/∂n = −q''                  on flux boundaries (q'' > 0 heats the body)
    q_n = (T⁺ − T⁻) / R              across a contact interface (R in m²K/W)

Operators are assembled once per material region, boundary and interface with unit
coefficients and combined linearly for each load set (`PatternCombination`), so a new
window costs one sparse factorization and the time steps cost one back-substitution each.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import cKDTree
from skfem import Basis, ElementTriP1, ElementTriP2, FacetBasis, asm

from twin.fem import forms
from twin.fem.combine import PatternCombination
from twin.fem.materials import Material
from twin.fem.mesh import AxiMesh

ELEMENTS = {1: ElementTriP1, 2: ElementTriP2}


def element_for(order: int):  # noqa: ANN201 - skfem element instance
    try:
        return ELEMENTS[order]()
    except KeyError:
        raise ValueError(f"element order must be 1 (P1) or 2 (P2), got {order!r}") from None


def _finite(value: float, what: str) -> float:
    if callable(value):  # a field f(r, z): checked where it is evaluated
        return 0.0
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{what} must be finite, got {value!r}")
    return value


@dataclass
class ThermalLoads:
    """One set of thermal loads (held constant over a window of time steps).

    sources             region → volumetric heat W/m³
    convection          boundary → (h W/(m²K), T∞ °C)
    flux                boundary → heat flux into the body W/m²
    (source densities, fluxes, bulk and fixed temperatures may also be fields given as
    functions f(r, z) of numpy arrays, like APDL tabular loads)
    contact_resistance  interface → R m²K/W (interfaces not listed are perfectly bonded
                        at a negligible R; see ThermalProblem.PERFECT_CONTACT_R)
    fixed_temperature   boundary → T °C
    fixed_dofs          optional (dof indices, values °C) for point constraints
    """

    sources: dict[str, float] = field(default_factory=dict)
    convection: dict[str, tuple[float, float]] = field(default_factory=dict)
    flux: dict[str, float] = field(default_factory=dict)
    contact_resistance: dict[str, float] = field(default_factory=dict)
    fixed_temperature: dict[str, float] = field(default_factory=dict)
    fixed_dofs: tuple[np.ndarray, np.ndarray] | None = None

    def __post_init__(self) -> None:
        for name, q in self.sources.items():
            _finite(q, f"heat source of region {name!r}")
        for name, hc in self.convection.items():
            h, t_inf = hc
            if not (_finite(h, f"film coefficient of boundary {name!r}") >= 0.0):
                raise ValueError(f"film coefficient of boundary {name!r} must be ≥ 0, got {h!r}")
            _finite(t_inf, f"bulk temperature of boundary {name!r}")
        for name, q in self.flux.items():
            _finite(q, f"heat flux of boundary {name!r}")
        for name, r in self.contact_resistance.items():
            if not (_finite(r, f"contact resistance of interface {name!r}") > 0.0):
                raise ValueError(f"contact resistance of interface {name!r} must be > 0, got {r!r}")
        for name, t in self.fixed_temperature.items():
            _finite(t, f"fixed temperature of boundary {name!r}")


class ThermalProblem:
    """Assembled axisymmetric heat-conduction operators on an `AxiMesh`.

    materials  material region name → Material; the regions must cover every cell once.
    order      1 (P1) or 2 (P2) Lagrange triangles.
    """

    #: resistance used for interfaces that a load set leaves out (effectively bonded)
    PERFECT_CONTACT_R = 1e-9

    def __init__(self, mesh: AxiMesh, materials: Mapping[str, Material], order: int = 1) -> None:
        self.mesh = mesh
        self.order = order
        self.element = element_for(order)
        self.intorder = 2 * order + 1  # the 2πr weight raises the polynomial degree by one
        self.basis = Basis(mesh.thermal, self.element, intorder=self.intorder)
        self.n_dofs = self.basis.N
        self.materials = dict(materials)
        self._check_materials()

        # one pattern for every operator: all cells plus the interface couplings (built
        # from the mass matrix: its entries are all positive, so none cancels to zero)
        pattern = asm(forms.capacity, self.basis)
        self._interface_factors: dict[str, tuple[sp.csc_matrix, np.ndarray]] = {}
        self._base_factorizations: dict[tuple, _BaseFactorization] = {}
        iface_ops = {}
        for name, iface in mesh.interfaces.items():
            iface_ops[name] = self._interface_operator(name, iface.facets_a, iface.facets_b)
            pattern = pattern + abs(iface_ops[name])
        self.ops = PatternCombination(pattern + sp.eye(self.n_dofs))
        for name, op in iface_ops.items():
            self.ops.add(f"interface:{name}", op)

        k_data = np.zeros(self.ops.nnz)
        c_data = np.zeros(self.ops.nnz)
        for region, mat in self.materials.items():
            sub = Basis(
                mesh.thermal, self.element, elements=mesh.region(region), intorder=self.intorder
            )
            self.ops.add(f"conduction:{region}", asm(forms.conduction, sub))
            self.ops.add(f"capacity:{region}", asm(forms.capacity, sub))
            k_data += mat.k * self.ops.data({f"conduction:{region}": 1.0})
            c_data += mat.rho_c * self.ops.data({f"capacity:{region}": 1.0})
        self.conduction_data = k_data
        self.capacity_data = c_data
        self._facet_bases: dict[str, FacetBasis] = {}
        self._source_vectors: dict[str, np.ndarray] = {}
        self._region_bases: dict[str, Basis] = {}
        self._facet_loads: dict[str, np.ndarray] = {}

    # ------------------------------------------------------------ operators
    def _check_materials(self) -> None:
        if not self.materials:
            raise ValueError("no materials given")
        count = np.zeros(self.mesh.n_cells, dtype=int)
        for region in self.materials:
            count[self.mesh.region(region)] += 1
        if np.any(count == 0):
            raise ValueError(f"{int(np.sum(count == 0))} cells have no material")
        if np.any(count > 1):
            raise ValueError(f"{int(np.sum(count > 1))} cells have more than one material")

    def _interface_operator(self, name: str, fa: np.ndarray, fb: np.ndarray) -> sp.csr_matrix:
        """Unit conductance J^T M_a J, with J the jump T_a − T_b on side-a dofs."""
        fbasis = FacetBasis(self.mesh.thermal, self.element, facets=fa, intorder=self.intorder)
        m_a = asm(forms.capacity, fbasis)
        dofs_a = self.basis.get_dofs(facets=fa).flatten()
        dofs_b = self.basis.get_dofs(facets=fb).flatten()
        xy = self.basis.doflocs
        dist, idx = cKDTree(xy[:, dofs_b].T).query(xy[:, dofs_a].T)
        scale = np.ptp(xy, axis=1).max()
        if np.any(dist > 1e-9 * scale):
            raise ValueError(f"interface {name!r}: the two faces do not coincide")
        n = self.n_dofs
        jump = sp.csr_matrix(
            (
                np.r_[np.ones(dofs_a.size), -np.ones(dofs_a.size)],
                (np.r_[dofs_a, dofs_a], np.r_[dofs_a, dofs_b[idx]]),
            ),
            shape=(n, n),
        )
        # low-rank form K_i = U M U^T (U: n × m jump columns, M: facet mass on side a),
        # used to update a factorization when only this interface's resistance changes
        self._interface_factors[name] = (
            sp.csc_matrix(jump.T)[:, dofs_a],
            m_a[dofs_a][:, dofs_a].toarray(),
        )
        return (jump.T @ m_a @ jump).tocsr()

    def facet_basis(self, boundary: str) -> FacetBasis:
        if boundary not in self._facet_bases:
            self._facet_bases[boundary] = FacetBasis(
                self.mesh.thermal,
                self.element,
                facets=self.mesh.boundary(boundary),
                intorder=self.intorder,
            )
        return self._facet_bases[boundary]

    def _boundary_terms(self, boundary: str) -> str:
        key = f"film:{boundary}"
        if key not in self.ops:
            fb = self.facet_basis(boundary)
            self.ops.add(key, asm(forms.capacity, fb))
            self._facet_loads[boundary] = asm(forms.unit_load, fb)
        return key

    def facet_load(self, boundary: str) -> np.ndarray:
        """∫_boundary v 2πr ds (load of a unit flux), W per W/m²."""
        self._boundary_terms(boundary)
        return self._facet_loads[boundary]

    def source_vector(self, region: str) -> np.ndarray:
        """∫_region v 2πr dA (load of a unit heat density), W per W/m³."""
        if region not in self._source_vectors:
            sub = Basis(
                self.mesh.thermal,
                self.element,
                elements=self.mesh.region(region),
                intorder=self.intorder,
            )
            self._region_bases[region] = sub
            self._source_vectors[region] = asm(forms.unit_load, sub)
        return self._source_vectors[region]

    def volume(self, region: str) -> float:
        """Volume of a region (revolved), m³."""
        return float(self.source_vector(region).sum())

    def fixed(self, loads: ThermalLoads) -> tuple[np.ndarray, np.ndarray]:
        """Dofs and values of every prescribed temperature (later entries win)."""
        dofs, values = [], []
        for boundary, t in loads.fixed_temperature.items():
            d = self.basis.get_dofs(facets=self.mesh.boundary(boundary)).flatten()
            dofs.append(d)
            values.append(_field_values(t, self.basis.doflocs[:, d], f"boundary {boundary!r}"))
        if loads.fixed_dofs is not None:
            d = np.asarray(loads.fixed_dofs[0], dtype=np.int64)
            if d.size and (d.min() < 0 or d.max() >= self.n_dofs):
                raise ValueError("fixed temperature on a dof that does not exist")
            dofs.append(d)
            values.append(np.broadcast_to(np.asarray(loads.fixed_dofs[1], float), d.shape))
        if not dofs:
            return np.zeros(0, dtype=np.int64), np.zeros(0)
        d, v = np.concatenate(dofs), np.concatenate(values)
        last = d.size - 1 - np.unique(d[::-1], return_index=True)[1]
        return d[last], v[last]

    def _weighted_load(self, value, basis: Basis, unit: np.ndarray, what: str) -> np.ndarray:  # noqa: ANN001
        """∫ value·v 2πr over a (facet) basis; `unit` is the cached load of value = 1."""
        if not callable(value):
            return float(value) * unit
        x = basis.global_coordinates().value
        return asm(forms.unit_load_weighted, basis, s=_field_values(value, x, what))

    def load_parts(self, loads: ThermalLoads) -> tuple[dict[str, float], dict[str, np.ndarray]]:
        """Film/interface coefficients and the load vectors (W) by kind.

        Returns (coefficients of the unit operators, {"sources", "flux", "convection"}).
        """
        coeff: dict[str, float] = {}
        parts = {k: np.zeros(self.n_dofs) for k in ("sources", "flux", "convection")}
        for region, q in loads.sources.items():
            unit = self.source_vector(region)
            basis = self._region_bases[region] if callable(q) else None
            parts["sources"] += self._weighted_load(q, basis, unit, f"region {region!r}")
        for boundary, q in loads.flux.items():
            unit = self.facet_load(boundary)
            parts["flux"] += self._weighted_load(
                q, self.facet_basis(boundary), unit, f"boundary {boundary!r}"
            )
        for boundary, (h, t_inf) in loads.convection.items():
            coeff[self._boundary_terms(boundary)] = float(h)
            parts["convection"] += float(h) * self._weighted_load(
                t_inf,
                self.facet_basis(boundary),
                self._facet_loads[boundary],
                f"boundary {boundary!r}",
            )
        for name in loads.contact_resistance:
            self.mesh.interface(name)
        for name in self.mesh.interfaces:
            r = loads.contact_resistance.get(name, self.PERFECT_CONTACT_R)
            coeff[f"interface:{name}"] = 1.0 / float(r)
        return coeff, parts

    def system(self, loads: ThermalLoads) -> tuple[np.ndarray, np.ndarray]:
        """Conductance data K (on the shared pattern, W/K) and load vector f (W)."""
        coeff, parts = self.load_parts(loads)
        return self.conduction_data + self.ops.data(coeff), sum(parts.values())

    # --------------------------------------------------------------- solves
    def steady(self, loads: ThermalLoads) -> np.ndarray:
        """Steady-state nodal temperature, °C."""
        k_data, f = self.system(loads)
        dofs, values = self.fixed(loads)
        if dofs.size == 0 and not any(h > 0 for h, _ in loads.convection.values()):
            raise ValueError("steady problem needs a fixed temperature or a convective boundary")
        return _LinearSolve(self.ops.csr(k_data), dofs, values).solve(f)

    def transient(self, loads: ThermalLoads, dt: float, theta: float = 1.0) -> ThermalStepper:
        """A stepper for fixed Δt (s): θ = 1 backward Euler, θ = 0.5 Crank–Nicolson."""
        if not (math.isfinite(dt) and dt > 0.0):
            raise ValueError(f"time step must be positive, got {dt!r}")
        if not (0.5 <= theta <= 1.0):
            raise ValueError(f"theta must lie in [0.5, 1], got {theta!r}")
        return ThermalStepper(self, loads, float(dt), float(theta))

    def energy_balance(
        self,
        T_old: np.ndarray,
        T_new: np.ndarray,
        loads: ThermalLoads,
        dt: float,
        theta: float = 1.0,
    ) -> dict[str, float]:
        """Discrete heat balance of one step, W.

        stored = sources + flux + fixed_in − convection_out; `residual_W` is what is left,
        round-off for an exact linear solve.  `heat_in_W` = sources + flux,
        `heat_out_W` = convection out + heat drawn by fixed temperatures.
        """
        coeff, parts = self.load_parts(loads)
        T_theta = theta * T_new + (1.0 - theta) * T_old
        C = self.ops.csr(self.capacity_data)
        stored = float((C @ (T_new - T_old)).sum() / dt)
        sources = float(parts["sources"].sum())
        flux = float(parts["flux"].sum())
        films = {k: c for k, c in coeff.items() if k.startswith("film:")}
        convection_out = float((self.ops.matrix(films) @ T_theta).sum() - parts["convection"].sum())
        dofs, _ = self.fixed(loads)
        fixed_in = 0.0
        if dofs.size:
            K = self.ops.csr(self.conduction_data + self.ops.data(coeff))
            residual = C @ (T_new - T_old) / dt + K @ T_theta - sum(parts.values())
            fixed_in = float(residual[dofs].sum())
        residual_w = sources + flux + fixed_in - convection_out - stored
        return {
            "sources_W": float(sources),
            "flux_W": float(flux),
            "convection_out_W": convection_out,
            "fixed_in_W": fixed_in,
            "stored_W": stored,
            "heat_in_W": float(sources + flux),
            "heat_out_W": convection_out - fixed_in,
            "residual_W": residual_w,
        }

    def probe(self, points_rz: np.ndarray) -> sp.csr_matrix:
        """Interpolation matrix P (n_points × n_dofs): T(points) = P @ T."""
        pts = np.atleast_2d(np.asarray(points_rz, dtype=float))
        if pts.shape[0] != 2:
            pts = pts.T
        return probe_matrix(self.basis, pts)


def probe_matrix(basis: Basis, points: np.ndarray) -> sp.csr_matrix:
    """Point-evaluation matrix of a scalar basis at points (2, n); error outside the mesh."""
    try:
        cells = basis.mesh.element_finder()(points[0], points[1])
    except ValueError as exc:
        raise ValueError(f"probe point outside the mesh: {exc}") from None
    p = basis.mesh.p
    t = basis.mesh.t[:, cells]
    # the finder may return the closest cell for points outside: check barycentrics
    a, b, c = p[:, t[0]], p[:, t[1]], p[:, t[2]]
    det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])
    l1 = ((points[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (points[1] - a[1])) / det
    l2 = ((b[0] - a[0]) * (points[1] - a[1]) - (points[0] - a[0]) * (b[1] - a[1])) / det
    tol = -1e-9
    outside = (l1 < tol) | (l2 < tol) | (1.0 - l1 - l2 < tol)
    if np.any(outside):
        bad = points[:, np.where(outside)[0][0]]
        raise ValueError(f"probe point (r={bad[0]:.6g}, z={bad[1]:.6g}) m is outside the mesh")
    return sp.csr_matrix(basis.probes(points))


def _field_values(value, points: np.ndarray, what: str) -> np.ndarray:  # noqa: ANN001
    """A constant or a field f(r, z) evaluated at points (2, ...), checked finite."""
    if callable(value):
        out = np.asarray(value(points[0], points[1]), dtype=float)
        out = np.broadcast_to(out, points.shape[1:]).astype(float)
    else:
        out = np.full(points.shape[1:], float(value))
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{what}: load field is not finite")
    return out


def factorize_symmetric(A: sp.csc_matrix) -> spla.SuperLU:
    """SuperLU of a symmetric positive-definite FE matrix.

    Minimum-degree ordering on Aᵀ+A with diagonal pivots keeps the symmetric structure:
    about half the fill and time of SuperLU's default (COLAMD, partial pivoting) here.
    """
    return spla.splu(
        A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
    )


class _LinearSolve:
    """Factorized SPD-pattern system with prescribed dofs eliminated."""

    def __init__(self, A: sp.csr_matrix, dofs: np.ndarray, values: np.ndarray) -> None:
        n = A.shape[0]
        self.dofs, self.values = dofs, values
        if dofs.size:
            free = np.ones(n, dtype=bool)
            free[dofs] = False
            self.free = np.where(free)[0]
            A_free = A[self.free][:, self.free]
            self.coupling = A[self.free][:, dofs]
        else:
            self.free = None
            A_free = A
        # A is symmetric: its CSR arrays read as CSC describe the same matrix
        A_csc = sp.csc_matrix((A_free.data, A_free.indices, A_free.indptr), shape=A_free.shape)
        self.lu = factorize_symmetric(A_csc)
        self.n = n

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        if self.free is None:
            return self.lu.solve(rhs)
        x = np.empty(self.n)
        x[self.dofs] = self.values
        x[self.free] = self.lu.solve(rhs[self.free] - self.coupling @ self.values)
        return x


class _BaseFactorization:
    """The step matrix without contact coupling, factorized, and its interface response.

    The contact terms are low rank: A = A_base + U W Uᵀ with U the interface jump columns
    (a few dozen) and W = blockdiag(θ·(1/R_i)·M_i).  Woodbury then gives
        A⁻¹ b = y − Z (I + W Uᵀ Z)⁻¹ W Uᵀ y,   y = A_base⁻¹ b,  Z = A_base⁻¹ U,
    so a window with new contact resistances needs no sparse factorization at all.  The
    base leaves the contacts out entirely (rather than taking the first resistances seen),
    so results never depend on which windows or runs came before: a batch gives the same
    numbers in one process or many.
    """

    def __init__(self, solver: _LinearSolve, U: sp.csc_matrix):
        self.solver = solver
        self.U = U
        self.Z = solver.lu.solve(U.toarray()) if U.shape[1] else np.zeros((U.shape[0], 0))
        self.UtZ = U.T @ self.Z


class ThermalStepper:
    """θ-method time stepping with a fixed Δt and fixed loads.

    Without fixed temperatures, the step matrix C/Δt + θK less its contact terms is
    factorized once per distinct set of film coefficients (they change with speed only),
    and the contact terms of each window enter through a low-rank (Woodbury) update.
    """

    def __init__(self, problem: ThermalProblem, loads: ThermalLoads, dt: float, theta: float):
        self.problem, self.loads, self.dt, self.theta = problem, loads, dt, theta
        coeff, parts = problem.load_parts(loads)
        self.f = sum(parts.values())
        k_data = problem.conduction_data + problem.ops.data(coeff)
        c_data = problem.capacity_data / dt
        ops = problem.ops
        self._explicit = ops.csr(c_data - (1.0 - theta) * k_data)
        self._update = None
        dofs, values = problem.fixed(loads)
        if dofs.size or not problem.mesh.interfaces:
            self._solver = _LinearSolve(ops.csr(c_data + theta * k_data), dofs, values)
            return
        films = {k: v for k, v in coeff.items() if k.startswith("film:")}
        key = (dt, theta, tuple(sorted(films.items())))
        base = problem._base_factorizations.get(key)
        if base is None:
            if len(problem._base_factorizations) >= 8:  # bound memory: drop the oldest
                problem._base_factorizations.pop(next(iter(problem._base_factorizations)))
            U = sp.hstack([problem._interface_factors[n][0] for n in problem.mesh.interfaces])
            k_base = problem.conduction_data + ops.data(films)
            solver = _LinearSolve(ops.csr(c_data + theta * k_base), dofs, values)
            base = _BaseFactorization(solver, sp.csc_matrix(U))
            problem._base_factorizations[key] = base
        self._solver = base.solver
        W = sla.block_diag(
            *[
                theta * coeff[f"interface:{n}"] * problem._interface_factors[n][1]
                for n in problem.mesh.interfaces
            ]
        )
        capacitance = np.eye(W.shape[0]) + W @ base.UtZ
        self._update = (base, W, sla.lu_factor(capacitance))

    def step(self, T: np.ndarray) -> np.ndarray:
        """Advance one Δt from nodal temperature T (°C)."""
        y = self._solver.solve(self._explicit @ T + self.f)
        if self._update is None:
            return y

        base, W, lu = self._update
        return y - base.Z @ sla.lu_solve(lu, W @ (base.U.T @ y))
