"""Field files (twin.io.vtk): compact, and read back bit for bit by meshio and VTK."""

from __future__ import annotations

import numpy as np
import pytest


def _frame():
    """A field frame of the default spindle as `twin replay` writes it, with field data."""
    from twin.spindle.fields import field_mesh
    from twin.spindle.model import SpindleModel

    model = SpindleModel.load()
    T = 22.0 + 10.0 * np.random.default_rng(7).random(model.n_dofs)
    mesh = field_mesh(model, T, 22.0)
    mesh.point_data["temperature_C"][0] = np.nan  # apdl-like marks nodes off the elements so
    mesh.field_data = {"TIME": np.array([60.0]), "READINGS": np.array([1 / 3, 2.5e-300])}
    return mesh


@pytest.fixture(scope="module")
def frame():
    return _frame()


def _payload_bytes(mesh) -> int:
    """The bytes of the values themselves: float64 points (3 coordinates) and arrays as
    given, Int32 connectivity and offsets, UInt8 cell types."""
    n_cells = sum(len(b.data) for b in mesh.cells)
    return (mesh.points.shape[0] * 3 * 8 + sum(b.data.size for b in mesh.cells) * 4
            + n_cells * (4 + 1)
            + sum(np.asarray(v).nbytes for v in mesh.point_data.values())
            + sum(np.asarray(b).nbytes for v in mesh.cell_data.values() for b in v))


@pytest.mark.parametrize("compress", [False, True])
def test_field_file_reads_back_bit_for_bit_in_meshio_and_pyvista(frame, tmp_path, compress):
    import meshio
    import pyvista as pv

    from twin.io.vtk import write_vtu

    path = write_vtu(tmp_path / "frame.vtu", frame, compress=compress)
    back = meshio.read(path)
    np.testing.assert_array_equal(back.points, frame.points)
    assert [b.type for b in back.cells] == ["triangle"]
    np.testing.assert_array_equal(back.cells[0].data, frame.cells[0].data)
    assert set(back.point_data) == {"temperature_C", "displacement_um", "von_mises_MPa"}
    for name, values in frame.point_data.items():
        assert back.point_data[name].dtype == np.float64  # no float32 rounding
        np.testing.assert_array_equal(back.point_data[name], values)
    np.testing.assert_array_equal(back.cell_data["region"][0], frame.cell_data["region"][0])
    for name, values in frame.field_data.items():
        np.testing.assert_array_equal(np.ravel(back.field_data[name]), values)

    grid = pv.read(path)
    np.testing.assert_array_equal(grid.points, frame.points)
    np.testing.assert_array_equal(grid.cells_dict[pv.CellType.TRIANGLE], frame.cells[0].data)
    for name, values in frame.point_data.items():
        np.testing.assert_array_equal(grid.point_data[name], values)
    np.testing.assert_array_equal(grid.cell_data["region"], frame.cell_data["region"][0])
    np.testing.assert_array_equal(grid.field_data["READINGS"], frame.field_data["READINGS"])


def test_field_file_is_the_values_and_little_more(frame, tmp_path):
    # meshio's writer stored every array base64-encoded (4/3 of its bytes), and the
    # connectivity, offsets and cell types as Int64: 412 kB for 220 kB of values
    from twin.io.vtk import write_vtu

    path = write_vtu(tmp_path / "frame.vtu", frame)
    size = path.stat().st_size
    assert size <= _payload_bytes(frame) + 3000, size
    head = path.read_bytes()[:4000]
    assert b'encoding="raw"' in head and b'format="binary"' not in head
    assert b'type="Int32" Name="connectivity"' in head
    assert b'type="UInt8" Name="types"' in head
    assert b'type="Float64" Name="temperature_C"' in head
    # compressed (the replay's window start states): smaller still, the same values
    packed = write_vtu(tmp_path / "packed.vtu", frame, compress=True)
    assert packed.stat().st_size < 0.7 * size
