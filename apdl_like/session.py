"""`Session`: one APDL database plus the FEM state, kept alive between decks.

A session runs decks (`run_file`, `run_text`) against one `SessionState` (database,
parameters, FEM cache, solution, run budget; see `apdl_like.state` for who writes what).
The twin's loop calls `advance(T, start_s, deck)`: one window deck from a given
temperature state, returning the temperature of every substep.  Mesh, materials and the
assembled operators stay in memory, so a window deck that only changes loads and time
re-uses them.  For the twin, `Session.from_mesh` loads an `AxiMesh` directly:

    nodes      thermal-mesh vertices, numbered 1..n (vertex i is node i+1)
    elements   triangles, numbered 1..n_cells, PLANE55 (order 1) or PLANE77 (order 2), K = L
    materials  one MAT number per region, in sorted region-name order (MP from `Material`)
    components regions -> element components, boundaries -> node components (upper-case);
               each interface side -> node components NAME_A / NAME_B
    contact    each interface is a contact pair with real set 101 + i (i in sorted
               interface-name order, `apdl_like.writer.DeckLayout`); its TCC (real
               constant 14, W/m²K) is
               the thermal contact conductance 1/R, mapped onto
               `ThermalLoads.contact_resistance[name] = 1/TCC`
    load sets  a load on elements or faces that no region or boundary holds exactly falls
               on a set the session names itself (_cellsN / _facesN, N the number of
               sets it knew by name, the mesh's own included), on its own view of the
               mesh (`apdl_like.fem_bridge`): the AxiMesh given, which the loop's
               sessions share, keeps its own sets only, the ThermalProblem given holds
               no load of the session's sets, and no session's names depend on another's
               decks
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from apdl_like.errors import ApdlError
from apdl_like.fem_bridge import FemModel
from apdl_like.interpreter import execute
from apdl_like.loadset import LoadSet, load_set_from_record
from apdl_like.model import Component, Database, ElementType
from apdl_like.model import Material as MpTable
from apdl_like.parser import Program, parse_deck, read_deck
from apdl_like.solve import adopt_thermal_problem
from apdl_like.state import SessionState, StepResult
from apdl_like.writer import DeckLayout, component_name
from twin.fem import AxiMesh, Material, ThermalProblem


class Session:
    """A persistent APDL-like session: runs decks against one `SessionState`."""

    def __init__(self, base_dir: str | Path | None = None, strict: bool = False) -> None:
        """base_dir  the folder /INPUT reads from; strict  unknown commands are errors"""
        self.state = SessionState(base_dir=Path(base_dir) if base_dir is not None else None,
                                  strict=strict)
        self.layout: DeckLayout | None = None  # the deck names of an AxiMesh's sets

    # read-only views the callers use most
    @property
    def db(self) -> Database:
        return self.state.db

    @property
    def params(self) -> dict[str, float]:
        return self.state.params

    @property
    def results(self) -> list[StepResult]:
        return self.state.solution.results

    @property
    def log(self) -> list[str]:
        return self.state.listing.log

    @property
    def thermal(self) -> ThermalProblem | None:
        """The cached ThermalProblem (None before the first thermal SOLVE)."""
        return self.state.fem.thermal

    # ------------------------------------------------------------ the twin
    @classmethod
    def from_mesh(
        cls,
        mesh: AxiMesh,
        materials: Mapping[str, Material],
        order: int = 1,
        T_initial_C: float = 20.0,
        T_ref_C: float = 20.0,
        base_dir: str | Path | None = None,
        thermal: ThermalProblem | None = None,
    ) -> Session:
        """A session whose database holds `mesh` (see the module docstring for numbering).

        thermal  an already assembled ThermalProblem of this mesh, materials and order to
                 adopt instead of assembling another one
        """
        s = cls(base_dir)
        db = s.state.db
        n = mesh.thermal.p.shape[1]
        db.nodes.set_arrays(np.arange(1, n + 1), mesh.thermal.p.T)
        names = sorted(materials)
        mat_of_region = {name: i + 1 for i, name in enumerate(names)}
        cell_mat = np.zeros(mesh.n_cells, np.int64)
        for name in names:
            cell_mat[mesh.region(name)] = mat_of_region[name]
        if np.any(cell_mat == 0):
            raise ValueError(f"{int(np.sum(cell_mat == 0))} cells have no material")
        t = mesh.thermal.t
        nodes = np.column_stack([t[0], t[1], t[2], t[2]]) + 1
        db.element_types[1] = ElementType("PLANE55" if order == 1 else "PLANE77", {3: 1})
        db.elements.set_arrays(np.arange(1, mesh.n_cells + 1), np.ones(mesh.n_cells, np.int64),
                               cell_mat, np.ones(mesh.n_cells, np.int64), nodes)
        for name, m in materials.items():
            db.materials[mat_of_region[name]] = MpTable({
                "KXX": m.k, "DENS": m.rho, "C": m.c, "EX": m.E, "PRXY": m.nu, "ALPX": m.alpha})
        layout = DeckLayout.for_mesh(mesh)
        s.layout = layout
        for name, cells in mesh.regions.items():
            db.components[layout.regions[name]] = Component("ELEM", np.sort(cells + 1))
        for name, facets in mesh.boundaries.items():
            db.components[layout.boundaries[name]] = Component(
                "NODE", np.unique(mesh.thermal.facets[:, facets]) + 1)
        db.contact_real_sets = dict(layout.interfaces)
        for name, iface in mesh.interfaces.items():
            for side, facets in (("A", iface.facets_a), ("B", iface.facets_b)):
                cname = component_name(name)[:30] + f"_{side}"
                db.components[cname] = Component(
                    "NODE", np.unique(mesh.thermal.facets[:, facets]) + 1)
            db.real_sets[db.contact_real_sets[name]] = {}
        db.settings.tunif = float(T_initial_C)
        db.settings.tref = float(T_ref_C)
        fem = FemModel(mesh, np.arange(n), np.arange(mesh.n_cells), order, db.nodes.ids)
        db.faces.rekey(fem.face_keys)
        cache = s.state.fem
        cache.model, cache.model_key = fem, (db.nodes.version, db.elements.version)
        cache.external_mesh = True
        if thermal is not None:
            adopt_thermal_problem(s.state, thermal)
        return s

    def set_state(self, temperature: np.ndarray, time_s: float) -> None:
        """Carry a temperature state (thermal dofs, °C) in at `time_s` (e.g. a resumed run)."""
        sol = self.state.solution
        sol.temperature = np.asarray(temperature, float).copy()
        sol.time = float(time_s)
        sol.fresh_start = False

    def start_from_nodes(self, points_rz: np.ndarray, nodal_C: np.ndarray, time_s: float,
                         source: str = "<state>") -> None:
        """Carry a nodal temperature state (one value per APDL node, at the nodes' own
        (r, z) `points_rz`) in at `time_s`: what ANTYPE,,REST continues from.  ApdlError
        naming `source` unless it holds a finite value for every node of this model."""
        from apdl_like.solve import fem_model

        nodes = self.state.db.nodes
        nodal_C = np.asarray(nodal_C, float)
        if nodal_C.shape != (len(nodes.ids),) or np.shape(points_rz) != (len(nodes.ids), 2):
            raise ApdlError(f"the state holds {nodal_C.size} nodes, the model "
                            f"{len(nodes.ids)}: not a state of this model", file=source)
        if not np.allclose(points_rz, nodes.xy, rtol=0.0, atol=1e-9):
            raise ApdlError("the state's nodes are not this model's nodes (coordinates "
                            "differ)", file=source)
        fem = fem_model(self.state)
        thermal = fem.mesh.thermal
        n_dofs = thermal.p.shape[1] + (thermal.facets.shape[1] if fem.order == 2 else 0)
        T = fem.nodal_to_thermal(nodal_C, np.full(n_dofs, np.nan))
        if not np.all(np.isfinite(T)):
            raise ApdlError("the state leaves nodes without a finite TEMP", file=source)
        self.set_state(T, time_s)

    def advance(self, T: np.ndarray, start_s: float, deck: str,
                file: str = "<window deck>") -> np.ndarray:
        """Run one window deck from temperature `T` (thermal dofs, °C) at `start_s`.

        Returns the temperature after every substep of the deck's load step, shape
        (n_substeps, n_dofs).  At `start_s` = 0 a uniform `T` becomes TUNIF, which a new
        analysis (ANTYPE,TRANS) starts from; a non-uniform one is the state a restart
        (ANTYPE,TRANS,REST) continues from, as at a later start.  The session's results are
        this deck's only (`results`).
        """
        T = np.asarray(T, float)
        # the deck needs no earlier deck's result (its start state is handed in): kept, a
        # replay's session held one result per solver step (about 35 kB each) and every
        # SOLVE counted its load step through all of them
        self.state.solution.results = []
        if start_s == 0.0 and T.size and np.all(T == T[0]):
            self.state.db.settings.tunif = float(T[0])
        else:
            self.set_state(T, start_s)
        self.run_text(deck, file)
        return np.asarray(self.state.solution.substep_temperatures)

    def read_window_deck(self, text: str, file: str = "<window deck>") -> LoadSet:
        """Run a window deck without solving and return the load set it applies.

        The session (normally a dedicated one from `Session.from_mesh`) keeps the loads.
        """
        state = self.state
        state.record_only = True
        before = len(state.recorded_solves)
        try:
            self.run_text(text, file)
        finally:
            state.record_only = False
        if len(state.recorded_solves) != before + 1:
            raise ApdlError("a window deck must SOLVE exactly once", file=file)
        return load_set_from_record(state.recorded_solves[-1], file)

    # ----------------------------------------------------------------- runs
    def run_file(self, path: str | Path) -> None:
        path = Path(path)
        if self.state.base_dir is None:
            self.state.base_dir = path.parent
        self.run_program(read_deck(path, str(path)))

    def run_text(self, text: str, file: str = "<deck>") -> None:
        self.run_program(parse_deck(text, file))

    def run_program(self, program: Program) -> None:
        budget = self.state.budget
        budget.statements_run = 0
        budget.loop_iterations = 0
        budget.unsolved = None
        execute(self.state, program)
        if budget.unsolved is not None:
            file, line, cmd = budget.unsolved
            raise ApdlError("loads or solution settings given here are never solved "
                            "(the deck ends without SOLVE)", file=file, line=line, command=cmd)
