"""The committed spindle mesh: quality, named sets, consistency with the spec."""

import numpy as np
import pytest
from typer.testing import CliRunner

from twin.fem import AxiMesh
from twin.spindle.mesher import build_mesh, mesh_quality
from twin.spindle.model import DEFAULT_MESH_PATH
from twin.spindle.spec import BOUNDARY_NAMES, load_spec


@pytest.fixture(scope="module")
def spec():
    return load_spec()


@pytest.fixture(scope="module")
def mesh(spec):
    return AxiMesh.from_msh(DEFAULT_MESH_PATH, interfaces=spec.interfaces())


def test_committed_mesh_is_small_and_well_shaped(mesh):
    q = mesh_quality(mesh.glued.p.T, mesh.glued.t.T)
    assert 1000 <= q["n_nodes"] <= 6000
    assert q["min_angle_deg"] >= 15.0
    assert q["max_aspect"] <= 4.0


def test_refined_mesh_quality_and_size(spec):
    fine = build_mesh(spec, size_factor=0.7)
    q = mesh_quality(fine.points, fine.triangles)
    assert q["min_angle_deg"] >= 15.0 and q["max_aspect"] <= 4.0
    coarse = mesh_quality(*(lambda m: (m.points, m.triangles))(build_mesh(spec, 1.0)))
    assert q["n_nodes"] > 1.5 * coarse["n_nodes"]


def test_quality_measure_on_known_triangles():
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2], [0.0, 1.0]])
    q = mesh_quality(pts, np.array([[0, 1, 2]]))
    assert q["min_angle_deg"] == pytest.approx(60.0)
    assert q["max_aspect"] == pytest.approx(1.0)
    q = mesh_quality(pts, np.array([[0, 1, 3]]))  # right isosceles: 45°, aspect √2·√3/2·...
    assert q["min_angle_deg"] == pytest.approx(45.0)
    assert q["max_aspect"] == pytest.approx(np.sqrt(2) / (np.sqrt(2) / 2) * np.sqrt(3) / 2)


def test_committed_mesh_matches_the_spec(spec, mesh):
    regenerated = build_mesh(spec, 1.0)
    assert regenerated.points.shape[0] == mesh.glued.p.shape[1]
    assert set(mesh.regions) == set(spec.regions)
    # rectangles revolved: the linear mesh reproduces the volumes exactly
    from twin.fem import ThermalProblem
    from twin.spindle.model import (
        SpindleModel,  # noqa: F401
        fem_material,
    )

    tp = ThermalProblem(mesh, {r: fem_material(spec, r) for r in spec.regions})
    for region in spec.regions:
        assert tp.volume(region) == pytest.approx(spec.region_volume_m3(region), rel=1e-9)


def test_every_boundary_and_both_interfaces_are_named(spec, mesh):
    assert set(mesh.boundaries) == set(BOUNDARY_NAMES)
    assert set(mesh.interfaces) == {"contact_front", "contact_rear"}
    for side in ("front", "rear"):
        b = spec.bearings[side]
        assert set(mesh.interfaces[b.interface].regions) == {b.outer_ring, b.sleeve}
        ring = spec.region_box(b.outer_ring)
        f = mesh.interfaces[b.interface].facets_a
        xy = mesh.thermal.p[:, mesh.thermal.facets[:, f]] * 1e3
        assert np.allclose(xy[0], ring.r_outer_mm)  # on the ring's outer diameter
        assert xy[1].min() == pytest.approx(ring.z_start_mm)
        assert xy[1].max() == pytest.approx(ring.z_end_mm)


def _facet_xy_mm(mesh, name):
    return mesh.thermal.p[:, mesh.thermal.facets[:, mesh.boundaries[name]]] * 1e3


def test_boundary_classification_spot_checks(spec, mesh):
    assert np.allclose(_facet_xy_mm(mesh, "axis")[0], 0.0)
    assert np.allclose(_facet_xy_mm(mesh, "mount")[1], spec.structure.mount_z_mm)
    nose = spec.region_box("shaft")
    assert np.allclose(_facet_xy_mm(mesh, "nose_face")[1], nose.z_end_mm)
    rotor = spec.region_box(spec.motor.rotor)
    assert np.allclose(_facet_xy_mm(mesh, "air_gap_rotor")[0], rotor.r_outer_mm)
    # coolant facets lie on channel walls
    xy = _facet_xy_mm(mesh, "coolant").reshape(2, -1)
    on_wall = np.zeros(xy.shape[1], bool)
    for c in spec.coolant_channels:
        on_wall |= ((xy[0] >= c.r_inner_mm - 1e-6) & (xy[0] <= c.r_outer_mm + 1e-6)
                    & (xy[1] >= c.z_start_mm - 1e-6) & (xy[1] <= c.z_end_mm + 1e-6))
    assert on_wall.all()
    # the housing's outer cylinder is housing_outer
    hx = _facet_xy_mm(mesh, "housing_outer")
    assert np.isclose(hx[0], 125.0).any()


def test_twin_mesh_cli(tmp_path):
    from twin.cli import app

    out = tmp_path / "coarse.msh"
    result = CliRunner().invoke(app, ["mesh", "--size-factor", "1.5", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert out.exists() and "nodes" in result.output
    m = AxiMesh.from_msh(out, interfaces=("contact_front", "contact_rear"))
    assert set(m.boundaries) == set(BOUNDARY_NAMES)
    assert [p.name for p in tmp_path.iterdir()] == ["coarse.msh"]  # no temp files left
    bad = CliRunner().invoke(app, ["mesh", "--size-factor", "-1", "--out", str(out)])
    assert bad.exit_code == 2 and "--size-factor" in bad.output
