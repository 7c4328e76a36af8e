"""SOLVE: thermal (steady or transient) and structural load steps on twin.fem.

The problems are cached in the session: a `ThermalProblem` per mesh topology and material
table, an `ElasticProblem` per mesh, materials, constraints and TREF.  A window deck that
only changes loads and time therefore costs one factorization (the stepper) plus the
back-substitutions.

Load ramping (KBC,0, APDL's default) interpolates HGEN, CONV (h, T_bulk), HFLUX and D,TEMP
linearly over the substeps of a load step from their values at the end of the previous load
step (first load step: zero, and TUNIF for temperatures); each substep then needs its own
factorization.  KBC,1 (stepped) applies the new loads at once.  Contact conductance is
always stepped.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from apdl_like.errors import ApdlError
from apdl_like.fem_bridge import FemModel, build_model
from apdl_like.model import RecordPartition, record_groups
from apdl_like.state import TCC_LOCATION, StepResult
from apdl_like.tabular_loads import in_use
from twin.fem import ElasticProblem, Material, ThermalLoads, ThermalProblem

if TYPE_CHECKING:
    from apdl_like.plane_solve import FaceTable
    from apdl_like.state import SessionState
_PLACEHOLDER = 1.0  # ρ, c of a steady analysis: unused, but Material wants positive values


def refuse_deck_mesh_loads(session: SessionState, done: str) -> None:
    """Tabular loads, F,,HEAT and nodal HGEN are solved on a deck's own mesh only
    (`apdl_like.plane_solve`), not on twin.fem's spindle."""
    db = session.db
    if in_use(db):
        raise ApdlError(f"tabular loads (%table%) are {done} on a deck's own mesh only, not on "
                        "the spindle session's: give values")
    if np.any(~np.isnan(db.nodes.arrays["f_heat"])):
        raise ApdlError(f"nodal heat flows (F,,HEAT) are {done} on a deck's own mesh only, not "
                        "on the spindle session's")
    if np.any(~np.isnan(db.nodes.arrays["bf_hgen"])):
        raise ApdlError(f"nodal heat generation (BF,Node,HGEN) is {done} on a deck's own mesh "
                        "only, not on the spindle session's: use BFE")


def fem_model(session: SessionState) -> FemModel:
    """The FEM view of the current mesh, rebuilt only when nodes or elements changed."""
    db = session.db
    key = db.mesh_key()
    cache = session.fem
    if cache.model is not None and cache.model_key == key:
        return cache.model
    if cache.model is not None and cache.external_mesh:
        raise ApdlError("the mesh of this session came from an AxiMesh with contact interfaces "
                        "and cannot be changed by N/E commands")
    cache.model = build_model(db)
    cache.model_key = key
    db.faces.rekey(cache.model.face_keys)
    return cache.model


def _require(props: dict[str, float], label: str, mat: int, why: str) -> float:
    if label not in props:
        raise ApdlError(f"material {mat} has no {label} (MP,{label},{mat},...), needed {why}")
    return props[label]


def _materials(session: SessionState, fem: FemModel, kind: str) -> dict[str, Material]:
    db = session.db
    mats = {}
    cell_mat = db.elements.mat[fem.cell_element]
    transient = session.db.settings.antype == "TRANS"
    for m in np.unique(cell_mat):
        m = int(m)
        props = db.materials.get(m)
        if props is None:
            raise ApdlError(f"material {m} is used by elements but has no MP properties")
        p = props.props
        # twin.fem takes constant, isotropic properties: say so rather than drop the rest
        for label in ("KXX", "DENS", "C", "EX", "PRXY", "ALPX"):
            if props.temperature_dependent(label):
                raise ApdlError(f"material {m}: temperature-dependent {label} is not supported "
                                "on the spindle session's mesh")
        if "KYY" in p and p["KYY"] != p.get("KXX"):
            raise ApdlError(f"material {m}: orthotropic KYY is not supported on the spindle "
                            "session's mesh")
        # the region of these cells: the mesh's own name when it has exactly this set
        region = fem.region_for(np.nonzero(cell_mat == m)[0])
        try:
            if kind == "thermal":
                k = _require(p, "KXX", m, "for heat conduction")
                rho = _require(p, "DENS", m, "for a transient") if transient else \
                    p.get("DENS", _PLACEHOLDER)
                c = _require(p, "C", m, "for a transient") if transient else \
                    p.get("C", _PLACEHOLDER)
                mats[region] = Material(k=k, rho=rho, c=c, name=f"MAT{m}")
            else:
                E = _require(p, "EX", m, "for a structural analysis")
                nu = p.get("PRXY", p.get("NUXY", 0.3))
                mats[region] = Material(k=p.get("KXX", _PLACEHOLDER), rho=_PLACEHOLDER,
                                        c=_PLACEHOLDER, E=E, nu=nu, alpha=p.get("ALPX", 0.0),
                                        name=f"MAT{m}")
        except ValueError as exc:
            raise ApdlError(str(exc)) from None
    return mats


def _material_key(mats: dict[str, Material]) -> tuple:
    return tuple(sorted((n, m.k, m.rho, m.c, m.E, m.nu, m.alpha) for n, m in mats.items()))


def _material_inputs(session: SessionState, fem: FemModel) -> tuple:
    """What `_materials` reads, cheaply: a window deck re-solves with unchanged materials."""
    db = session.db
    if fem.used_materials is None:  # the element materials of a FemModel never change
        fem.used_materials = np.unique(db.elements.mat[fem.cell_element]).tolist()
    props = tuple((m, tuple(db.materials[m].props.items()) if m in db.materials else None)
                  for m in fem.used_materials)
    return id(fem), db.settings.antype, props


def thermal_problem(session: SessionState, fem: FemModel) -> ThermalProblem:
    cache = session.fem
    inputs = _material_inputs(session, fem)
    if cache.thermal is not None and cache.thermal_inputs == inputs:
        return on_model_mesh(session, fem)
    mats = _materials(session, fem, "thermal")
    key = (id(fem), _material_key(mats), fem.order)
    if cache.thermal_key != key:
        cache.thermal = ThermalProblem(fem.mesh, mats, order=fem.order)
        cache.thermal_key = key
    cache.thermal_inputs = inputs
    return on_model_mesh(session, fem)


def on_model_mesh(session: SessionState, fem: FemModel) -> ThermalProblem:
    """The session's ThermalProblem on `fem`'s mesh.  Once `fem` named a set of its own,
    its mesh is a view of the one the problem was assembled or adopted on (which the
    loop's sessions share, `Session.from_mesh`): the session then goes on with a copy of
    the problem on that view (`ThermalProblem.on_mesh`: the operators shared, the named
    sets' loads and factorizations its own), made once; call it after naming loads."""
    cache = session.fem
    problem = cache.thermal
    assert problem is not None
    if problem.mesh is not fem.mesh:
        problem = cache.thermal = problem.on_mesh(fem.mesh)
    return problem


def adopt_thermal_problem(session: SessionState, problem: ThermalProblem) -> None:
    """Use an assembled ThermalProblem (same mesh, materials and order) as the cached one."""
    fem = fem_model(session)
    if problem.mesh is not fem.mesh or problem.order != fem.order:
        raise ValueError("the ThermalProblem belongs to another mesh or element order")
    mats = _materials(session, fem, "thermal")
    by_constants = sorted((m.k, m.rho_c) for m in mats.values())
    if by_constants != sorted((m.k, m.rho_c) for m in problem.materials.values()):
        raise ValueError("the ThermalProblem has other materials than the session")
    session.fem.thermal = problem
    session.fem.thermal_key = (id(fem), _material_key(mats), fem.order)


def _check_axisymmetric(session: SessionState, physics: str) -> None:
    db = session.db
    for t in db.elements.type_numbers():
        et = db.element_types[t]
        if et.physics == "unsupported":
            raise ApdlError(f"element type {t} ({et.name}) is not supported: redefine it, e.g. "
                            f"ET,{t},PLANE55 and KEYOPT,{t},3,1")
        if et.physics != physics:
            raise ApdlError(f"element type {t} ({et.name}) is not a {physics} element; a load "
                            f"step solves one physics (use ETCHG to switch)")
        if not et.axisymmetric:
            raise ApdlError(f"element type {t} ({et.name}) is a plane element: only axisymmetric "
                            f"analyses are supported (KEYOPT,{t},3,1)")


def thermal_loads(session: SessionState, fem: FemModel, fraction: float = 1.0) -> ThermalLoads:
    """The database's thermal loads as twin.fem ThermalLoads (ramped to `fraction`)."""
    db = session.db
    prev = None
    if fraction < 1.0:
        prev = session.solution.previous_loads or _first_step_loads(session)
    tunif = db.settings.tunif
    el = db.elements.arrays
    cell_hgen = el["hgen"][fem.cell_element]
    cell_rec = el["hgen_record"][fem.cell_element]
    cell_prev = prev["hgen"][fem.cell_element] if prev is not None else None
    sources = {}
    for cells, name in _load_sets(session, fem, "hgen", cell_rec, cell_prev, fem.region_for):
        q = float(cell_hgen[cells[0]])
        if prev is not None:
            q0 = float(np.nan_to_num(cell_prev[cells[0]]))
            q = q0 + fraction * (q - q0)
        if q != 0.0:
            sources[name()] = q
    faces = db.faces
    convection, flux = {}, {}
    fprev = prev["faces"] if prev is not None else None

    def boundary(idx: np.ndarray) -> str:
        return fem.boundary_for(fem.face_facets[idx])

    for idx, name in _load_sets(session, fem, "conv", faces.conv_record,
                                None if fprev is None else fprev["conv_h"], boundary):
        h, tb = float(faces.conv_h[idx[0]]), float(faces.conv_bulk[idx[0]])
        if math.isnan(h) or math.isnan(tb):
            raise ApdlError("a face has CONV with only one of film coefficient and bulk "
                            "temperature (SFE KVAL 1 and 2)")
        if fprev is not None:
            h0 = float(np.nan_to_num(fprev["conv_h"][idx[0]]))
            tb0 = fprev["conv_bulk"][idx[0]]
            tb0 = tunif if np.isnan(tb0) else float(tb0)
            h, tb = h0 + fraction * (h - h0), tb0 + fraction * (tb - tb0)
        if h != 0.0:
            convection[name()] = (h, tb)
    for idx, name in _load_sets(session, fem, "hflux", faces.hflux_record,
                                None if fprev is None else fprev["hflux"], boundary):
        q = float(faces.hflux[idx[0]])
        if fprev is not None:
            q0 = float(np.nan_to_num(fprev["hflux"][idx[0]]))
            q = q0 + fraction * (q - q0)
        if q != 0.0:
            flux[name()] = q
    d = db.nodes.arrays["d_temp"]
    fixed = np.nonzero(~np.isnan(d) & (fem.thermal_dof >= 0))[0]
    values = d[fixed]
    if prev is not None:
        d0 = prev["d_temp"][fixed]
        d0 = np.where(np.isnan(d0), tunif, d0)
        values = d0 + fraction * (values - d0)
    contact = {}
    for name in fem.mesh.interfaces:
        real = session.db.contact_real_sets.get(name)
        tcc = db.real_sets.get(real, {}).get(TCC_LOCATION) if real is not None else None
        if tcc is not None:
            if not tcc > 0.0:
                raise ApdlError(f"TCC of real set {real} (contact {name}) must be > 0, got {tcc!r}")
            contact[name] = 1.0 / tcc
    return ThermalLoads(sources=sources, convection=convection, flux=flux,
                        contact_resistance=contact,
                        fixed_dofs=(fem.thermal_dof[fixed], values) if fixed.size else None)


def _load_sets(session: SessionState, fem: FemModel, kind: str, record: np.ndarray,
               extra: np.ndarray | None, name_of: Callable[[np.ndarray], str]
               ) -> list[tuple[np.ndarray, Callable[[], str]]]:
    """`record_groups(record, extra)`, each group with a function giving its region or
    boundary name (`name_of`, called when the group's load is not zero, as it adds a set
    the session's mesh does not have yet).  Without `extra` (a load step that is not ramped) the
    groups and their names are kept in the session by `kind` and reused while the
    record array partitions the entities as the last one of `kind` did
    (`RecordPartition.order_of`): a window deck's load steps restate their loads on the
    same components."""
    if extra is not None:
        return [(g, partial(name_of, g)) for g in record_groups(record, extra)]
    kept = session.fem.partitions.get(kind)
    order = kept.order_of(record, fem) if kept is not None else None
    if kept is None or order is None:
        kept = session.fem.partitions[kind] = RecordPartition.of(record, fem)
        order = list(range(len(kept.groups)))

    def named(i: int) -> str:
        name = kept.names[i]
        if name is None:
            name = kept.names[i] = name_of(kept.groups[i])
        return name

    return [(kept.groups[i], partial(named, i)) for i in order]


def _first_step_loads(session: SessionState) -> dict:
    """Ramps of the first load step start from no load (NaN: zero, or TUNIF)."""
    db = session.db
    n_faces = db.faces.keys.size
    return {"hgen": np.full(len(db.elements.ids), np.nan),
            "d_temp": np.full(len(db.nodes.ids), np.nan),
            "faces": {k: np.full(n_faces, np.nan) for k in ("conv_h", "conv_bulk", "hflux")},
            "key": session.fem.model_key}


def _snapshot(session: SessionState) -> dict:
    db = session.db
    f = db.faces
    return {"hgen": db.elements.arrays["hgen"].copy(),
            "d_temp": db.nodes.arrays["d_temp"].copy(),
            "faces": {"conv_h": f.conv_h.copy(), "conv_bulk": f.conv_bulk.copy(),
                      "hflux": f.hflux.copy()},
            "key": session.fem.model_key}


def initial_temperature(session: SessionState, fem: FemModel, n_dofs: int) -> np.ndarray:
    base = np.full(n_dofs, session.db.settings.tunif)
    return fem.nodal_to_thermal(session.db.nodes.arrays["ic_temp"], base)


def face_table(session: SessionState) -> FemModel | FaceTable:
    """The exterior faces SF/SFE load: the AxiMesh's (a twin session) or the deck mesh's."""
    if session.fem.external_mesh:
        return fem_model(session)
    from apdl_like.plane_solve import deck_faces  # a deck's own mesh: imported when used

    return deck_faces(session)


def solve_thermal(session: SessionState) -> StepResult:
    """A thermal load step: on twin.fem for a twin session, else on the deck's own mesh."""
    if np.any(~np.isnan(session.db.faces.rdsf_emis)):
        raise ApdlError("radiation between RDSF surfaces is not solved (apdl_like computes "
                        "their view factors only: /AUX12, VFQUERY)")
    if not session.fem.external_mesh:
        from apdl_like.plane_solve import solve_plane_thermal

        return solve_plane_thermal(session)
    refuse_deck_mesh_loads(session, "solved")
    fem = fem_model(session)
    _check_axisymmetric(session, "thermal")
    problem = thermal_problem(session, fem)
    s = session.db.settings
    sol = session.solution
    if sol.previous_loads is not None and sol.previous_loads["key"] != session.fem.model_key:
        sol.previous_loads = None
    if sol.fresh_start or sol.temperature is None or sol.temperature.size != problem.n_dofs:
        sol.temperature = initial_temperature(session, fem, problem.n_dofs)
        sol.time = 0.0
        sol.fresh_start = False
    ramped = s.kbc == 0 and s.antype == "TRANS"
    steps_T, steps_t = [], []
    if s.antype == "STATIC" or s.timint is False:
        end = s.time if s.time is not None else sol.time + 1.0
        loads = thermal_loads(session, fem)
        problem = on_model_mesh(session, fem)
        try:
            T = problem.steady(loads)
        except ValueError as exc:
            raise ApdlError(str(exc)) from None
        steps_T, steps_t = [T], [end]
    else:
        span = sol.span_to(s.time)
        n = s.substeps(span)
        dt = span / n
        T = sol.temperature
        stepper = None
        for k in range(1, n + 1):
            if stepper is None or ramped:
                loads = thermal_loads(session, fem, k / n if ramped else 1.0)
                stepper = on_model_mesh(session, fem).transient(loads, dt)
            T = stepper.step(T)
            steps_T.append(T)
            steps_t.append(sol.time + k * dt if k < n else s.time)
    sol.temperature = steps_T[-1]
    sol.time = steps_t[-1]
    sol.substep_times = steps_t
    sol.substep_temperatures = steps_T
    sol.previous_loads = _snapshot(session)
    return StepResult(len(sol.results) + 1, sol.time, "thermal", sol.temperature,
                      nodal_temperature=fem.thermal_nodal(sol.temperature))


def _constraints(session: SessionState, fem: FemModel) -> dict[str, str]:
    nodes = session.db.nodes.arrays
    for label in ("d_ux", "d_uy"):
        v = nodes[label]
        if np.any(v[~np.isnan(v)] != 0.0):
            raise ApdlError(f"only zero displacements are supported ({label[2:].upper()} ≠ 0)")
    ux, uy = ~np.isnan(nodes["d_ux"]), ~np.isnan(nodes["d_uy"])
    fn = fem.face_nodes
    face_ux = ux[fn[0]] & ux[fn[1]]
    face_uy = uy[fn[0]] & uy[fn[1]]
    out = {}
    for mask, comps in ((face_ux & face_uy, "rz"), (face_ux & ~face_uy, "r"),
                        (face_uy & ~face_ux, "z")):
        if mask.any():
            out[fem.boundary_for(fem.face_facets[mask])] = comps
    for label, nodal, face in (("UX", ux, face_ux), ("UY", uy, face_uy)):
        covered = np.zeros(nodal.size, bool)
        covered[fn[0, face]] = covered[fn[1, face]] = True
        ends = fem.midside_ends  # a mid-side node between two held corners is held with them
        covered[fem.midside_nodes] = covered[ends[0]] & covered[ends[1]]
        lone = nodal & ~covered & (fem.glued_dof >= 0)
        if lone.any():
            n = int(session.db.nodes.ids[np.nonzero(lone)[0][0]])
            raise ApdlError(f"D,{label} on node {n} is not on a constrained boundary edge: "
                            "constraints act on element faces whose nodes are all constrained")
    if not any("z" in c for c in out.values()):
        raise ApdlError("the structure needs an axial constraint (D,...,UY,0 on an edge)")
    return out


def solve_structural(session: SessionState) -> StepResult:
    """A static thermo-elastic load step: twin.fem for a twin session, else the deck mesh."""
    if not session.fem.external_mesh:
        from apdl_like.plane_solve import solve_plane_structural

        return solve_plane_structural(session)
    fem = fem_model(session)
    _check_axisymmetric(session, "structural")
    s = session.db.settings
    if s.antype != "STATIC":
        raise ApdlError("structural analyses are static only (ANTYPE,STATIC)")
    mats = _materials(session, fem, "structural")
    constraints = _constraints(session, fem)
    key = (id(fem), _material_key(mats), tuple(sorted(constraints.items())), s.tref, fem.order)
    cache = session.fem
    if cache.elastic_key != key:
        try:
            cache.elastic = ElasticProblem(fem.mesh, mats, constraints, T_ref=s.tref,
                                             order=fem.order)
        except RuntimeError as exc:  # singular stiffness (a mechanism)
            raise ApdlError(f"the structure is not held (singular stiffness: {exc})") from None
        cache.elastic_key = key
    elastic = cache.elastic
    n_t = elastic.temperature_basis.N
    sol = session.solution
    base = np.full(n_t, s.tunif)
    body = sol.body_temperature
    if body is not None:
        if cache.external_mesh and body.temperature.size == n_t:
            base = body.temperature  # the same twin.fem dofs
        else:
            base = fem.nodal_to_thermal(body.nodal_temperature, base)
    T = fem.nodal_to_thermal(session.db.nodes.arrays["bf_temp"], base)
    u = elastic.solve(T)
    stress = elastic.stresses(u, T)
    sol.time = s.time if s.time is not None else sol.time + 1.0
    return StepResult.structural(len(sol.results) + 1, sol.time, T, u, stress,
                                 fem.glued_nodal, fem.thermal_nodal(T))
