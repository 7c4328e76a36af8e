"""`SessionState`: what one APDL-like session holds, as small objects with one owner each.

    db        the APDL database (nodes, elements, materials, loads, settings): written by
              the /PREP7 and load commands (`apdl_like.commands`)
    params    scalar parameters: assignments, *SET, *GET, *DO
    fem       `FemCache`, the FEM view of the mesh and the assembled problems: written by
              `apdl_like.solve` only
    solution  `Solution`, the temperature state, time and solved load steps: written by
              `apdl_like.solve` (SOLVE), ANTYPE (new analysis or restart) and
              `Session.set_state` / `Session.advance`
    budget    `RunBudget`, the per-run counters that keep a deck finite: written by
              `apdl_like.interpreter`; reset by `Session.run_program`
    listing   `Listing`: the run's log, warnings and the files the deck writes (/OUT,
              *CFOPEN), kept in memory until the CLI writes them inside --out
    saved     SAVE/RESUME: named copies of the database and parameters, in memory
    processor, base_dir, inputs, strict, record_only, recorded_solves
              the deck context: processor commands, /INPUT folder and the files /INPUT
              read, unknown commands as errors (--strict), the solve-recording mode of
              `Session.read_window_deck`

Command handlers take a `SessionState`; nothing here imports the commands or the session.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from apdl_like.errors import ApdlError
from apdl_like.fem_bridge import FemModel, nearest_node
from apdl_like.model import Database, RecordPartition

if TYPE_CHECKING:
    from apdl_like.parser import Statement
    from twin.fem import ElasticProblem, ThermalProblem

TCC_LOCATION = 14  # real-constant position of TCC (thermal contact conductance) on CONTA17x


class LocatedCall(Protocol):
    """What `SessionState.note_load` reads of an apdl_like.call.Call (which imports this
    module, so it is not named here): the statement it was made from."""

    @property
    def statement(self) -> Statement: ...


@dataclass
class StepResult:
    """One solved load step (its last substep)."""

    load_step: int
    time: float
    analysis: str  # "thermal" | "structural"
    temperature: np.ndarray  # thermal dofs, °C (structural: the body temperature used)
    displacement: np.ndarray | None = None  # (2, n glued scalar dofs), m
    stress: dict[str, np.ndarray] = field(default_factory=dict)  # glued scalar dofs, Pa
    nodal_temperature: np.ndarray | None = None  # per APDL node, °C (NaN: no element)
    # per APDL node: UX, UY (m), SX, SY, SZ, SXY, SEQV (Pa; averaged nodal stresses)
    nodal_structural: dict[str, np.ndarray] = field(default_factory=dict)

    @classmethod
    def structural(cls, load_step: int, time: float, temperature: np.ndarray,
                   displacement: np.ndarray, stress: dict[str, np.ndarray],
                   to_nodes: Callable[[np.ndarray], np.ndarray],
                   nodal_temperature: np.ndarray) -> StepResult:
        """A structural step; `to_nodes` maps a scalar field on the dofs to the APDL nodes."""
        nodal = {"UX": to_nodes(displacement[0]), "UY": to_nodes(displacement[1])}
        for item, key in (("SX", "rr"), ("SY", "zz"), ("SZ", "tt"), ("SXY", "rz"),
                          ("SEQV", "von_mises")):
            nodal[item] = to_nodes(stress[key])
        return cls(load_step, time, "structural", temperature, displacement, stress,
                   nodal_temperature=nodal_temperature, nodal_structural=nodal)


@dataclass
class FemCache:
    """The FEM view of the mesh and the problems assembled on it (owner: apdl_like.solve).

    Each entry is rebuilt only when its key (mesh version, materials, constraints) changes.
    """

    model: FemModel | None = None
    model_key: tuple | None = None
    external_mesh: bool = False  # the mesh came from an AxiMesh: N/E may not change it
    thermal: ThermalProblem | None = None
    thermal_key: tuple | None = None
    thermal_inputs: tuple | None = None  # the MP/ANTYPE inputs `thermal` was checked against
    elastic: ElasticProblem | None = None
    elastic_key: tuple | None = None
    # the load groups of the last thermal SOLVE by kind (hgen, conv, hflux) and the regions
    # and boundaries they were named: reused while a load step loads the same sets
    partitions: dict[str, RecordPartition] = field(default_factory=dict)
    # a deck's own mesh (apdl_like.plane_solve): exterior faces, scikit-fem mesh, solver
    faces: Any = None
    faces_key: tuple | None = None
    plane: Any = None
    plane_key: tuple | None = None
    plane_solver: tuple | None = None  # (key, PlaneThermal)
    plane_inputs: Any = None  # the loads of the last thermal solve (reaction heats)


@dataclass
class Solution:
    """Temperature state, time and solved load steps (owner: apdl_like.solve)."""

    temperature: np.ndarray | None = None  # thermal dofs at `time`, °C
    time: float = 0.0  # s
    fresh_start: bool = True  # the next thermal SOLVE starts from TUNIF/IC (ANTYPE, NEW)
    previous_loads: dict | None = None  # loads of the last load step (start of KBC,0 ramps)
    body_temperature: StepResult | None = None  # LDREAD: the thermal result to apply
    substep_times: list[float] = field(default_factory=list)  # of the last load step, s
    substep_temperatures: list[np.ndarray] = field(default_factory=list)
    # every substep of every load step of the current analysis on a deck's own mesh (what
    # OUTRES,ALL keeps in MAPDL's results file: SET by TIME and NSOL read it), s and °C
    history_times: list[float] = field(default_factory=list)
    history_temperatures: list[np.ndarray] = field(default_factory=list)
    results: list[StepResult] = field(default_factory=list)
    post_index: int = -1  # result set shown in /POST1 (SET)
    post_result: StepResult | None = None  # SET,,,,,TIME: a set between stored times
    new_analysis: bool = True  # the next SOLVE starts a new results file (its load step 1)

    def span_to(self, end_time: float | None) -> float:
        """The length (s) of a transient load step from now to its TIME `end_time`."""
        if end_time is None:
            raise ApdlError("a transient load step needs its end time (TIME)")
        span = end_time - self.time
        if not span > 0.0:
            raise ApdlError(f"TIME {end_time!r} is not after the current time {self.time!r}")
        return span


@dataclass
class RunBudget:
    """Per-run counters that keep a deck finite, and the first load not yet solved."""

    statements_run: int = 0
    loop_iterations: int = 0
    unsolved: tuple[str, int, str] | None = None  # (file, line, command) after the last SOLVE


@dataclass
class Listing:
    """Where output goes: the log, or the file named by /OUT (in memory, by file name)."""

    log: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    files: dict[str, list[str]] = field(default_factory=dict)
    target: str | None = None  # /OUT file receiving output; None: the log
    command_file: str | None = None  # *CFOPEN file receiving *CFWRITE lines
    errors: int = 0  # *MSG,ERROR messages (MAPDL's error count; the run goes on)

    def write(self, text: str) -> None:
        if self.target is None:
            self.log.append(text)
        else:
            self.files[self.target].append(text)


@dataclass
class Radiation:
    """/AUX12: the view-factor geometry (V2DOPT; None: the elements' own), the factors of
    the RDSF faces (key, (F, areas, owners)) and the last VFQUERY average."""

    axisymmetric: bool | None = None
    factors: tuple | None = None
    average: float | None = None


@dataclass
class SessionState:
    """Everything a deck reads and writes (see the module docstring for the owners)."""

    db: Database = field(default_factory=Database)
    params: dict[str, float] = field(default_factory=dict)
    fem: FemCache = field(default_factory=FemCache)
    solution: Solution = field(default_factory=Solution)
    budget: RunBudget = field(default_factory=RunBudget)
    listing: Listing = field(default_factory=Listing)
    saved: dict[str, tuple[Database, dict]] = field(default_factory=dict)
    processor: str = "BEGIN"
    base_dir: Path | None = None
    inputs: list[Path] = field(default_factory=list)  # files /INPUT read: no output replaces one
    strict: bool = False  # an unknown command is an error, not a warning
    # /POST26 variables: number -> (name, times s, values); FSUM's last total heat, W
    variables: dict[int, tuple[str, np.ndarray, np.ndarray]] = field(default_factory=dict)
    fsum_heat: float | None = None
    # ETABLE columns (per element of the table) and SSUM's last totals
    element_table: dict[str, np.ndarray] = field(default_factory=dict)
    element_sums: dict[str, float] = field(default_factory=dict)
    # the last sort, NSORT's or ESORT's: its command, the node or element numbers and the
    # sort keys in sorted order (*GET,,SORT reads it); ESORT's element order (indices of
    # the element table, sorted first) for PRETAB, None after EUSORT
    last_sort: tuple[str, np.ndarray, np.ndarray] | None = None
    element_order: np.ndarray | None = None
    told: set[str] = field(default_factory=set)  # warnings given once a run (PRESOL)
    # PLNSOL's item and its (max, min) over the selected nodes (*GET,,PLNSOL reads it);
    # (item, None) for an item PLNSOL cannot give here
    plot_extremes: tuple[str, tuple[float, float] | None] | None = None
    radiation: Radiation = field(default_factory=Radiation)
    load_steps: dict[int, dict] = field(default_factory=dict)  # LSWRITE, in memory
    record_only: bool = False  # SOLVE records what it would solve instead of solving
    recorded_solves: list[dict] = field(default_factory=list)
    model_functions: dict[str, Any] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.model_functions = {
            "NX": self._nx, "NY": self._ny, "NZ": self._nz, "NODE": self._node,
            "TEMP": self._temp, "UX": self._ux, "UY": self._uy,
        }

    # ------------------------------------------------------------- messages
    @property
    def log(self) -> list[str]:
        return self.listing.log

    def say(self, text: str) -> None:
        """A line of output: to the /OUT file when one is open, else to the log."""
        self.listing.write(text)

    def warn(self, warning: ApdlError) -> None:
        """A located warning (an unknown command): kept, and shown in the log."""
        text = f"warning: {warning}"
        self.listing.warnings.append(text)
        self.listing.log.append(text)

    def note_load(self, call: LocatedCall) -> None:
        """Remember the first load after the last SOLVE (a deck must not end there)."""
        if self.budget.unsolved is None:
            st = call.statement
            self.budget.unsolved = (st.file, st.line, st.name)

    # ------------------------------------------------------ model functions
    def node_index(self, n: float) -> int:
        """Position of node number `n` in the node table (ApdlError if it does not exist)."""
        i = int(self.db.nodes.index(int(round(n)))[0]) if abs(n) < 2**31 else -1
        if i < 0:
            raise ApdlError(f"node {n:g} does not exist")
        return i

    def node_location(self, n: float) -> np.ndarray:
        """(X, Y) of node n in the active coordinate system (MAPDL's NX, NY, *GET LOC)."""
        i = self.node_index(n)  # first: it merges pending nodes, which replaces .xy
        return self.db.active_system.from_global(self.db.nodes.xy[i])[0]

    def _nx(self, n: float) -> float:
        return float(self.node_location(n)[0])

    def _ny(self, n: float) -> float:
        return float(self.node_location(n)[1])

    def _nz(self, n: float) -> float:
        self.node_index(n)
        return 0.0

    def _node(self, x: float, y: float, z: float = 0.0) -> float:
        db = self.db
        point = np.array(db.active_system.to_global(x, y))  # given in the active system
        i = nearest_node(db.nodes.xy, db.nodes.selected, point)
        return 0.0 if i < 0 else float(db.nodes.ids[i])

    def _temp(self, n: float) -> float:
        return self.nodal_result("TEMP", n)

    def _ux(self, n: float) -> float:
        return self.nodal_result("UX", n)

    def _uy(self, n: float) -> float:
        return self.nodal_result("UY", n)

    # -------------------------------------------------------------- results
    def result(self) -> StepResult:
        """The result set shown in /POST1 (the last one unless SET chose another)."""
        results = self.solution.results
        if not results:
            raise ApdlError("no results yet (SOLVE first)")
        if self.solution.post_result is not None:
            return self.solution.post_result
        return results[self.solution.post_index]

    def nodal_result(self, item: str, n: float) -> float:
        """TEMP, UX, UY, SX, SY, SZ, SXY, SEQV at node n from the current result set."""
        i = self.node_index(n)
        res = self.result()
        if item == "TEMP":
            value = res.nodal_temperature[i]
        elif not res.nodal_structural:
            raise ApdlError(f"{item} needs a structural result (the current one is thermal)")
        else:
            value = res.nodal_structural[item][i]
        if np.isnan(value):
            raise ApdlError(f"node {n:g} is not attached to an element (no {item})")
        return float(value)

    # -------------------------------------------------------------- outputs
    def scalar_parameters(self) -> dict[str, float]:
        """The numeric scalar parameters (arrays and character values left out)."""
        return {k.upper(): float(v) for k, v in sorted(self.params.items())
                if isinstance(v, float | int)}

    def contact_conductance(self) -> dict[str, float]:
        """Current TCC (W/m²K) per contact interface that has one."""
        out = {}
        for name, real in self.db.contact_real_sets.items():
            tcc = self.db.real_sets.get(real, {}).get(TCC_LOCATION)
            if tcc is not None:
                out[name] = tcc
        return out
