"""`Session`: one APDL database plus the FEM state, kept alive between decks.

A session runs decks (`run_file`, `run_text`) against one database.  Mesh, materials and the
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
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

import apdl_like.commands.begin  # noqa: F401  (registers commands)
import apdl_like.commands.blocks  # noqa: F401
import apdl_like.commands.loads  # noqa: F401
import apdl_like.commands.post1  # noqa: F401
import apdl_like.commands.prep7  # noqa: F401
import apdl_like.commands.selection  # noqa: F401
import apdl_like.commands.solution  # noqa: F401
from apdl_like.errors import ApdlError
from apdl_like.fem_bridge import FemModel, nearest_node
from apdl_like.interpreter import execute
from apdl_like.model import Component, Database, ElementType
from apdl_like.model import Material as MpTable
from apdl_like.parser import Program, parse_deck, read_deck
from apdl_like.solve import TCC_LOCATION, StepResult
from apdl_like.writer import DeckLayout, component_name
from twin.fem import AxiMesh, Material, ThermalProblem


class Session:
    """A persistent APDL-like session (database, parameters, FEM caches, results)."""

    def __init__(self, base_dir: str | Path | None = None) -> None:
        self.db = Database()
        self.params: dict[str, float] = {}
        self.processor = "BEGIN"
        self.title = ""
        self.log: list[str] = []
        self.base_dir = Path(base_dir) if base_dir is not None else None
        self.results: list[StepResult] = []
        self.post_index = -1  # result set shown in /POST1 (SET)
        # FEM state
        self.fem: FemModel | None = None
        self.fem_key: tuple | None = None
        self.external_mesh = False
        self.thermal = None
        self.thermal_key: tuple | None = None
        self.elastic = None
        self.elastic_key: tuple | None = None
        self.state: np.ndarray | None = None  # thermal dofs at `time`
        self.time = 0.0
        self.fresh_start = True
        self.previous_loads: dict | None = None
        self.body_temperature: np.ndarray | None = None  # LDREAD, thermal dofs
        self.substep_times: list[float] = []
        self.substep_temperatures: list[np.ndarray] = []
        self.contact_real_sets: dict[str, int] = {}
        self.layout: DeckLayout | None = None
        self.last_real: tuple[int, int] | None = None  # (set, next location) for RMORE
        self.solve_enabled = True
        self.recorded_solves: list[dict] = []  # with solve_enabled False: what SOLVE saw
        # run bookkeeping
        self.statements_run = 0
        self.loop_iterations = 0
        self.unsolved: tuple[str, int, str] | None = None  # first load after the last SOLVE
        self.model_functions = {
            "NX": self._nx, "NY": self._ny, "NZ": self._nz, "NODE": self._node,
            "TEMP": self._temp, "UX": self._ux, "UY": self._uy,
        }

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
        from apdl_like.fem_bridge import FemModel

        s = cls(base_dir)
        db = s.db
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
        s.contact_real_sets = dict(layout.interfaces)
        for name, iface in mesh.interfaces.items():
            for side, facets in (("A", iface.facets_a), ("B", iface.facets_b)):
                cname = component_name(name)[:30] + f"_{side}"
                db.components[cname] = Component(
                    "NODE", np.unique(mesh.thermal.facets[:, facets]) + 1)
            db.real_sets[s.contact_real_sets[name]] = {}
        db.settings.tunif = float(T_initial_C)
        db.settings.tref = float(T_ref_C)
        fem = FemModel(mesh, np.arange(n), np.arange(mesh.n_cells), order, db.nodes.ids)
        db.faces.rekey(fem.face_keys)
        s.fem, s.fem_key, s.external_mesh = fem, (db.nodes.version, db.elements.version), True
        if thermal is not None:
            from apdl_like.solve import adopt_thermal_problem

            adopt_thermal_problem(s, thermal)
        return s

    def set_state(self, temperature: np.ndarray, time_s: float) -> None:
        """Carry a temperature state (thermal dofs, °C) in at `time_s` (e.g. a resumed run)."""
        self.state = np.asarray(temperature, float).copy()
        self.time = float(time_s)
        self.fresh_start = False

    # ----------------------------------------------------------------- runs
    def run_file(self, path: str | Path) -> None:
        path = Path(path)
        if self.base_dir is None:
            self.base_dir = path.parent
        self.run_program(read_deck(path, str(path)))

    def run_text(self, text: str, file: str = "<deck>") -> None:
        self.run_program(parse_deck(text, file))

    def run_program(self, program: Program) -> None:
        self.statements_run = 0
        self.loop_iterations = 0
        self.unsolved = None
        execute(self, program)
        if self.unsolved is not None:
            file, line, cmd = self.unsolved
            raise ApdlError("loads or solution settings given here are never solved "
                            "(the deck ends without SOLVE)", file=file, line=line, command=cmd)

    def note_load(self, call) -> None:  # noqa: ANN001 - a commands.Call
        if self.unsolved is None:
            st = call.statement
            self.unsolved = (st.file, st.line, st.name)

    def say(self, text: str) -> None:
        self.log.append(text)

    # ------------------------------------------------------ model functions
    def _node_index(self, n: float) -> int:
        i = int(self.db.nodes.index(int(round(n)))[0]) if abs(n) < 2**31 else -1
        if i < 0:
            raise ApdlError(f"node {n:g} does not exist")
        return i

    def _nx(self, n: float) -> float:
        return float(self.db.nodes.xy[self._node_index(n), 0])

    def _ny(self, n: float) -> float:
        return float(self.db.nodes.xy[self._node_index(n), 1])

    def _nz(self, n: float) -> float:
        self._node_index(n)
        return 0.0

    def _node(self, x: float, y: float, z: float = 0.0) -> float:
        db = self.db
        i = nearest_node(db.nodes.xy, db.nodes.selected, np.array([x, y]))
        return 0.0 if i < 0 else float(db.nodes.ids[i])

    def result(self) -> StepResult:
        if not self.results:
            raise ApdlError("no results yet (SOLVE first)")
        return self.results[self.post_index]

    def nodal_result(self, item: str, n: float) -> float:
        """TEMP, UX, UY, SX, SY, SZ, SXY, SEQV at node n from the current result set."""
        i = self._node_index(n)
        res = self.result()
        fem = self.fem
        assert fem is not None
        if item == "TEMP":
            d = fem.thermal_dof[i]
            value = res.temperature[d] if d >= 0 else np.nan
        elif res.displacement is None:
            raise ApdlError(f"{item} needs a structural result (the current one is thermal)")
        else:
            d = fem.glued_dof[i]
            if item in ("UX", "UY"):
                value = res.displacement[0 if item == "UX" else 1, d] if d >= 0 else np.nan
            else:
                key = {"SX": "rr", "SY": "zz", "SZ": "tt", "SXY": "rz", "SEQV": "von_mises"}[item]
                value = res.stress[key][d] if d >= 0 else np.nan
        if np.isnan(value):
            raise ApdlError(f"node {n:g} is not attached to an element (no {item})")
        return float(value)

    def _temp(self, n: float) -> float:
        return self.nodal_result("TEMP", n)

    def _ux(self, n: float) -> float:
        return self.nodal_result("UX", n)

    def _uy(self, n: float) -> float:
        return self.nodal_result("UY", n)

    # -------------------------------------------------------------- outputs
    def scalar_parameters(self) -> dict[str, float]:
        return {k.upper(): float(v) for k, v in sorted(self.params.items())}

    def contact_conductance(self) -> dict[str, float]:
        """Current TCC (W/m²K) per contact interface that has one."""
        out = {}
        for name, real in self.contact_real_sets.items():
            tcc = self.db.real_sets.get(real, {}).get(TCC_LOCATION)
            if tcc is not None:
                out[name] = tcc
        return out
