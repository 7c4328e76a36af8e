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
from collections.abc import Callable, Mapping
from functools import partial

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree
from skfem import Basis, FacetBasis, asm

from twin.fem.balance import HeatBalance
from twin.fem.combine import PatternCombination
from twin.fem.elements import element_for
from twin.fem.forms import capacity, conduction, unit_load, unit_load_weighted
from twin.fem.linalg import DirichletSolver, LowRankUpdate, WoodburySolver, kept
from twin.fem.loads import ThermalLoads, field_values
from twin.fem.materials import Material
from twin.fem.mesh import AxiMesh
from twin.fem.probes import probe_matrix
from twin.fem.stepper import ThermalStepper

KEPT_FILM_SETS = 8
"""Film loads and heat-balance row sums kept per set of film coefficients (the newest; they
change with the speed only), as `LowRankUpdate` keeps its factorizations."""
KEPT_STEP_SIZES = 8  # time steps whose C/Δt a ThermalProblem keeps


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
        pattern = asm(capacity, self.basis)
        self._interface_jumps: dict[str, sp.csc_matrix] = {}
        self._interface_mass: dict[str, np.ndarray] = {}
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
            self.ops.add(f"conduction:{region}", asm(conduction, sub))
            self.ops.add(f"capacity:{region}", asm(capacity, sub))
            k_data += mat.k * self.ops.data({f"conduction:{region}": 1.0})
            c_data += mat.rho_c * self.ops.data({f"capacity:{region}": 1.0})
        self.conduction_data = k_data
        self.capacity_data = c_data
        self._facet_bases: dict[str, FacetBasis] = {}
        self._source_vectors: dict[str, np.ndarray] = {}
        self._region_bases: dict[str, Basis] = {}
        self._facet_loads: dict[str, np.ndarray] = {}
        self.capacity_vector = self.ops.csr(c_data) @ np.ones(self.n_dofs)
        """C·1, J/K per dof: the heat a dof stores per K."""
        # the contact terms are low rank, K_i = U_i M_i U_iᵀ: a window with new contact
        # resistances updates a factorization instead of making a new one
        self.contact_update = (
            LowRankUpdate(sp.hstack([self._interface_jumps[n] for n in mesh.interfaces]))
            if mesh.interfaces
            else None
        )
        # each interface's block on the diagonal of the update's W (its columns in U)
        ends = np.cumsum([self._interface_mass[n].shape[0] for n in mesh.interfaces])
        self._interface_blocks = {n: slice(int(e) - self._interface_mass[n].shape[0], int(e))
                                  for n, e in zip(mesh.interfaces, ends, strict=True)}
        # Σ h M_film·1 of the heat balance per set of film coefficients (they change with
        # the speed only, the balance is asked for every step): the newest few, as the
        # factorizations in `contact_update`
        self._film_rows: dict[tuple[tuple[str, float], ...], np.ndarray] = {}
        self._convection_loads: dict[tuple[tuple[str, float, float], ...], np.ndarray] = {}
        # C/Δt (read-only data on the pattern, and as a matrix) per Δt: backward Euler's
        # explicit side, asked for by every step of a loop that re-evaluates its loads
        self._capacity_rates: dict[float, tuple[np.ndarray, sp.csr_matrix]] = {}

    def on_mesh(self, mesh: AxiMesh) -> ThermalProblem:
        """This problem on `mesh`, a view of its own mesh (`AxiMesh.view`) that may name
        more sets: the assembled operators are shared, while the operators, loads and
        factorizations of named sets (those held so far included) are kept apart from here
        on.  An owner that names sets of its own on a view can then use a problem others
        share, and neither sees the other's names; nothing is assembled anew.

        ValueError unless `mesh` has this mesh's triangles, interfaces and every one of
        its regions and boundaries (the same arrays)."""
        own = self.mesh
        same = mesh.thermal is own.thermal and mesh.interfaces.keys() == own.interfaces.keys() \
            and all(mesh_sets.get(name) is members
                    for mesh_sets, own_sets in ((mesh.regions, own.regions),
                                                (mesh.boundaries, own.boundaries),
                                                (mesh.interfaces, own.interfaces))
                    for name, members in own_sets.items())
        if not same:
            raise ValueError("the mesh is not a view of this problem's mesh (AxiMesh.view)")
        other = object.__new__(ThermalProblem)
        other.__dict__.update(self.__dict__)
        other.mesh = mesh
        other.ops = self.ops.copy()
        for cache in ("_facet_bases", "_source_vectors", "_region_bases", "_facet_loads",
                      "_film_rows", "_convection_loads", "_capacity_rates"):
            setattr(other, cache, dict(getattr(self, cache)))
        if self.contact_update is not None:
            other.contact_update = self.contact_update.copy()
        return other

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
        m_a = asm(capacity, fbasis)
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
        self._interface_jumps[name] = sp.csc_matrix(jump.T)[:, dofs_a]
        self._interface_mass[name] = m_a[dofs_a][:, dofs_a].toarray()
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
            self.ops.add(key, asm(capacity, fb))
            self._facet_loads[boundary] = asm(unit_load, fb)
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
            self._source_vectors[region] = asm(unit_load, sub)
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
            values.append(field_values(t, self.basis.doflocs[:, d], f"boundary {boundary!r}"))
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

    def _weighted_load(self, value: float | Callable[[np.ndarray, np.ndarray], np.ndarray],
                       basis: Basis | None, unit: np.ndarray, what: str) -> np.ndarray:
        """∫ value·v 2πr over a (facet) basis; `unit` is the cached load of value = 1."""
        if not callable(value):
            return float(value) * unit
        x = np.asarray(basis.global_coordinates())
        return asm(unit_load_weighted, basis, s=field_values(value, x, what))

    def load_parts(self, loads: ThermalLoads) -> tuple[dict[str, float], dict[str, np.ndarray]]:
        """Film/interface coefficients and the load vectors (W) by kind.

        Returns (coefficients of the unit operators, {"sources", "flux", "convection"}).
        """
        coeff: dict[str, float] = {}
        parts = {k: np.zeros(self.n_dofs) for k in ("sources", "flux")}
        for region, q in loads.sources.items():
            unit = self.source_vector(region)
            basis = self._region_bases[region] if callable(q) else None
            parts["sources"] += self._weighted_load(q, basis, unit, f"region {region!r}")
        for boundary, q in loads.flux.items():
            unit = self.facet_load(boundary)
            parts["flux"] += self._weighted_load(
                q, self.facet_basis(boundary), unit, f"boundary {boundary!r}"
            )
        for boundary, (h, _) in loads.convection.items():
            coeff[self._boundary_terms(boundary)] = float(h)
        parts["convection"] = self._convection_load(loads.convection)
        for name in loads.contact_resistance:
            self.mesh.interface(name)
        for name in self.mesh.interfaces:
            r = loads.contact_resistance.get(name, self.PERFECT_CONTACT_R)
            coeff[f"interface:{name}"] = 1.0 / float(r)
        return coeff, parts

    def _convection_load(self, convection: dict[str, tuple[float, float]]) -> np.ndarray:
        """Σ h ∫ T∞ v 2πr ds over the convective boundaries (W; read-only).  With constant
        bulk temperatures it is kept per set of (h, T∞) in the boundaries' order, the order
        of the sum (a loop re-evaluating the bearing loads every step keeps its films):
        a hit is the vector made anew, to the bit."""
        def make() -> np.ndarray:
            load = np.zeros(self.n_dofs)
            for boundary, (h, t_inf) in convection.items():
                self._boundary_terms(boundary)
                load += float(h) * self._weighted_load(
                    t_inf,
                    self.facet_basis(boundary),
                    self._facet_loads[boundary],
                    f"boundary {boundary!r}",
                )
            load.flags.writeable = False
            return load

        if any(callable(t_inf) for _, t_inf in convection.values()):
            return make()
        key = tuple((b, float(h), float(t)) for b, (h, t) in convection.items())
        return kept(self._convection_loads, key, make, KEPT_FILM_SETS)

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
        return DirichletSolver(self.ops.csr(k_data), dofs, values).solve(f)

    def transient(self, loads: ThermalLoads, dt: float, theta: float = 1.0) -> ThermalStepper:
        """A stepper for fixed Δt (s): θ = 1 backward Euler, θ = 0.5 Crank–Nicolson."""
        if not (math.isfinite(dt) and dt > 0.0):
            raise ValueError(f"time step must be positive, got {dt!r}")
        if not (0.5 <= theta <= 1.0):
            raise ValueError(f"theta must lie in [0.5, 1], got {theta!r}")
        dt, theta = float(dt), float(theta)
        coeff, parts = self.load_parts(loads)
        c_data, c_matrix = kept(self._capacity_rates, dt, partial(self._capacity_rate, dt),
                                KEPT_STEP_SIZES)
        dofs, values = self.fixed(loads)
        # K on the pattern only where it is used: backward Euler's explicit side is C/Δt
        # (C/Δt − 0·K is C/Δt to the bit), and a solver by low-rank update builds its own
        k_data = None
        if theta != 1.0 or dofs.size or self.contact_update is None:
            k_data = self.conduction_data + self.ops.data(coeff)
        return ThermalStepper(
            self._step_solver(coeff, c_data, k_data, (dofs, values), dt, theta),
            c_matrix if k_data is None else self.ops.csr(c_data - (1.0 - theta) * k_data),
            sum(parts.values()),
            dt,
            theta,
            balance=partial(self._heat_balance, coeff, parts, dofs, dt, theta),
        )

    def _capacity_rate(self, dt: float) -> tuple[np.ndarray, sp.csr_matrix]:
        """C/Δt on the pattern (read-only) and as a CSR matrix sharing that data."""
        c_data = self.capacity_data / dt
        c_data.flags.writeable = False
        return c_data, self.ops.csr(c_data)

    def _step_solver(
        self,
        coeff: dict[str, float],
        c_data: np.ndarray,
        k_data: np.ndarray | None,
        fixed: tuple[np.ndarray, np.ndarray],
        dt: float,
        theta: float,
    ) -> DirichletSolver | WoodburySolver:
        """C/Δt + θK factorized (c_data = C/Δt, k_data = K on the shared pattern, needed
        with fixed temperatures or without contact interfaces only).

        Without fixed temperatures, C/Δt + θK less its contact terms is factorized once per
        distinct set of film coefficients (they change with speed only), and the contact
        terms of each load set enter through the low-rank update.  That base leaves the
        contacts out entirely (rather than taking the first resistances seen), so results
        never depend on which windows or runs came before: a batch gives the same numbers
        in one process or many.
        """
        dofs, values = fixed
        if dofs.size or self.contact_update is None:
            assert k_data is not None
            return DirichletSolver(self.ops.csr(c_data + theta * k_data), dofs, values)
        films = {k: v for k, v in coeff.items() if k.startswith("film:")}

        def base() -> DirichletSolver:
            k_base = self.conduction_data + self.ops.data(films)
            return DirichletSolver(self.ops.csr(c_data + theta * k_base), dofs, values)

        size = self.contact_update.U.shape[1]
        W = np.zeros((size, size))  # block diagonal, as scipy's block_diag but no checks
        for n, block in self._interface_blocks.items():
            W[block, block] = theta * coeff[f"interface:{n}"] * self._interface_mass[n]
        key = (dt, theta, tuple(sorted(films.items())))
        return self.contact_update.solver(key, base, W)

    def heat_balance(self, loads: ThermalLoads, dt: float, theta: float = 1.0) -> HeatBalance:
        """The heat balance of a θ-step of Δt (s) under `loads` (see `twin.fem.balance`)."""
        coeff, parts = self.load_parts(loads)
        return self._heat_balance(coeff, parts, self.fixed(loads)[0], float(dt), float(theta))

    def _heat_balance(
        self,
        coeff: dict[str, float],
        parts: dict[str, np.ndarray],
        dofs: np.ndarray,
        dt: float,
        theta: float,
    ) -> HeatBalance:
        films = {k: c for k, c in coeff.items() if k.startswith("film:")}
        fixed = {}
        if dofs.size:
            K = self.ops.csr(self.conduction_data + self.ops.data(coeff))
            C = self.ops.csr(self.capacity_data)
            fixed = {
                "fixed_capacity": np.asarray(C[dofs].sum(axis=0)).ravel(),
                "fixed_conductance": np.asarray(K[dofs].sum(axis=0)).ravel(),
                "fixed_load_W": float(sum(parts.values())[dofs].sum()),
            }
        return HeatBalance(
            dt=dt,
            theta=theta,
            capacity=self.capacity_vector,
            sources_W=float(parts["sources"].sum()),
            flux_W=float(parts["flux"].sum()),
            film=self._film_row_sums(films),
            film_load_W=float(parts["convection"].sum()),
            **fixed,
        )

    def _film_row_sums(self, films: dict[str, float]) -> np.ndarray:
        """Σ h M_film·1 (W/K per dof) of film coefficients `films`; read-only.  Keyed in
        the films' order, the order of the sum: a hit is the vector made anew, to the bit."""
        def make() -> np.ndarray:
            rows = self.ops.matrix(films) @ np.ones(self.n_dofs)
            rows.flags.writeable = False
            return rows

        return kept(self._film_rows, tuple(films.items()), make, KEPT_FILM_SETS)

    def energy_balance(
        self,
        T_old: np.ndarray,
        T_new: np.ndarray,
        loads: ThermalLoads,
        dt: float,
        theta: float = 1.0,
    ) -> dict[str, float]:
        """Discrete heat balance of one step T_old → T_new (°C), W.

        stored = sources + flux + fixed_in − convection_out; `residual_W` is what is left,
        round-off for an exact linear solve.  `heat_in_W` = sources + flux,
        `heat_out_W` = convection out + heat drawn by fixed temperatures.
        In a loop, `ThermalStepper.energy_balance` reuses the prepared terms.
        """
        return self.heat_balance(loads, dt, theta)(T_old, T_new)

    def probe(self, points_rz: np.ndarray) -> sp.csr_matrix:
        """Interpolation matrix P (n_points × n_dofs): T(points) = P @ T."""
        pts = np.atleast_2d(np.asarray(points_rz, dtype=float))
        if pts.shape[0] != 2:
            pts = pts.T
        return probe_matrix(self.basis, pts)
