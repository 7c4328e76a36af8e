"""apdl_like session for the twin: window decks, operator reuse, load-set round trip, CDB
exchange with mapdl-archive, and the `apdl-like` CLI."""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
from unittest.mock import ANY

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from apdl_like.errors import ApdlError
from apdl_like.loadset import LoadSet
from apdl_like.session import Session
from apdl_like.writer import DeckLayout, window_deck
from tests.apdl_decks import held_faces
from twin.fem import AxiMesh, Material, ThermalLoads, ThermalProblem

STEEL = Material(k=49.8, rho=7830.0, c=465.0, E=210e9, nu=0.265, alpha=12.2e-6)
BRONZE = Material(k=60.0, rho=8800.0, c=380.0)


@pytest.fixture(scope="module")
def mesh() -> AxiMesh:
    return _mesh()


def _mesh() -> AxiMesh:
    r = np.linspace(0.0, 0.04, 13)
    z = np.linspace(0.0, 0.08, 25)
    return AxiMesh.structured(
        r, z,
        regions={"shaft": lambda r, z: r < 0.02, "sleeve": lambda r, z: r > 0.02,
                 "bearing_front": lambda r, z: (r > 0.02) & (z > 0.05),
                 "bearing_rear": lambda r, z: (r > 0.02) & (z < 0.02)},
        boundaries={"coolant": lambda r, z: np.isclose(r, 0.04),
                    "nose_face": lambda r, z: np.isclose(z, 0.08),
                    "mount": lambda r, z: np.isclose(z, 0.0)},
        interfaces={"contact_front": lambda r, z: np.isclose(r, 0.02)},
    )


def loadset(window: int, q_front: float = 1.1e6, r_front: float = 1.5e-4) -> LoadSet:
    return LoadSet(window=window, start_s=60.0 * window,
                   heat_generation={"bearing_front": q_front, "bearing_rear": 4.0e5},
                   convection={"coolant": (450.0, 22.5), "nose_face": (12.0, 24.0)},
                   contact_resistance={"contact_front": r_front})


def test_window_deck_round_trip(mesh):
    ls = loadset(7)
    deck = window_deck(ls, DeckLayout.for_mesh(mesh))
    back = Session.from_mesh(mesh, {"shaft": STEEL, "sleeve": BRONZE}).read_window_deck(deck)
    assert back == ls


finite = st.floats(min_value=1e-9, max_value=1e9, allow_nan=False, allow_infinity=False)


@settings(max_examples=40, deadline=None)
@given(window=st.integers(0, 10_000), dt=st.floats(0.01, 100.0), n=st.integers(1, 50),
       q=st.floats(-1e9, 1e9), h=st.floats(0.0, 1e5), tb=st.floats(-50.0, 500.0),
       r=finite)
def test_round_trip_is_exact_for_any_values(mesh, window, dt, n, q, h, tb, r):
    ls = LoadSet(window=window, start_s=window * n * dt, dt_s=dt, n_steps=n,
                 heat_generation={"bearing_rear": q}, convection={"coolant": (h, tb)},
                 contact_resistance={"contact_front": r})
    deck = window_deck(ls, DeckLayout.for_mesh(mesh))
    back = Session.from_mesh(mesh, {"shaft": STEEL, "sleeve": BRONZE}).read_window_deck(deck)
    assert back == ls
    # the resistance the solver uses is the given one to the last bit or within one ulp
    assert math.isclose(back.contact_resistance["contact_front"], r, rel_tol=2.3e-16)


def test_window_decks_reuse_operators_and_match_the_fem_api(mesh):
    mats = {"shaft": STEEL, "sleeve": BRONZE}
    s = Session.from_mesh(mesh, mats, T_initial_C=20.0)
    s.run_text(window_deck(loadset(0), s.layout), "window_000.inp")
    problem = s.thermal
    terms = set(problem.ops._terms)
    sources = set(problem._source_vectors)
    T_first = s.state.solution.temperature.copy()
    # the loop's call: the state handed in explicitly, every substep handed back
    steps = s.advance(T_first, 60.0, window_deck(loadset(1, q_front=1.3e6, r_front=1.1e-4),
                                                  s.layout), "w1.inp")
    assert s.thermal is problem  # mesh, materials, operators kept
    assert set(problem.ops._terms) == terms and set(problem._source_vectors) == sources
    assert s.state.solution.time == 120.0 and steps.shape == (15, problem.n_dofs)
    np.testing.assert_array_equal(steps[-1], s.state.solution.temperature)
    # a window holds its own result only (the loop advances every 4 s step: kept, the
    # results of a whole run piled up in the session)
    assert [(r.load_step, r.time) for r in s.results] == [(1, 120.0)]
    np.testing.assert_array_equal(s.results[0].temperature, steps[-1])

    # the same two windows through twin.fem directly, loads written by hand
    ref = ThermalProblem(mesh, mats)
    T = np.full(ref.n_dofs, 20.0)
    for q_front, r_front in ((1.1e6, 1.5e-4), (1.3e6, 1.1e-4)):
        stepper = ref.transient(ThermalLoads(
            sources={"bearing_front": q_front, "bearing_rear": 4.0e5},
            convection={"coolant": (450.0, 22.5), "nose_face": (12.0, 24.0)},
            contact_resistance={"contact_front": r_front}), dt=4.0)
        for _ in range(15):
            T = stepper.step(T)
        if q_front == 1.1e6:
            np.testing.assert_allclose(T_first, T, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(s.state.solution.temperature, T, rtol=1e-12, atol=1e-12)


def test_session_adopts_an_assembled_thermal_problem(mesh):
    mats = {"shaft": STEEL, "sleeve": BRONZE}
    problem = ThermalProblem(mesh, mats)
    s = Session.from_mesh(mesh, mats, thermal=problem)
    s.run_text(window_deck(loadset(0), s.layout), "w.inp")
    assert s.thermal is problem
    with pytest.raises(ValueError, match="other materials"):
        Session.from_mesh(mesh, {"shaft": STEEL, "sleeve": STEEL}, thermal=problem)


def test_window_deck_needs_its_session_components(mesh):
    s = Session()  # no model
    with pytest.raises(ApdlError, match="does not exist"):
        s.run_text(window_deck(loadset(0), DeckLayout.for_mesh(mesh)), "w.inp")


def test_window_deck_round_trip_on_the_spindle_mesh():
    from twin.spindle.model import DEFAULT_MESH_PATH, fem_material
    from twin.spindle.spec import load_spec

    spec = load_spec()
    mesh = AxiMesh.from_msh(DEFAULT_MESH_PATH, interfaces=spec.interfaces())
    materials = {region: fem_material(spec, region) for region in spec.regions}
    layout = DeckLayout.for_mesh(mesh)
    ls = LoadSet(
        window=3, start_s=180.0,
        heat_generation={name: 1e5 * (i + 1) for i, name in enumerate(sorted(mesh.regions))},
        convection={name: (10.0 * (i + 1), 20.0 + i) for i, name in
                    enumerate(sorted(mesh.boundaries))},
        contact_resistance={name: 1e-4 * (i + 1) for i, name in
                            enumerate(sorted(mesh.interfaces))})
    # every region and boundary maps back to itself: the node components of the
    # boundaries select exactly their own faces
    assert Session.from_mesh(mesh, materials).read_window_deck(window_deck(ls, layout)) == ls


@pytest.mark.slow
# ----------------------------------------------------------------- CDB
def test_export_cdb_reads_back_with_mapdl_archive(tmp_path):
    from mapdl_archive import Archive

    from twin.spindle.model import DEFAULT_MESH_PATH
    from twin.spindle.spec import load_spec

    out = tmp_path / "spindle.cdb"
    done = subprocess.run([sys.executable, "-m", "apdl_like", "export-cdb", "--out", str(out),
                           "--quiet"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    mesh = AxiMesh.from_msh(DEFAULT_MESH_PATH, interfaces=load_spec().interfaces())
    archive = Archive(str(out))
    assert archive.n_node == mesh.thermal.p.shape[1]
    assert archive.n_elem == mesh.n_cells
    assert len(archive.element_components) == len(mesh.regions)
    assert len(archive.node_components) == len(mesh.boundaries) + 2 * len(mesh.interfaces)
    # and our own /INPUT reads the same archive
    (tmp_path / "read.inp").write_text("/INPUT,spindle,cdb\n*GET,NN,NODE,0,NUM,COUNT\n"
                                       "*GET,NE,ELEM,0,NUM,COUNT\n")
    s = Session()
    s.run_file(tmp_path / "read.inp")
    assert s.params["NN"] == archive.n_node and s.params["NE"] == archive.n_elem
    assert len(s.db.components) == len(archive.element_components) + len(
        archive.node_components)


def test_export_cdb_of_a_spindle_msh_keeps_its_contact_faces_apart(tmp_path):
    # `--mesh` glued the contact interfaces (CONTACT_FRONT, not _A/_B; 20 nodes fewer)
    from typer.testing import CliRunner

    from apdl_like.cli import app
    from twin.spindle.model import DEFAULT_MESH_PATH

    def components(path):
        return sorted(line.split(",")[1] for line in path.read_text().splitlines()
                      if line.upper().startswith("CMBLOCK"))

    default, given = tmp_path / "default.cdb", tmp_path / "given.cdb"
    for out, extra in ((default, []), (given, ["--mesh", str(DEFAULT_MESH_PATH)])):
        result = CliRunner().invoke(app, ["export-cdb", "--out", str(out), *extra])
        assert result.exit_code == 0, result.output
    assert components(given) == components(default)
    assert "CONTACT_FRONT_A" in components(given) and "CONTACT_REAR_B" in components(given)
    nodes = [CliRunner().invoke(app, ["export-cdb", "--out", str(tmp_path / "x.cdb"),
                                      *extra]).output.split(": ")[1].split(",")[0]
             for extra in ([], ["--mesh", str(DEFAULT_MESH_PATH)])]
    assert nodes[0] == nodes[1]


@pytest.mark.parametrize("text", ["$MeshFormat\n", "garbage\n"])
def test_export_cdb_of_a_file_that_is_no_mesh_exits_2(text, tmp_path):
    # meshio failed with IndexError, or exited the process itself (exit 1)
    from typer.testing import CliRunner

    from apdl_like.cli import app

    bad = tmp_path / "bad.msh"
    bad.write_text(text)
    result = CliRunner().invoke(app, ["export-cdb", "--out", str(tmp_path / "x.cdb"),
                                      "--mesh", str(bad)])
    assert result.exit_code == 2
    assert result.output.startswith(f"error: {bad}: not a readable gmsh mesh (")
    assert result.output.count("\n") == 1 and not (tmp_path / "x.cdb").exists()


def test_input_of_a_cdb_written_by_mapdl_archive(tmp_path):
    """mapdl-archive writes triangles as SHELL181; the deck redefines the type as PLANE55
    axisymmetric and solves the hollow-cylinder log profile."""
    import pyvista as pv
    from mapdl_archive import save_as_archive
    from skfem import MeshTri

    ri, ro, h, k, q = 0.02, 0.05, 0.01, 50.0, 2e5
    base = MeshTri.init_tensor(np.linspace(ri, ro, 31), np.linspace(0.0, h, 3))
    points = np.column_stack([base.p.T, np.zeros(base.p.shape[1])])
    cells = np.hstack([np.full((base.t.shape[1], 1), 3), base.t.T]).ravel()
    grid = pv.UnstructuredGrid(cells, np.full(base.t.shape[1], pv.CellType.TRIANGLE), points)
    save_as_archive(str(tmp_path / "strip.cdb"), grid)
    (tmp_path / "deck.inp").write_text(f"""
/INPUT,strip,cdb
/PREP7
ET,4,PLANE55
KEYOPT,4,3,1
EMODIF,ALL,MAT,1        ! mapdl-archive numbers a material per cell
MP,KXX,1,{k}
FINISH
/SOLU
NSEL,S,LOC,X,{ri}
SF,ALL,HFLUX,{q}
NSEL,S,LOC,X,{ro}
D,ALL,TEMP,30
ALLSEL
SOLVE
*GET,T_IN,NODE,NODE({ri},0),TEMP
""")
    s = Session()
    s.run_file(tmp_path / "deck.inp")
    exact = 30.0 + q * ri / k * math.log(ro / ri)
    assert s.params["T_IN"] == pytest.approx(exact, rel=2e-3)


# ------------------------------------------------------------------ CLI
def test_cli_run_writes_params_and_vtu(tmp_path):
    import meshio

    deck = tmp_path / "d.inp"
    deck.write_text(f"""/PREP7
ET,1,PLANE55,,,1
MP,KXX,1,10
RECTNG,0.01,0.02,0,0.01
ESIZE,0.005
AMESH,ALL
/SOLU
{held_faces("X", (0.01, 100), (0.02, 50))}
SOLVE
FINISH
/POST1
PRNSOL,TEMP
*GET,NMAX,NODE,0,NUM,MAX
""")
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(deck), "--out",
                           str(out)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    params = json.loads((out / "params.json").read_text())
    assert set(params) == {"NMAX"}
    vtu = meshio.read(out / "result_001.vtu")
    T = vtu.point_data["TEMP"]
    r = vtu.points[:, 0]
    # T = T_i − (T_i − T_o) ln(r/r_i)/ln(r_o/r_i): the nodes on the two radii are exact
    assert np.allclose(T[np.isclose(r, 0.01)], 100.0) and np.allclose(T[np.isclose(r, 0.02)],
                                                                          50.0)
    assert "PRNSOL" in (out / "log.txt").read_text()


@pytest.mark.parametrize("text, where", [
    ("/PREP7\nN,1,0,0\nET,1,PLANE55\nMP,KXX,1,-1\n", "d.inp:4: MP"),
    ("/SOLU\nSOLVE\n", "d.inp:2: SOLVE"),
    ("A = 1/0\n", "d.inp:1: A = 1/0: division by zero"),
    ("*MSG,FATAL,7\nstop: %I\nB = 1\n", "d.inp:1: *MSG: FATAL: stop: 7."),
])
def test_cli_bad_deck_exits_2_without_traceback(tmp_path, text, where):
    deck = tmp_path / "d.inp"
    deck.write_text(text)
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(deck), "--out",
                           str(tmp_path / "o")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert where in done.stderr and "Traceback" not in done.stderr
    # the log says where the run stopped
    assert where in (tmp_path / "o" / "log.txt").read_text().splitlines()[-1]


def test_cli_counts_msg_errors_and_runs_on(tmp_path):
    # *MSG,ERROR in batch: told on stderr, counted in the summary, the run goes on (exit 0)
    deck = tmp_path / "d.inp"
    deck.write_text("*MSG,ERROR,3\n%I bad rows\n*MSG,WARN\ncheck\nB = 1\n")
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(deck), "--out",
                           str(tmp_path / "o")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines() == [f"error: {deck}:1: *MSG: 3 bad rows.",
                                        f"warning: {deck}:3: *MSG: check."]
    assert done.stdout.rstrip().endswith("; 1 *MSG,ERROR message(s), told on stderr")
    log = (tmp_path / "o" / "log.txt").read_text().splitlines()
    assert log[:2] == [" *** ERROR ***", " 3 bad rows."]
    assert json.loads((tmp_path / "o" / "params.json").read_text())["B"] == 1.0


def test_cli_bad_line_keeps_what_ran_before_it(tmp_path):
    """Statement by statement: a results table written and a load step solved before a bad
    line are kept in --out; the run still exits 2 naming the line."""
    deck = tmp_path / "d.inp"
    deck.write_text("/PREP7\nET,1,PLANE55\nMP,KXX,1,2\nN,1,0,0\nN,2,1,0\nN,3,1,1\n"
                    "N,4,0,1\nE,1,2,3,4\nD,1,TEMP,10\nD,4,TEMP,10\nD,2,TEMP,30\n"
                    "D,3,TEMP,30\n/SOLU\nSOLVE\n/POST1\n*GET,TMID,NODE,2,TEMP\n"
                    "/OUT,table,txt\n*VWRITE,TMID\n(F8.2)\n/OUT\nMP,KXX,1,-1\n")
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(deck), "--out",
                           str(tmp_path / "o")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "d.inp:21: MP" in done.stderr
    out = tmp_path / "o"
    assert float((out / "table.txt").read_text().split()[0]) == 30.0
    assert (out / "result_001.vtu").is_file()
    assert json.loads((out / "params.json").read_text())["TMID"] == 30.0


def test_cli_warns_on_unknown_commands_and_strict_makes_them_errors(tmp_path):
    deck = tmp_path / "d.inp"
    deck.write_text("A = 2\nBOGUS,1\n")
    run = [sys.executable, "-m", "apdl_like", "run", str(deck), "--out", str(tmp_path / "o")]
    done = subprocess.run(run, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "d.inp:2: BOGUS: unknown or unsupported command BOGUS; ignored" in done.stderr
    strict = subprocess.run([*run, "--strict"], capture_output=True, text=True, timeout=120)
    assert strict.returncode == 2 and "d.inp:2: BOGUS" in strict.stderr
    assert "Traceback" not in strict.stderr


def test_spindle_session_refuses_what_twin_fem_cannot_solve(mesh):
    """The spindle session solves on twin.fem (constant, isotropic k): a k(T) or a KYY
    is an error naming the material, never silently dropped."""
    for change in ("MP,KXX,1,45,0.01", "MP,KYY,1,3"):
        s = Session.from_mesh(mesh, {"shaft": STEEL, "sleeve": BRONZE})
        with pytest.raises(ApdlError, match="material 1"):
            s.run_text(f"/PREP7\n{change}\nFINISH\n" + window_deck(loadset(0), s.layout),
                       "w.inp")


def test_a_deck_saved_with_a_utf8_bom_runs(tmp_path):
    # Notepad and other Windows editors start a UTF-8 file with a byte-order mark: the
    # deck stopped at line 1 ("not a command or assignment: '\ufeff/PREP7'"), while the
    # run CSVs beside it were read with their BOM; a deck it /INPUTs may carry one too
    (tmp_path / "sub.inp").write_bytes(b"\xef\xbb\xbfB = A + 1\r\n")
    (tmp_path / "deck.inp").write_bytes(b"\xef\xbb\xbf/PREP7\r\nA = 2\r\n/INPUT,sub,inp\r\n")
    s = Session(base_dir=tmp_path)
    s.run_file(tmp_path / "deck.inp")
    assert s.params["A"] == 2.0 and s.params["B"] == 3.0


def test_a_later_load_step_restates_only_what_changed_and_solves_the_same(mesh):
    # a window of 15 load steps whose bearing loads follow the rings restated all 54 loads
    # every 4 s step; loads stay until changed, so load step i + 1 writes only its changes
    mats = {"shaft": STEEL, "sleeve": BRONZE}
    first = dataclasses.replace(loadset(1), n_steps=1)
    second = dataclasses.replace(loadset(1, q_front=1.3e6), start_s=64.0, n_steps=1)
    layout = DeckLayout.for_mesh(mesh)
    short = window_deck(second, layout, load_step=(2, 15), after=first)
    full = window_deck(second, layout, load_step=(2, 15))
    assert short.count("BFE") == 1 and "SF," not in short and "RMODIF" not in short
    assert full.count("BFE") == 2 and full.count("SF,") == 2 and "RMODIF" in full
    # a load set naming other regions than the step before is written in full
    other = dataclasses.replace(second, heat_generation={"bearing_front": 1.3e6})
    assert window_deck(other, layout, load_step=(2, 15), after=first).count("SF,") == 2
    # the first load step of a deck is always written in full
    assert window_deck(second, layout, load_step=(1, 15), after=first) == \
        window_deck(second, layout, load_step=(1, 15))
    runs = []
    for deck in (short, full):
        s = Session.from_mesh(mesh, mats, T_initial_C=20.0)
        s.run_text(window_deck(loadset(0), s.layout), "window_000.inp")
        T = s.advance(s.state.solution.temperature.copy(), 60.0,
                      window_deck(first, layout, load_step=(1, 15)))[-1]
        runs.append(s.advance(T, 64.0, deck)[-1])
    np.testing.assert_array_equal(runs[0], runs[1])
    assert np.abs(runs[0] - T).max() > 0.01  # the step moved the field


def _load_step(time_s: float, loads: str) -> str:
    return f"/SOLU\nANTYPE,TRANS,REST\nKBC,1\nDELTIM,4.0\nTIME,{time_s!r}\n{loads}\nALLSEL\nSOLVE\n"


# load steps after a window deck (bearing_front, bearing_rear heated; coolant, nose_face
# films): each keeps or changes how the loads group the elements and faces
LATER_LOAD_STEPS = (
    "CMSEL,S,BEARING_FRONT\nBFE,ALL,HGEN,,1.2e6",  # new records, the same groups
    "CMSEL,S,BEARING_FRONT\nBFE,ALL,HGEN,,1.25e6\nCMSEL,S,BEARING_REAR\nBFE,ALL,HGEN,,5e5",
    "CMSEL,S,BEARING_FRONT\nBFE,ALL,HGEN,,1.3e6",  # the records' order turns, and back
    "ESEL,S,CENT,Y,0.07,0.08\nCMSEL,R,BEARING_FRONT\nBFE,ALL,HGEN,,2e6",  # a group split
    "CMSEL,S,BEARING_FRONT\nCMSEL,A,BEARING_REAR\nBFE,ALL,HGEN,,9e5",  # groups merged
    "CMSEL,S,BEARING_REAR\nBFE,ALL,HGEN,,0",  # no heat there: not a source
    "CMSEL,S,COOLANT\nSF,ALL,CONV,500,23",  # a film's values change, its faces not
    "NSEL,S,LOC,Y,0.08\nSF,ALL,CONV,15,24\nCMSEL,S,COOLANT\nSF,ALL,CONV,0,23",
    "CMSEL,S,SHAFT\nBFE,ALL,HGEN,,1e5",  # a set no load named before
)


def test_load_groups_kept_between_load_steps_follow_every_change():
    """The session keeps the last SOLVE's load groups (`RecordPartition`) and reuses them
    while a load step loads the same sets with new records: every load step below solves
    to the bits and loads, in the same order, of a session that groups every step anew."""
    from apdl_like.solve import fem_model, thermal_loads

    mats = {"shaft": STEEL, "sleeve": BRONZE}
    # one mesh: the sets a session names are its own (the other names the same ones)
    shared = _mesh()
    kept, fresh = (Session.from_mesh(shared, mats, T_initial_C=20.0) for _ in range(2))
    for s in (kept, fresh):
        s.run_text(window_deck(dataclasses.replace(loadset(0), n_steps=1), s.layout), "w0.inp")
    partitions = kept.state.fem.partitions
    hgen = partitions["hgen"]
    order = []  # the heated regions of each load step, in the order of their loads
    for i, loads in enumerate(LATER_LOAD_STEPS):
        deck = _load_step(4.0 * (i + 2), loads)
        fresh.state.fem.partitions.clear()  # groups anew
        kept.run_text(deck, f"ls{i}.inp")
        fresh.run_text(deck, f"ls{i}.inp")
        np.testing.assert_array_equal(kept.state.solution.temperature,
                                      fresh.state.solution.temperature)
        fresh.state.fem.partitions.clear()
        got, want = (thermal_loads(s.state, fem_model(s.state)) for s in (kept, fresh))
        assert list(got.sources.items()) == list(want.sources.items())
        assert list(got.convection.items()) == list(want.convection.items())
        if i < 3:  # the same elements heated in the same groups: the groups were reused
            assert partitions["hgen"] is hgen
        order.append(list(got.sources))
    assert order[:4] == [["bearing_rear", "bearing_front"], ["bearing_front", "bearing_rear"],
                         ["bearing_rear", "bearing_front"], ["bearing_rear", ANY, ANY]]
    assert len(order[4]) == 1 and order[5] == ["bearing_front"]
    assert list(got.sources.items()) == [("bearing_front", 9e5), ("shaft", 1e5)]
    assert list(got.convection.items()) == [("nose_face", (15.0, 24.0))]


def test_a_record_partition_is_reused_only_for_the_same_groups_of_the_same_owner():
    from apdl_like.model import RecordPartition, record_groups

    record = np.array([-1, 7, 7, 3, -1, 3, 9])
    owner = object()
    p = RecordPartition.of(record, owner)
    assert [g.tolist() for g in p.groups] == [[3, 5], [1, 2], [6]]
    assert p.order_of(record, owner) == [0, 1, 2]
    relabelled = np.array([-1, 20, 20, 31, -1, 31, 12])  # new ids, other order
    assert p.order_of(relabelled, owner) == [2, 1, 0]
    assert [p.groups[i].tolist() for i in p.order_of(relabelled, owner)] == \
        [g.tolist() for g in record_groups(relabelled)]
    assert p.order_of(record, object()) is None  # another mesh's groups
    for changed in ([-1, 7, 8, 3, -1, 3, 9],  # a group split
                    [-1, 7, 7, 3, -1, 3, 3],  # two groups merged
                    [-1, 7, 7, 3, 4, 3, 9],  # one more loaded entity
                    [-1, 7, 7, 3, -1, 3, -1]):  # one fewer
        assert p.order_of(np.array(changed), owner) is None


def _partial_loads(time_s: float, heated_z: tuple[float, float],
                   cooled_z: tuple[float, float], restart: bool) -> str:
    """A load step of the spindle that heats part of the housing and cools part of its
    outer face: sets that are no region or boundary of the mesh."""
    return (f"/SOLU\nANTYPE,TRANS{',REST' if restart else ''}\nTIMINT,ON\nKBC,1\n"
            f"DELTIM,4.0\nTIME,{time_s!r}\n"
            f"ESEL,S,CENT,Y,{heated_z[0]!r},{heated_z[1]!r}\nCMSEL,R,HOUSING\n"
            "BFE,ALL,HGEN,,2e5\n"
            f"NSEL,S,LOC,Y,{cooled_z[0]!r},{cooled_z[1]!r}\nCMSEL,R,HOUSING_OUTER\n"
            "SF,ALL,CONV,15,22\nALLSEL\nSOLVE\nFINISH\n")


def test_sessions_sharing_a_spindle_model_keep_the_sets_they_name_to_themselves():
    """A session names each set a load falls on that the mesh has no name for; on the
    shared spindle model those names went onto the model's mesh, so two sessions named
    one set twice (_cells15 / _cells15_), a session's names depended on what another one
    had run, and every later session and archive of the mesh saw the other's sets.  Each
    session here solves and names its sets as a session on a model of its own, bit for
    bit, and the shared model (mesh, operators, field files, later sessions) is as
    loaded."""
    from apdl_like.cdb import cdb_text
    from apdl_like.solve import fem_model, thermal_loads
    from twin.loop.replay import spindle_session
    from twin.spindle.fields import field_mesh
    from twin.spindle.model import SpindleModel

    model = SpindleModel.load()
    mesh = model.mesh
    regions = {k: v.copy() for k, v in mesh.regions.items()}
    boundaries = {k: v.copy() for k, v in mesh.boundaries.items()}
    layout = DeckLayout.for_mesh(mesh)
    archive = cdb_text(mesh, model.materials)
    T0 = np.full(model.n_dofs, 20.0)
    field_regions = field_mesh(model, T0).cell_data["region"][0].copy()
    later = spindle_session(model)
    components = sorted(later.db.components)

    x = ((0.10, 0.20), (0.20, 0.30))  # heated and cooled z ranges
    y = ((0.25, 0.35), (0.05, 0.15))
    shared = {"a": spindle_session(model), "b": spindle_session(model)}
    own = {"a": spindle_session(SpindleModel.load()), "b": spindle_session(SpindleModel.load())}
    decks = {"a": (x, y), "b": (y, x)}
    for step in range(2):  # a, b, a, b: each session's sets after the other's
        for who in ("a", "b"):
            heated, cooled = decks[who][step]
            deck = _partial_loads(4.0 * (step + 1), heated, cooled, restart=step > 0)
            names = []
            for s in (shared[who], own[who]):
                s.run_text(deck, f"{who}{step}.inp")
                loads = thermal_loads(s.state, fem_model(s.state))
                names.append((list(loads.sources), list(loads.convection)))
            np.testing.assert_array_equal(shared[who].state.solution.temperature,
                                          own[who].state.solution.temperature)
            assert names[0] == names[1]
            assert len(names[0][0]) == step + 1 and len(names[0][1]) == step + 1
    # both sessions named a set of their own first: the same name, other cells
    assert thermal_loads(shared["a"].state, fem_model(shared["a"].state)).sources == \
        {"_cells15": 2e5, "_cells16": 2e5}
    # the shared model is as loaded
    assert mesh.regions.keys() == regions.keys() and mesh.boundaries.keys() == boundaries.keys()
    for now, before in ((mesh.regions, regions), (mesh.boundaries, boundaries)):
        for name, members in before.items():
            np.testing.assert_array_equal(now[name], members)
    assert set(model.thermal._source_vectors) <= set(regions)
    assert {t.split(":", 1)[1] for t in model.thermal.ops._terms if t.startswith("film:")} \
        <= set(boundaries)
    assert DeckLayout.for_mesh(mesh) == layout and cdb_text(mesh, model.materials) == archive
    np.testing.assert_array_equal(field_mesh(model, T0).cell_data["region"][0], field_regions)
    assert sorted(spindle_session(model).db.components) == components
    assert sorted(later.db.components) == components
