"""Thermal SOLVE on a deck's own mesh: the database -> `apdl_like.plane_thermal`.

A session that holds the spindle (`Session.from_mesh`, contact interfaces) solves on
twin.fem (`apdl_like.solve`); a deck that builds its own mesh with N/E/FILL/AMESH solves
here, on native quads, planar or axisymmetric, with MAPDL's material models.

Exterior faces (what SF/SFE load) are the element edges used by exactly one element; they
are keyed by their corner node numbers (`FaceTable`), so loads survive a rebuilt mesh.
"""

from __future__ import annotations

from dataclasses import astuple, dataclass
from typing import TYPE_CHECKING

import numpy as np

from apdl_like.errors import ApdlError
from apdl_like.line_thermal import LINK_KINDS, ThermalLinks, link_constants
from apdl_like.model import Database, element_corners, pair_keys, record_groups
from apdl_like.plane_elastic import plane182_technology, solve_elastic
from apdl_like.plane_thermal import (
    PlaneMesh,
    PlaneThermal,
    Property,
    ThermalInputs,
    build_mesh,
    march,
)
from apdl_like.state import StepResult
from apdl_like.tabular_loads import TabularLoads, tabular_loads

if TYPE_CHECKING:
    from apdl_like.model import SolutionSettings
    from apdl_like.state import SessionState

THERMAL_PLANES = ("PLANE35", "PLANE55", "PLANE77")
DEFAULT_DTMIN_FRACTION = 1e-3  # AUTOTS without DTMIN: DTIME/1000
DEFAULT_DTMAX_FRACTION = 0.1  # AUTOTS without DTMAX: a tenth of the load step


@dataclass
class FaceTable:
    """Exterior element edges: corner node indices, packed node-number keys."""

    face_nodes: np.ndarray  # (2, n_faces) node indices
    face_keys: np.ndarray  # (n_faces,) pair_keys of the corner node numbers
    owner: np.ndarray  # (n_faces,) the element (index in the element table) it bounds

    def face_index(self, keys: np.ndarray) -> np.ndarray:
        """Positions of node-pair keys among the exterior faces; -1 where not one."""
        order = np.argsort(self.face_keys)
        sorted_keys = self.face_keys[order]
        if not sorted_keys.size:
            return np.full(np.shape(keys), -1)
        pos = np.clip(np.searchsorted(sorted_keys, keys), 0, sorted_keys.size - 1)
        return np.where(sorted_keys[pos] == keys, order[pos], -1)


def corners_and_midside(db: Database) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
    """Per element: corner node indices (m, 4; K = L for triangles), mid-side node indices
    (m, 4: I-J, J-K, K-L, L-I; -1 none) or None for a linear model, and which elements are
    solids (surface elements such as SURF151 only carry face loads)."""
    el = db.elements
    el.flush()
    if len(el.ids) == 0:
        raise ApdlError("the model has no elements")
    missing = [int(t) for t in np.unique(el.type) if int(t) not in db.element_types]
    if missing:
        raise ApdlError(f"element type {missing[0]} is used by elements but never defined (ET)")
    physics = np.array([db.element_types[int(t)].physics for t in el.type])
    solid = (physics != "surface") & (physics != "line")
    if not solid.any() and not (physics == "line").any():
        raise ApdlError("the model has only surface elements")
    nodes = el.nodes
    idx = db.nodes.index(nodes.ravel()).reshape(nodes.shape)
    idx[nodes == 0] = -1
    idx[~solid] = np.where(idx[~solid, :1] >= 0, idx[~solid, :1], 0)  # not meshed
    tri6 = np.array([db.element_types[int(t)].triangle6 for t in el.type], bool)
    quadratic = np.array([db.element_types[int(t)].quadratic for t in el.type], bool)
    corners = element_corners(db, idx, tri6)
    if not quadratic[solid].any():
        return corners, None, solid
    if not quadratic[solid].all():
        raise ApdlError("mixing linear and quadratic elements is not supported")
    mid = idx[:, 4:8].copy()
    mid[tri6] = np.column_stack([idx[tri6, 3], idx[tri6, 4], np.full(tri6.sum(), -1),
                                 idx[tri6, 5]])
    collapsed = corners[:, 2] == corners[:, 3]
    mid[collapsed & ~tri6, 2] = -1  # O of a degenerate 8-node quad sits on K = L
    mid[~solid] = -1
    return corners, mid, solid


def exterior_faces(db: Database) -> FaceTable:
    """The element edges used by exactly one element."""
    corners, _, solid = corners_and_midside(db)
    owner = np.repeat(np.nonzero(solid)[0], 4)
    corners = corners[solid]
    a = corners.ravel()
    b = np.roll(corners, -1, axis=1).ravel()
    keep = a != b
    a, b, owner = a[keep], b[keep], owner[keep]
    ids = db.nodes.ids
    keys = pair_keys(ids[a], ids[b])
    unique, first, counts = np.unique(keys, return_index=True, return_counts=True)
    once = first[counts == 1]
    once.sort()
    return FaceTable(np.vstack([a[once], b[once]]), keys[once], owner[once])


def plane_mesh(s: SessionState) -> PlaneMesh:
    """The scikit-fem mesh of the deck's thermal elements (cached)."""
    db = s.db
    key = (*db.mesh_key(), analysis_mode(db))
    cache = s.fem
    if cache.plane is None or cache.plane_key != key:
        corners, mid, solid = corners_and_midside(db)
        mesh = build_mesh(db.nodes.xy, db.nodes.ids, corners, mid, key[2] == "axisymmetric",
                          solid, _link_nodes(db))
        cache.plane, cache.plane_key = mesh, key
        cache.plane_solver = None
    return cache.plane  # type: ignore[return-value]


def _link_nodes(db: Database) -> np.ndarray:
    """Node indices of the line and point elements (LINK31..34, MASS71)."""
    el = db.elements
    line = np.array([db.element_types[int(t)].physics == "line" for t in el.type], bool)
    nodes = el.nodes[line]
    return db.nodes.index(np.unique(nodes[nodes > 0]))


def thermal_links(db: Database, mesh: PlaneMesh) -> ThermalLinks | None:
    """The deck's thermal line and point elements on the mesh's dofs (None: there are none)."""
    el = db.elements
    types = {t: db.element_types[t] for t in (int(u) for u in np.unique(el.type))}
    line = np.nonzero([types[int(t)].physics == "line" for t in el.type])[0]
    if not line.size:
        return None
    i = mesh.node_dof[db.nodes.index(el.nodes[line, 0])]
    j_nodes = el.nodes[line, 1]
    j = np.where(j_nodes > 0, mesh.node_dof[db.nodes.index(np.where(j_nodes > 0, j_nodes,
                                                                     el.nodes[line, 0]))], i)
    kind = np.array([LINK_KINDS[types[int(el.type[e])].name] for e in line])
    xy = db.nodes.xy
    length = np.hypot(*(xy[db.nodes.index(np.where(j_nodes > 0, j_nodes, el.nodes[line, 0]))]
                        - xy[db.nodes.index(el.nodes[line, 0])]).T)
    consts = []
    for e in line:
        number = int(el.ids[e])
        real = db.real_sets.get(int(el.real[e]))
        if real is None:
            raise ApdlError(f"element {number}: real constant set {int(el.real[e])} is not "
                            "defined (R)")
        et = types[int(el.type[e])]
        consts.append(link_constants(LINK_KINDS[et.name], real, et.keyopt, f"element {number}"))
    bars = kind == "conduction"
    if np.any(bars & (length <= 0.0)):
        bad = int(el.ids[line[np.nonzero(bars & (length <= 0.0))[0][0]]])
        raise ApdlError(f"element {bad}: a conduction bar needs two distinct node locations")
    area, emission, film_at, capacitance = (np.array(v) for v in zip(*consts, strict=True))
    return ThermalLinks(line, i, j, kind, length, area.astype(float), el.mat[line],
                        film_at.astype(int), emission.astype(float), capacitance.astype(bool),
                        db.settings.toffst)


def deck_faces(s: SessionState) -> FaceTable:
    """The exterior faces of a deck's own mesh (cached); the face loads follow them."""
    db = s.db
    key = db.mesh_key()
    cache = s.fem
    if cache.faces is None or cache.faces_key != key:
        cache.faces, cache.faces_key = exterior_faces(db), key
    db.faces.rekey(cache.faces.face_keys)
    return cache.faces


def analysis_mode(db: Database) -> str:
    """axisymmetric, plane_stress (planar, the default) or plane_strain, from KEYOPT(3)."""
    used = {int(t) for t in np.unique(db.elements.type)}
    kinds = set()
    for t in used:
        et = db.element_types.get(t)
        if et is None:
            continue
        if et.physics in ("surface", "line"):
            continue  # SURF151 follows the solid it lies on; links have no plane mode
        if et.physics == "unsupported":
            raise ApdlError(f"element type {t} ({et.name}) is not supported: use PLANE35, "
                            "PLANE55, PLANE77, PLANE182 or PLANE183")
        k3 = et.keyopt.get(3, 0)
        allowed = (0, 1, 2) if et.physics == "structural" else (0, 1)
        if k3 not in allowed:
            raise ApdlError(f"element type {t} ({et.name}): KEYOPT(3) = {k3} is not supported "
                            "(0 planar, 1 axisymmetric" +
                            (", 2 plane strain)" if et.physics == "structural" else ")"))
        kinds.add({0: "plane_stress", 1: "axisymmetric", 2: "plane_strain"}[k3])
    if len(kinds) > 1:
        raise ApdlError("the model mixes planar and axisymmetric element types")
    return kinds.pop() if kinds else "plane_stress"


# ---------------------------------------------------------------- materials
def material_property(db: Database, mat: int, label: str, why: str,
                      default: float | None = None) -> Property:
    """A property of material `mat` as a function of temperature: MP C0..C4 polynomial or
    an MPTEMP/MPDATA table (linear between points, constant beyond them)."""
    m = db.materials.get(mat)
    if m is not None and label in m.tables:
        temps, values = m.tables[label]
        return lambda T: np.interp(T, temps, values)
    if m is None or label not in m.props:
        if default is not None:
            return lambda T: np.full_like(T, default)
        raise ApdlError(f"material {mat} has no {label} (MP,{label},{mat},...), needed {why}")
    coeffs = m.coefficients.get(label, (m.props[label],))
    if len(coeffs) == 1:
        c0 = coeffs[0]
        return lambda T: np.full_like(T, c0)
    return lambda T: np.polynomial.polynomial.polyval(T, coeffs)


def _is_nonlinear(db: Database, mats: list[int]) -> bool:
    """Whether a property of these materials changes with temperature (Picard iteration).
    An MPTEMP/MPDATA table of one value throughout, or C1..C4 of zero, is constant: a deck
    that writes its constant c as a table solves linearly (it iterated every substep, 10×
    the time)."""
    for mat in mats:
        m = db.materials.get(mat)
        if m is None:
            continue
        if any(np.ptp(values) > 0.0 for _, values in m.tables.values()):
            return True
        if any(any(c[1:]) for c in m.coefficients.values()):
            return True
    return False


def _when_used(db: Database, mat: int, label: str, why: str) -> Property:
    """The property, or one that names what is missing when an element first needs it (a
    material of only links need not have KXX, DENS or C)."""
    try:
        return material_property(db, mat, label, why)
    except ApdlError as exc:
        message = str(exc)

        def missing(T: np.ndarray) -> np.ndarray:
            raise ApdlError(message)

        return missing


def _properties(db: Database, transient: bool) -> tuple[dict[str, list[Property]], list[int]]:
    mats = sorted({int(m) for m in np.unique(db.elements.mat)})
    size = max(mats) + 1
    out: dict[str, list[Property]] = {"kxx": [None] * size, "kyy": [None] * size,  # type: ignore[list-item]
                                      "rho_c": [None] * size, "enthalpy": [None] * size,
                                      "hf": [None] * size, "specific_heat": [None] * size}
    physics = np.array([db.element_types[int(t)].physics for t in db.elements.type])
    link_only = set(mats) - {int(m) for m in np.unique(db.elements.mat[physics != "line"])}
    for mat in mats:
        if mat not in db.materials:
            if mat in link_only:
                continue  # MASS71 with a capacitance: no material
            raise ApdlError(f"material {mat} is used by elements but has no MP properties")
        kxx = _when_used(db, mat, "KXX", "for heat conduction")
        m = db.materials[mat]
        kyy = material_property(db, mat, "KYY", "") if "KYY" in m.props or "KYY" in m.tables \
            else kxx
        if transient and "ENTH" in m.tables:
            out["enthalpy"][mat], rho_c = enthalpy_table(*m.tables["ENTH"])
        elif transient:
            dens = _when_used(db, mat, "DENS", "for a transient")
            c = _when_used(db, mat, "C", "for a transient")
            rho_c = _product(dens, c)
        else:
            rho_c = material_property(db, mat, "C", "", default=1.0)
        out["kxx"][mat], out["kyy"][mat], out["rho_c"][mat] = kxx, kyy, rho_c
        if "HF" in m.props or "HF" in m.tables:
            out["hf"][mat] = material_property(db, mat, "HF", "")
        if "C" in m.props or "C" in m.tables:
            out["specific_heat"][mat] = material_property(db, mat, "C", "")
    return out, mats


def enthalpy_table(temps: np.ndarray, enthalpy: np.ndarray) -> tuple[Property, Property]:
    """H(T) and ρc(T) = dH/dT of an MPTEMP/MPDATA enthalpy table (ENTH, J/m³): MAPDL
    uses the enthalpy instead of DENS·C when both are given (phase change: the latent heat
    is the steep part of H).  H is linear between the points and goes on with the end
    slopes beyond them; each interval's slope holds up to its upper temperature."""
    if temps.size < 2:
        raise ApdlError("an enthalpy table (MPDATA,ENTH) needs at least two temperatures")
    slopes = np.diff(enthalpy) / np.diff(temps)
    if np.any(slopes <= 0.0):
        raise ApdlError("the enthalpy (MPDATA,ENTH) must increase with temperature")
    inner = temps[1:-1]

    def interval(T: np.ndarray) -> np.ndarray:
        return np.searchsorted(inner, T, side="right")

    def H(T: np.ndarray) -> np.ndarray:
        i = interval(T)
        return enthalpy[i] + slopes[i] * (T - temps[i])

    return H, lambda T: slopes[interval(T)]


def _product(a: Property, b: Property) -> Property:
    return lambda T: a(T) * b(T)


# -------------------------------------------------------------------- loads
@dataclass
class _LoadState:
    """The database's thermal loads on the plane mesh, as arrays to interpolate."""

    hgen: np.ndarray  # per element, W/m³ (NaN: none)
    conv_h: np.ndarray  # per exterior face
    conv_bulk: np.ndarray
    hflux: np.ndarray
    d_temp: np.ndarray  # per node (NaN: free)
    f_heat: np.ndarray  # per node, W (NaN: none)
    bf_hgen: np.ndarray  # per node, W/m³ (NaN: none)

    @classmethod
    def of(cls, db: Database) -> _LoadState:
        f = db.faces
        nodes = db.nodes.arrays
        return cls(db.elements.arrays["hgen"].copy(), f.conv_h.copy(), f.conv_bulk.copy(),
                   f.hflux.copy(), nodes["d_temp"].copy(), nodes["f_heat"].copy(),
                   nodes["bf_hgen"].copy())

    def none(self) -> _LoadState:
        """No load anywhere (NaN): where the ramps of a first load step start."""
        return _LoadState(*(np.full_like(a, np.nan) for a in astuple(self)))


def _tabular(s: SessionState, faces: FaceTable) -> TabularLoads | None:
    """The loads that come from tables (`%NAME%`), looked up at nodes, face middles and
    element centroids."""
    db = s.db
    if not db.load_tables:
        return None
    xy = db.nodes.xy
    f = db.faces

    def face_middles(idx: np.ndarray) -> np.ndarray:
        return 0.5 * (xy[faces.face_nodes[0, idx]] + xy[faces.face_nodes[1, idx]])

    def centroids(idx: np.ndarray) -> np.ndarray:
        corners = corners_and_midside(db)[0][idx]
        distinct = np.ones(corners.shape, bool)
        distinct[:, 1:] = corners[:, 1:] != corners[:, :-1]  # K = L of a triangle: once
        return (xy[corners] * distinct[..., None]).sum(axis=1) / distinct.sum(axis=1)[:, None]

    def nodes(idx: np.ndarray) -> np.ndarray:
        return xy[idx]

    return tabular_loads(db, s.params, {
        "hgen": (db.elements.arrays["hgen_table"], centroids),
        "conv_h": (f.conv_h_table, face_middles), "conv_bulk": (f.conv_bulk_table, face_middles),
        "hflux": (f.hflux_table, face_middles), "d_temp": (db.nodes.arrays["d_temp_table"], nodes),
        "f_heat": (db.nodes.arrays["f_heat_table"], nodes)})


def _inputs(db: Database, mesh: PlaneMesh, faces: FaceTable, props: dict,
            now: _LoadState, before: _LoadState | None, fraction: float,
            varying: bool = False) -> ThermalInputs:
    """The solver's inputs from the loads `now`, ramped from `before` by `fraction`;
    `varying`: the values of one load record may differ from face to face (tables)."""
    tunif = db.settings.tunif

    def ramp(new: np.ndarray, old: np.ndarray | None, start: float) -> np.ndarray:
        if old is None or fraction >= 1.0:
            return new
        old = np.where(np.isnan(old), start, old)
        return old + fraction * (np.nan_to_num(new, nan=start) - old)

    hgen = np.nan_to_num(ramp(now.hgen, None if before is None else before.hgen, 0.0))
    face_key = faces.face_keys
    films, fluxes = [], []
    h = ramp(now.conv_h, None if before is None else before.conv_h, 0.0)
    tb = ramp(now.conv_bulk, None if before is None else before.conv_bulk, tunif)
    rec = db.faces.conv_record
    for idx in record_groups(rec, h if before is not None or varying else None):
        hv, tv = float(h[idx[0]]), float(tb[idx[0]])
        if np.isnan(hv) or np.isnan(tv):
            raise ApdlError("a face has CONV with only one of film coefficient and bulk "
                            "temperature (SFE KVAL 1 and 2)")
        if hv != 0.0:
            for sub in _split_by(idx, tb):
                films.append((face_key[sub], hv, float(tb[sub[0]])))
    q = ramp(now.hflux, None if before is None else before.hflux, 0.0)
    for idx in record_groups(db.faces.hflux_record):
        for sub in _split_by(idx, q):
            if q[sub[0]] != 0.0:
                fluxes.append((face_key[sub], float(q[sub[0]])))
    d = ramp(now.d_temp, None if before is None else before.d_temp, tunif)
    nodes_fixed = np.nonzero(~np.isnan(now.d_temp) & (mesh.node_dof >= 0))[0]
    fixed = (mesh.node_dof[nodes_fixed], d[nodes_fixed])
    heat = ramp(now.f_heat, None if before is None else before.f_heat, 0.0)
    heated = np.nonzero(~np.isnan(heat) & (heat != 0.0) & (mesh.node_dof >= 0))[0]
    nodal_heat = (mesh.node_dof[heated], heat[heated]) if heated.size else None
    nodal_hgen = None
    rate = ramp(now.bf_hgen, None if before is None else before.bf_hgen, 0.0)
    generating = np.nonzero(~np.isnan(rate) & (rate != 0.0) & (mesh.node_dof >= 0))[0]
    if generating.size:
        nodal_hgen = np.zeros(mesh.n_dofs)
        nodal_hgen[mesh.node_dof[generating]] = rate[generating]
    enthalpy = props["enthalpy"] if any(h is not None for h in props["enthalpy"]) else None
    return ThermalInputs(props["kxx"], props["kyy"], props["rho_c"], hgen, films, fluxes, fixed,
                         enthalpy, props["hf"], props["specific_heat"], nodal_heat, nodal_hgen)


def _split_by(idx: np.ndarray, values: np.ndarray) -> list[np.ndarray]:
    """Index groups of equal value (a ramped record may hold several values)."""
    v = values[idx]
    if np.all(v == v[0]) or np.all(np.isnan(v)):
        return [idx]
    _, inverse = np.unique(v, return_inverse=True)
    return [idx[inverse.ravel() == k] for k in range(inverse.max() + 1)]


def initial_temperature(s: SessionState, mesh: PlaneMesh) -> np.ndarray:
    """TUNIF everywhere, IC where given (mid-side dofs without IC: TUNIF)."""
    T = np.full(mesh.n_dofs, s.db.settings.tunif)
    ic = s.db.nodes.arrays["ic_temp"]
    given = ~np.isnan(ic) & (mesh.node_dof >= 0)
    T[mesh.node_dof[given]] = ic[given]
    return T


def _couplings(db: Database, mesh: PlaneMesh) -> list[np.ndarray]:
    out = []
    for label, numbers in db.couplings.values():
        if label in ("TEMP", "ALL"):
            idx = db.nodes.index(numbers)
            out.append(mesh.node_dof[idx[idx >= 0]])
    return out


def solve_plane_thermal(s: SessionState) -> StepResult:
    """One thermal load step (steady or transient) on the deck's mesh."""
    db = s.db
    mesh = plane_mesh(s)
    faces = deck_faces(s)
    settings = db.settings
    transient = settings.antype == "TRANS" and settings.timint is not False
    props, mats = _properties(db, settings.antype == "TRANS")
    links = thermal_links(db, mesh)
    nonlinear = _is_nonlinear(db, mats) or (links is not None and
                                            bool(np.any(links.kind == "radiation")))
    element_material = db.elements.mat
    couplings = _couplings(db, mesh)
    key = (id(mesh), element_material.tobytes(), tuple(c.tobytes() for c in couplings))
    cache = s.fem
    if cache.plane_solver is None or cache.plane_solver[0] != key or links is not None:
        cache.plane_solver = (key, PlaneThermal(mesh, element_material, couplings, links))
    model: PlaneThermal = cache.plane_solver[1]
    sol = s.solution
    if sol.fresh_start or sol.temperature is None or sol.temperature.size != mesh.n_dofs:
        sol.temperature = initial_temperature(s, mesh)
        sol.time = 0.0
        sol.fresh_start = False
        sol.previous_loads = None
        sol.history_times, sol.history_temperatures = [], []
    now = _LoadState.of(db)
    _check_nodal_hgen(db, mesh, links, now)
    tables = _tabular(s, faces)
    varying = tables is not None
    T0 = sol.temperature
    if not transient:
        end = settings.time if settings.time is not None else sol.time + 1.0
        inputs = _inputs(db, mesh, faces, props, now if tables is None else tables.at(now, end),
                         None, 1.0, varying)
        T = model.steady(inputs, T0, nonlinear)
        times, temps = [end], [T]
    else:
        span = sol.span_to(settings.time)
        ramped = settings.kbc == 0
        before = sol.previous_loads if ramped else None
        if ramped and before is None:
            before = now.none()
        start = sol.time
        steady_inputs = _inputs(db, mesh, faces, props,
                                now if tables is None else tables.at(now, settings.time),
                                None, 1.0, varying)

        def inputs_at(t: float) -> ThermalInputs:
            if tables is not None:
                # tabular entries take the table's value at t, unramped (in `before` too)
                return _inputs(db, mesh, faces, props, tables.at(now, t),
                               None if before is None else tables.at(before, t),
                               (t - start) / span if ramped else 1.0, True)
            if not ramped:
                return steady_inputs
            return _inputs(db, mesh, faces, props, now, before, (t - start) / span)

        dt, adaptive, dt_min, dt_max = _substeps(settings, span)
        scale = _temperature_scale(T0, steady_inputs)
        times, temps = march(model, inputs_at, T0, start, settings.time, dt, settings.theta,
                             nonlinear, adaptive, dt_min, dt_max, scale)
    sol.temperature, sol.time = temps[-1], times[-1]
    sol.substep_times, sol.substep_temperatures = times, temps
    sol.history_times += times
    sol.history_temperatures += temps
    sol.previous_loads = now if tables is None else tables.cleared(now)
    s.fem.plane_inputs = steady_inputs if transient else inputs
    return StepResult(len(sol.results) + 1, sol.time, "thermal", sol.temperature,
                      nodal_temperature=mesh.nodal(sol.temperature))


def _check_nodal_hgen(db: Database, mesh: PlaneMesh, links: ThermalLinks | None,
                      now: _LoadState) -> None:
    """Nodal HGEN (BF,Node,HGEN) where its documented rule is pinned down here: on linear
    plane elements (PLANE55), whose weighted nodal volumes ∫ N_n dV are positive shares of
    the element; not on quadratic ones (their corner shares are zero or negative), not at
    the nodes of links and masses, and not on an element that has BFE,,HGEN as well (which
    of the two MAPDL applies there is not documented)."""
    nodes = np.nonzero(~np.isnan(now.bf_hgen) & (mesh.node_dof >= 0))[0]
    if not nodes.size:
        return
    first = int(db.nodes.ids[nodes[0]])
    if not mesh.lumped:
        raise ApdlError(f"nodal HGEN (BF at node {first}) on quadratic elements (PLANE77, "
                        "PLANE35) is not supported: use BFE,,HGEN")
    if links is not None:
        at_links = np.isin(mesh.node_dof[nodes], np.concatenate([links.i, links.j]))
        if np.any(at_links):
            raise ApdlError(f"nodal HGEN (BF) at node {int(db.nodes.ids[nodes[at_links][0]])}"
                            ", a node of a link or mass element, is not supported: use BFE")
    corners = corners_and_midside(db)[0]
    both = ~np.isnan(now.hgen) & np.any(np.isin(corners, nodes), axis=1)
    if np.any(both):
        raise ApdlError(f"element {int(db.elements.ids[np.argmax(both)])} has both BFE,,HGEN "
                        "and nodal HGEN (BF) at its nodes: give one of them")


def _substeps(settings: SolutionSettings, span: float) -> tuple[float, bool, float, float]:
    """(first substep, adaptive?, DTMIN, DTMAX) from DELTIM/NSUBST and AUTOTS: the first
    substep is span / `SolutionSettings.substeps` with or without AUTOTS; the bounds are
    DELTIM's DTMIN, DTMAX or span / NSBMX, span / NSBMN, and where not given
    `DEFAULT_DTMIN_FRACTION` of the first substep and `DEFAULT_DTMAX_FRACTION` of the span
    (MAPDL's defaults depend "on the physics of the model")."""
    dt = span / settings.substeps(span)
    if settings.deltim is not None:
        dt_min, dt_max = settings.dtmin, settings.dtmax
    else:
        dt_min = span / settings.nsub_max if settings.nsub_max else None
        dt_max = span / settings.nsub_min if settings.nsub_min else None
    dt_min = dt * DEFAULT_DTMIN_FRACTION if dt_min is None else min(dt_min, dt)
    dt_max = max(dt, span * DEFAULT_DTMAX_FRACTION if dt_max is None else dt_max)
    return dt, bool(settings.autots), dt_min, dt_max


def _temperature_scale(T0: np.ndarray, inputs: ThermalInputs) -> float:
    """The temperature range the problem spans (initial field, fixed and bulk values)."""
    values = [T0]
    if inputs.fixed[1].size:
        values.append(inputs.fixed[1])
    values += [np.array([tb]) for _, _, tb in inputs.films]
    allv = np.concatenate(values)
    return float(np.ptp(allv)) if allv.size else 1.0


# --------------------------------------------------------------- structural
def _element_values(db: Database, label: str, why: str, default: float | None) -> np.ndarray:
    mats = db.elements.mat
    out = np.empty(mats.size)
    for m in np.unique(mats):
        material = db.materials.get(int(m))
        props = material.props if material is not None else {}
        if label in ("PRXY",) and label not in props and "NUXY" in props:
            value = props["NUXY"]
        elif label in props:
            value = props[label]
        elif default is not None:
            value = default
        else:
            raise ApdlError(f"material {int(m)} has no {label} (MP,{label},{int(m)},...), "
                            f"needed {why}")
        if material is not None and material.temperature_dependent(label):
            raise ApdlError(f"material {int(m)}: temperature-dependent {label} is not supported "
                            "in a structural analysis")
        out[mats == m] = value
    return out


def solve_plane_structural(s: SessionState) -> StepResult:
    """A static thermo-elastic load step on the deck's mesh (LDREAD/BF temperatures)."""
    db = s.db
    settings = db.settings
    if settings.antype != "STATIC":
        raise ApdlError("structural analyses are static only (ANTYPE,STATIC)")
    mode = analysis_mode(db)
    mesh = plane_mesh(s)
    n = mesh.n_dofs
    E = _element_values(db, "EX", "for a structural analysis", None)
    nu = _element_values(db, "PRXY", "", 0.3)
    alpha = _element_values(db, "ALPX", "", 0.0)
    T = np.full(n, settings.tunif)
    body = s.solution.body_temperature
    if body is not None and body.nodal_temperature is not None:
        given = ~np.isnan(body.nodal_temperature) & (mesh.node_dof >= 0)
        T[mesh.node_dof[given]] = body.nodal_temperature[given]
    bf = db.nodes.arrays["bf_temp"]
    given = ~np.isnan(bf) & (mesh.node_dof >= 0)
    T[mesh.node_dof[given]] = bf[given]
    dofs, values = [], []
    for c, label in enumerate(("d_ux", "d_uy")):
        d = db.nodes.arrays[label]
        held = np.nonzero(~np.isnan(d) & (mesh.node_dof >= 0))[0]
        dofs.append(c * n + mesh.node_dof[held])
        values.append(d[held])
    couplings = []
    for label, numbers in db.couplings.values():
        idx = db.nodes.index(numbers)
        scalar = mesh.node_dof[idx[idx >= 0]]
        scalar = scalar[scalar >= 0]
        for c, name in enumerate(("UX", "UY")):
            if label in (name, "ALL"):
                couplings.append(c * n + scalar)
    technology = {int(t): plane182_technology(et.keyopt.get(1, 0), f"element type {int(t)}")
                  if et.name == "PLANE182" else ""
                  for t in np.unique(db.elements.type) for et in [db.element_types[int(t)]]}
    technology = np.array([technology[int(t)] for t in db.elements.type])
    disp, stress = solve_elastic(mesh, mode, E, nu, alpha, T - settings.tref,
                                 (np.concatenate(dofs), np.concatenate(values)), couplings,
                                 technology)
    sol = s.solution
    sol.time = settings.time if settings.time is not None else sol.time + 1.0
    return StepResult.structural(len(sol.results) + 1, sol.time, T, disp, stress, mesh.nodal,
                                 mesh.nodal(T))
