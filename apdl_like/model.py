"""The APDL database: nodes, elements, attributes, components, selections and loads.

Entities carry their APDL numbers; tables are numpy arrays sorted by number, so selecting
and loading thousands of entities in a window deck is a handful of vectorized operations.
Nodes and elements added one by one (`N`, `E`) wait in a small pending dict and are merged
when a command next reads the tables; every per-node and per-element array (selection,
loads) is carried over to the new numbering at that moment.

Face loads (SF, SFE) live on the exterior faces of the mesh, which `apdl_like.fem_bridge`
derives from the elements; they are stored per face and keyed by the sorted pair of corner
node numbers, so they survive a rebuild of the face table.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from apdl_like.coordinates import GLOBAL_SYSTEMS, CoordinateSystem
from apdl_like.errors import ApdlError

PAIR_BASE = np.int64(1) << 31  # node numbers are < 2^31: (lo, hi) packs into one int64


def pair_keys(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """One int64 key per unordered node pair (a[i], b[i]): an element face by its corner
    node numbers, whichever way round an element lists them."""
    lo, hi = np.minimum(a, b).astype(np.int64), np.maximum(a, b).astype(np.int64)
    return lo * PAIR_BASE + hi


# Element types this subset knows: name -> (physics, corner nodes, quadratic?)
ELEMENT_TYPES: dict[str, tuple[str, int, bool]] = {
    "PLANE55": ("thermal", 4, False),
    "PLANE77": ("thermal", 4, True),
    "PLANE182": ("structural", 4, False),
    "PLANE183": ("structural", 4, True),
    "PLANE35": ("thermal", 3, True),
    # surface effect elements: they carry face loads (SFE) onto the solid's exterior faces
    "SURF151": ("surface", 2, False),
    # thermal line and point elements (apdl_like.line_thermal): they couple their nodes
    "LINK31": ("line", 2, False),
    "LINK32": ("line", 2, False),
    "LINK33": ("line", 2, False),
    "LINK34": ("line", 2, False),
    "MASS71": ("line", 1, False),
}
# ETCHG,TTS / STT pairs (thermal <-> structural)
THERMAL_TO_STRUCTURAL = {"PLANE55": "PLANE182", "PLANE77": "PLANE183"}
MAX_ELEMENT_NODES = 8


@dataclass
class ElementType:
    name: str
    keyopt: dict[int, int] = field(default_factory=dict)

    @property
    def physics(self) -> str:
        """thermal, structural, surface, line, or unsupported (3-D types read from an archive)."""
        return ELEMENT_TYPES[self.name][0] if self.name in ELEMENT_TYPES else "unsupported"

    @property
    def quadratic(self) -> bool:
        return ELEMENT_TYPES[self.name][2] if self.name in ELEMENT_TYPES else False

    @property
    def axisymmetric(self) -> bool:
        return self.keyopt.get(3, 0) == 1

    @property
    def triangle6(self) -> bool:
        """PLANE183 with KEYOPT(1)=1: the 6-node triangle `E,I,J,K,L,M,N`."""
        return self.name == "PLANE35" or (self.name == "PLANE183" and
                                           self.keyopt.get(1, 0) == 1)


def _remap(
    old_ids: np.ndarray,
    new_ids: np.ndarray,
    arrays: dict[str, np.ndarray],
    fills: dict[str, object],
) -> dict[str, np.ndarray]:
    """Carry per-entity arrays from `old_ids` to `new_ids` (both sorted)."""
    pos = np.searchsorted(old_ids, new_ids)
    pos_c = np.clip(pos, 0, max(len(old_ids) - 1, 0))
    found = (
        (pos < len(old_ids)) & (old_ids[pos_c] == new_ids)
        if len(old_ids)
        else np.zeros(len(new_ids), bool)
    )
    out = {}
    for name, arr in arrays.items():
        new = np.full((len(new_ids), *arr.shape[1:]), fills[name], dtype=arr.dtype)
        if len(old_ids):
            new[found] = arr[pos_c[found]]
        out[name] = new
    return out


class _NumberedTable:
    """What node and element tables share: sorted ids, pending additions, selection.

    Subclasses provide `ids`, `arrays` (with a "selected" mask) and `flush()`, which
    merges pending additions into the sorted arrays.
    """

    ids: np.ndarray
    arrays: dict[str, np.ndarray]

    def flush(self) -> None:  # pragma: no cover - every table overrides it
        raise NotImplementedError

    def __len__(self) -> int:
        self.flush()
        return len(self.ids)

    @property
    def selected(self) -> np.ndarray:
        self.flush()
        return self.arrays["selected"]

    @selected.setter
    def selected(self, mask: np.ndarray) -> None:
        self.flush()
        self.arrays["selected"] = mask

    def selected_ids(self) -> np.ndarray:
        """The numbers of the selected entities.  `ids[selected]` read `ids` before
        `selected` flushed the pending additions: an N, E or NGEN just before a CM, NGEN
        or *GET,,NODE,0,COUNT gave mismatched arrays (an internal error)."""
        mask = self.selected  # flushes first
        return self.ids[mask]

    def index(self, numbers: np.ndarray | int) -> np.ndarray:
        """Positions of node or element numbers; -1 for numbers that do not exist."""
        self.flush()
        nums = np.atleast_1d(np.asarray(numbers, dtype=np.int64))
        pos = np.searchsorted(self.ids, nums)
        pos_c = np.clip(pos, 0, max(len(self.ids) - 1, 0))
        ok = (
            (pos < len(self.ids)) & (self.ids[pos_c] == nums)
            if len(self.ids)
            else np.zeros(nums.shape, bool)
        )
        return np.where(ok, pos_c, -1)


class NodeTable(_NumberedTable):
    """Nodes by number: coordinates (x = r, y = z), selection and per-node loads (NaN: none)."""

    ARRAYS = {
        "selected": True,
        "d_temp": np.nan,
        "d_ux": np.nan,
        "d_uy": np.nan,
        "bf_temp": np.nan,
        "ic_temp": np.nan,
        "d_temp_table": -1,  # D,,TEMP,%table%: its slot in Database.load_tables (-1: none)
        "f_heat": np.nan,  # F,,HEAT: heat flow into the node, W (axisymmetric: 360°)
        "f_heat_table": -1,
        "bf_hgen": np.nan,  # BF,,HGEN at the node, W/m³ (see apdl_like.plane_thermal)
    }
    DTYPES = {"selected": bool, "d_temp_table": np.int64, "f_heat_table": np.int64}

    def __init__(self) -> None:
        self.ids = np.zeros(0, dtype=np.int64)
        self.xy = np.zeros((0, 2))
        self.arrays: dict[str, np.ndarray] = {
            k: np.zeros(0, self.DTYPES.get(k, float)) for k in self.ARRAYS
        }
        self.pending: dict[int, tuple[float, float]] = {}
        self.version = 0

    def set_arrays(self, ids: np.ndarray, xy: np.ndarray) -> None:
        """Replace every node at once (a mesh loaded from outside); all selected, no loads."""
        order = np.argsort(ids)
        self.ids = np.asarray(ids, np.int64)[order]
        self.xy = np.asarray(xy, float)[order]
        self.arrays = {
            k: np.full(len(self.ids), v, dtype=self.DTYPES.get(k, float))
            for k, v in self.ARRAYS.items()
        }
        self.pending.clear()
        self.version += 1

    def add(self, number: int, x: float, y: float) -> None:
        self.pending[number] = (x, y)

    def flush(self) -> None:
        if not self.pending:
            return
        nums = np.fromiter(self.pending, dtype=np.int64, count=len(self.pending))
        coords = np.array(list(self.pending.values()), dtype=float).reshape(-1, 2)
        new_ids = np.union1d(self.ids, nums)
        carried = _remap(
            self.ids, new_ids, {"xy": self.xy, **self.arrays}, {"xy": np.nan, **self.ARRAYS}
        )
        pos = np.searchsorted(new_ids, nums)
        carried["xy"][pos] = coords
        carried["selected"][pos] = True  # new entities join the selected set, as in APDL
        self.ids, self.xy = new_ids, carried.pop("xy")
        self.arrays = carried
        self.pending.clear()
        self.version += 1


class ElementTable(_NumberedTable):
    """Elements by number: type, material, real set, node numbers (0 = none), selection, HGEN."""

    # hgen_table: BF/BFE,,HGEN,%table%, its slot in Database.load_tables (-1: none)
    ARRAYS = {"selected": True, "hgen": np.nan, "hgen_record": -1, "hgen_table": -1}
    DTYPES = {"selected": bool, "hgen": float, "hgen_record": np.int64, "hgen_table": np.int64}

    def __init__(self) -> None:
        self.ids = np.zeros(0, dtype=np.int64)
        self.type = np.zeros(0, dtype=np.int64)
        self.mat = np.zeros(0, dtype=np.int64)
        self.real = np.zeros(0, dtype=np.int64)
        self.nodes = np.zeros((0, MAX_ELEMENT_NODES), dtype=np.int64)
        self.arrays: dict[str, np.ndarray] = {k: np.zeros(0, self.DTYPES[k]) for k in self.ARRAYS}
        self.pending: dict[int, tuple[int, int, int, tuple[int, ...]]] = {}
        self.version = 0

    def set_arrays(
        self,
        ids: np.ndarray,
        etype: np.ndarray,
        mat: np.ndarray,
        real: np.ndarray,
        nodes: np.ndarray,
    ) -> None:
        order = np.argsort(ids)
        self.ids = np.asarray(ids, np.int64)[order]
        self.type = np.asarray(etype, np.int64)[order]
        self.mat = np.asarray(mat, np.int64)[order]
        self.real = np.asarray(real, np.int64)[order]
        padded = np.zeros((len(ids), MAX_ELEMENT_NODES), np.int64)
        padded[:, : nodes.shape[1]] = nodes
        self.nodes = padded[order]
        self.arrays = {
            k: np.full(len(self.ids), v, dtype=self.DTYPES[k]) for k, v in self.ARRAYS.items()
        }
        self.pending.clear()
        self.version += 1

    def add(self, number: int, etype: int, mat: int, real: int, nodes: tuple[int, ...]) -> None:
        self.pending[number] = (etype, mat, real, nodes)

    def type_numbers(self) -> list[int]:
        """The element type numbers in use, ascending (`np.unique` of `type`).  A mesh of
        one type, the usual case, is told by one comparison: np.unique sorts (or hashes)
        the whole column, which every SOLVE of a window deck read twice."""
        self.flush()
        t = self.type
        if t.size and bool((t == t[0]).all()):
            return [int(t[0])]
        return [int(x) for x in np.unique(t)]

    def flush(self) -> None:
        if not self.pending:
            return
        nums = np.fromiter(self.pending, dtype=np.int64, count=len(self.pending))
        new_ids = np.union1d(self.ids, nums)
        carried = _remap(
            self.ids,
            new_ids,
            {
                "type": self.type,
                "mat": self.mat,
                "real": self.real,
                "nodes": self.nodes,
                **self.arrays,
            },
            {"type": 0, "mat": 0, "real": 0, "nodes": 0, **self.ARRAYS},
        )
        pos = np.searchsorted(new_ids, nums)
        for p, (etype, mat, real, nodes) in zip(pos, self.pending.values(), strict=True):
            carried["type"][p], carried["mat"][p], carried["real"][p] = etype, mat, real
            carried["nodes"][p] = 0
            carried["nodes"][p, : len(nodes)] = nodes
        carried["selected"][pos] = True
        self.ids, self.type, self.mat, self.real, self.nodes = (
            new_ids,
            carried.pop("type"),
            carried.pop("mat"),
            carried.pop("real"),
            carried.pop("nodes"),
        )
        self.arrays = carried
        self.pending.clear()
        self.version += 1


def record_groups(record: np.ndarray, extra: np.ndarray | None = None) -> list[np.ndarray]:
    """Index sets sharing a load record id (and `extra` value), for entities with a record.

    Groups come in ascending record order (then `extra`), members in ascending index order.
    """
    has = np.nonzero(record >= 0)[0]
    if has.size == 0:
        return []
    if extra is None:
        order = has[np.argsort(record[has], kind="stable")]
        return _split(order, np.nonzero(np.diff(record[order]))[0] + 1)
    keys = np.column_stack([record[has].astype(float), np.nan_to_num(extra[has], nan=-1e300)])
    _, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(inverse, kind="stable")
    splits = np.nonzero(np.diff(inverse[order]))[0] + 1
    return [has[s] for s in _split(order, splits)]


def _split(a: np.ndarray, at: np.ndarray) -> list[np.ndarray]:
    """`np.split(a, at)` for ascending indices `at` (the same views, without np.split's
    per-piece overhead)."""
    bounds = [0, *at.tolist(), a.size]
    return [a[i:j] for i, j in zip(bounds[:-1], bounds[1:], strict=True)]


@dataclass(eq=False)
class RecordPartition:
    """`record_groups(record)` of one record array, kept to be reused while a later record
    array partitions the entities the same way (`order_of`).

    Every load command gives its entities a new record id, so a window deck's load step
    that restates the bearing heat on the same components leaves new ids but the same
    groups; telling that takes a few vector comparisons, where grouping anew sorts the
    records.  `names` holds what the owner (`owner`, the FemModel it was made for) names
    each group, filled in by the owner as it needs them.
    """

    owner: object
    has: np.ndarray  # record >= 0
    members: np.ndarray  # np.nonzero(has)[0]
    label: np.ndarray  # the group (index into groups) of each member
    first: np.ndarray  # the position in `members` of each group's first member
    groups: list[np.ndarray]
    names: list[str | None]

    @classmethod
    def of(cls, record: np.ndarray, owner: object) -> RecordPartition:
        has = record >= 0
        members = np.nonzero(has)[0]
        groups = record_groups(record)
        label = np.empty(members.size, np.int64)
        for i, g in enumerate(groups):
            label[np.searchsorted(members, g)] = i
        first = np.searchsorted(members, [int(g[0]) for g in groups]).astype(np.int64)
        return cls(owner, has, members, label, first, groups, [None] * len(groups))

    def order_of(self, record: np.ndarray, owner: object) -> list[int] | None:
        """The groups of `record` as `record_groups` gives them (ascending record), as
        indices into `groups`, if `record` (of the same `owner`) partitions the entities
        as this one does; else None.  The same partition: the same entities have a record,
        every group's members share one record, and no two groups share one."""
        if owner is not self.owner or not np.array_equal(record >= 0, self.has):
            return None
        r = record[self.members]
        rep = r[self.first]
        if not np.array_equal(r, rep[self.label]):
            return None
        order = np.argsort(rep, kind="stable")
        if rep.size > 1 and not bool(np.all(np.diff(rep[order]) > 0)):
            return None
        return order.tolist()


@dataclass
class Component:
    """A named set of node or element numbers (CM, CMBLOCK)."""

    entity: str  # "NODE" or "ELEM"
    numbers: np.ndarray  # sorted APDL numbers
    # the membership mask over the table it was last resolved against, and that
    # table's version: a window deck selects the same components every minute
    _mask: np.ndarray | None = field(default=None, repr=False, compare=False)
    _mask_key: tuple[int, int] | None = field(default=None, repr=False, compare=False)

    def mask(self, table: NodeTable | ElementTable) -> np.ndarray:
        """Read-only membership mask over `table` (numbers not in the table are ignored)."""
        table.flush()
        key = (id(table), table.version)
        if self._mask is None or self._mask_key != key:
            mask = np.zeros(len(table.ids), bool)
            idx = table.index(self.numbers)
            mask[idx[idx >= 0]] = True
            mask.flags.writeable = False
            self._mask, self._mask_key = mask, key
        return self._mask


@dataclass
class FaceLoads:
    """Loads on exterior faces, keyed by (low, high) corner node numbers packed in one int."""

    keys: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    conv_h: np.ndarray = field(default_factory=lambda: np.zeros(0))
    conv_bulk: np.ndarray = field(default_factory=lambda: np.zeros(0))
    conv_record: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    hflux: np.ndarray = field(default_factory=lambda: np.zeros(0))
    hflux_record: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    # RDSF: a radiating surface, its emissivity and enclosure number (NaN: none)
    rdsf_emis: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rdsf_encl: np.ndarray = field(default_factory=lambda: np.zeros(0))
    # SF/SFE,%table%: the value's slot in Database.load_tables (-1: none)
    conv_h_table: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    conv_bulk_table: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    hflux_table: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))

    FILLS = {
        "conv_h": np.nan,
        "conv_bulk": np.nan,
        "conv_record": -1,
        "hflux": np.nan,
        "hflux_record": -1,
        "rdsf_emis": np.nan,
        "rdsf_encl": np.nan,
        "conv_h_table": -1,
        "conv_bulk_table": -1,
        "hflux_table": -1,
    }

    def rekey(self, new_keys: np.ndarray) -> None:
        """Carry the loads over to a new face table (faces that vanished lose their loads)."""
        order = np.argsort(new_keys)
        if np.array_equal(new_keys, self.keys):
            return
        names = list(self.FILLS)
        sorted_old = np.argsort(self.keys)
        carried = _remap(
            self.keys[sorted_old],
            new_keys[order],
            {n: getattr(self, n)[sorted_old] for n in names},
            self.FILLS,
        )
        inverse = np.empty_like(order)
        inverse[order] = np.arange(order.size)
        for n in names:
            setattr(self, n, carried[n][inverse])
        self.keys = np.asarray(new_keys, np.int64)


@dataclass
class Material:
    """MP properties of one material number (APDL labels).

    props         C0 of each property (a constant property is just this)
    coefficients  label -> (C0, C1, C2, C3, C4): the property is C0 + C1·T + ... + C4·T⁴
    tables        label -> (temperatures, values) from MPTEMP/MPDATA
    """

    props: dict[str, float] = field(default_factory=dict)
    coefficients: dict[str, tuple[float, ...]] = field(default_factory=dict)
    tables: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)

    def temperature_dependent(self, label: str) -> bool:
        return label in self.tables or len(self.coefficients.get(label, ())) > 1


@dataclass
class SolutionSettings:
    antype: str = "STATIC"
    restart: bool = False
    time: float | None = None
    deltim: float | None = None
    nsubst: int | None = None
    kbc: int = 0
    timint: bool | None = None  # None: the default of the analysis type
    # None: no AUTOTS given, stepped at fixed substeps as with AUTOTS,OFF.  MAPDL's own
    # default (program-chosen, adaptive for most thermal transients) is not emulated: a
    # deck that wants adaptive steps says AUTOTS,ON (the twin's window decks need fixed
    # 4 s steps and say nothing)
    autots: bool | None = None
    dtmin: float | None = None  # DELTIM bounds (with AUTOTS)
    dtmax: float | None = None
    nsub_max: int | None = None  # NSUBST bounds (with AUTOTS)
    nsub_min: int | None = None
    theta: float = 1.0  # TINTP: 1 backward Euler, 0.5 Crank-Nicolson
    outres: str = "ALL"
    tref: float = 0.0
    tunif: float = 0.0
    toffst: float = 0.0  # TOFFST: the absolute temperature of the model's zero (radiation)

    def substeps(self, span: float) -> int:
        """The substeps of a load step of `span` (s): NSUBST's NSBSTP, or span / DTIME
        rounded to the nearest integer (at least 1), as DELTIM's notes document: "the
        program calculates the initial incremental time so that (EndingTime −
        StartingTime)/DTIME is an integer" (0.4 over a span of 1: 3 substeps; 0.9: one).
        With AUTOTS this fixes the first substep, span / substeps."""
        if self.deltim is not None:
            return max(1, int(np.floor(span / self.deltim + 0.5)))
        return self.nsubst or 1


@dataclass
class Line:
    """A line between keypoints k1 -> k2, its divisions and spacing ratio (LESIZE; the last
    division over the first, along k1 -> k2): straight, or with `arc` a circular arc about
    `centre`, the origin of the active cylindrical system (L in CSYS 1 or a cylindrical
    LOCAL between keypoints of one radius, as MAPDL draws lines in the active system)."""

    k1: int
    k2: int
    ndiv: int | None = None
    space: float = 1.0
    arc: bool = False
    centre: tuple[float, float] = (0.0, 0.0)  # of an arc: the cylindrical system's origin


@dataclass
class Database:
    nodes: NodeTable = field(default_factory=NodeTable)
    elements: ElementTable = field(default_factory=ElementTable)
    element_types: dict[int, ElementType] = field(default_factory=dict)
    materials: dict[int, Material] = field(default_factory=dict)
    real_sets: dict[int, dict[int, float]] = field(default_factory=dict)
    components: dict[str, Component] = field(default_factory=dict)
    faces: FaceLoads = field(default_factory=FaceLoads)
    settings: SolutionSettings = field(default_factory=SolutionSettings)
    # active attributes for new elements (TYPE, MAT, REAL)
    active_type: int = 1
    active_mat: int = 1
    active_real: int = 1
    # AMESH geometry: keypoints and areas (lists of keypoint numbers)
    keypoints: dict[int, tuple[float, float]] = field(default_factory=dict)
    areas: dict[int, list[int]] = field(default_factory=dict)
    lines: dict[int, Line] = field(default_factory=dict)
    # keypoints and lines left out by KSEL/LSEL (MAPDL selects a new one): the rest are selected
    unselected_keypoints: set[int] = field(default_factory=set)
    unselected_lines: set[int] = field(default_factory=set)
    unselected_areas: set[int] = field(default_factory=set)
    esize_divisions: int | None = None  # ESIZE,,NDIV: divisions of lines without LESIZE
    mesh_triangles: bool = False  # MSHAPE,1
    meshed_areas: set[int] = field(default_factory=set)
    # AATT: area -> (MAT, REAL, TYPE) its elements get from AMESH (else the active ones)
    area_attributes: dict[int, tuple[int, int, int]] = field(default_factory=dict)
    area_elements: dict[int, np.ndarray] = field(default_factory=dict)  # AMESH: area -> elements
    line_elements: dict[int, np.ndarray] = field(default_factory=dict)  # LMESH: line -> elements
    keypoint_hgen: dict[int, float] = field(default_factory=dict)  # BFK,,HGEN, W/m³
    esize: float | None = None
    title: str = ""
    mp_temperatures: list[float] = field(default_factory=list)  # MPTEMP, for MPDATA
    node_history: list[int] = field(default_factory=list)  # the last two nodes N defined
    csys: int = 0  # active coordinate system (0 Cartesian, 1 cylindrical, ≥ 11 LOCAL)
    local_systems: dict[int, CoordinateSystem] = field(default_factory=dict)  # LOCAL, CLOCAL
    # coupled DOF sets (CP): set number -> (label, node numbers)
    couplings: dict[int, tuple[str, np.ndarray]] = field(default_factory=dict)
    last_real: tuple[int, int] | None = None  # (set, next location) for RMORE
    # contact interface (of an AxiMesh session) -> its real-constant set (TCC at 14)
    contact_real_sets: dict[str, int] = field(default_factory=dict)
    load_records: int = 0  # a counter: every load command gets its own record id
    # the tables loads name (`%NAME%`), by slot; only grows, so saved load steps stay valid
    load_tables: list[str] = field(default_factory=list)

    @property
    def active_system(self) -> CoordinateSystem:
        """The coordinate system CSYS (or the last LOCAL) made active."""
        return self.coordinate_system(self.csys)

    def coordinate_system(self, number: int) -> CoordinateSystem:
        system = GLOBAL_SYSTEMS.get(number) or self.local_systems.get(number)
        if system is None:
            raise ApdlError(f"coordinate system {number} is not defined (LOCAL)")
        return system

    def next_record(self) -> int:
        self.load_records += 1
        return self.load_records

    def mesh_key(self) -> tuple[int, int]:
        """(node, element) table versions once pending rows are in: the key of mesh caches."""
        self.nodes.flush()
        self.elements.flush()
        return (self.nodes.version, self.elements.version)


def element_corners(db: Database, idx: np.ndarray, tri6: np.ndarray) -> np.ndarray:
    """Corners (n, 4) of the elements as node-table indices, from the node-table indices of
    their nodes idx (n, ≥ 4; −1 where blank): a 6-node triangle (tri6) and a blank fourth
    node repeat the third corner, as MAPDL's degenerate K = L triangle does."""
    corners = idx[:, :4].copy()
    corners[tri6, 3] = corners[tri6, 2]
    blank = corners[:, 3] < 0
    corners[blank, 3] = corners[blank, 2]
    if np.any(corners[:, :3] < 0):
        bad = db.elements.ids[np.nonzero(np.any(corners[:, :3] < 0, axis=1))[0][0]]
        raise ApdlError(f"element {bad} refers to a node that does not exist")
    return corners
