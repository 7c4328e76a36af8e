"""Run outputs: params.json, result_NNN.vtu per solved load step (twin.io.vtk), log.txt.

VTU points are every APDL node at (X, Y, 0) = (r, z, 0) in metres; nodal arrays TEMP (°C),
U (m, 3 components, U_z = 0) and S (Pa, 6 components XX YY ZZ XY YZ XZ with ZZ the hoop
stress) plus SEQV; NaN marks nodes outside the elements; the field data TIME holds the load
step's end time (s).  Every file is written atomically.

A *state file* is the same format with TEMP and TIME only (`write_state_vtu`; a replay's
`decks/window_kkk_start.vtu`, with the estimator's READINGS_START_C, SENSOR_LAG_S and
SENSOR_OFFSET_C as further field data): `read_state_vtu` reads it, or any result_NNN.vtu,
as the temperature state a restart (ANTYPE,,REST) continues from (`apdl-like run --start`).
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin.io.atomic import write_text
from twin.io.vtk import read_vtu, write_vtu

if TYPE_CHECKING:
    from apdl_like.state import SessionState


def _cells(session: SessionState) -> list[tuple[str, np.ndarray]]:
    db = session.db
    el = db.elements
    solid = np.array([db.element_types[int(t)].physics != "surface" for t in el.type], bool)
    idx = db.nodes.index(el.nodes.ravel()).reshape(el.nodes.shape)
    tri6_type = np.array([db.element_types[int(t)].triangle6 for t in el.type], bool)
    quadratic = np.array([db.element_types[int(t)].quadratic for t in el.type], bool)
    degenerate = (el.nodes[:, 2] == el.nodes[:, 3]) & ~tri6_type
    blocks = []
    lin = ~quadratic & solid
    if np.any(lin & degenerate):
        blocks.append(("triangle", idx[lin & degenerate][:, :3]))
    if np.any(lin & ~degenerate):
        blocks.append(("quad", idx[lin & ~degenerate][:, :4]))
    q8 = quadratic & ~degenerate & ~tri6_type & solid
    if np.any(q8):
        blocks.append(("quad8", idx[q8]))
    t6 = quadratic & degenerate & solid
    if np.any(t6):
        blocks.append(("triangle6", idx[t6][:, [0, 1, 2, 4, 5, 7]]))
    if np.any(tri6_type):
        blocks.append(("triangle6", idx[tri6_type][:, :6]))
    return blocks


def write_result_vtu(session: SessionState, result_index: int, path: Path) -> None:
    import meshio

    res = session.solution.results[result_index]
    points = np.column_stack([session.db.nodes.xy, np.zeros(len(session.db.nodes.ids))])
    data = {"TEMP": res.nodal_temperature}
    nodal = res.nodal_structural
    if nodal:
        n = points.shape[0]
        u = np.zeros((n, 3))
        u[:, 0], u[:, 1] = nodal["UX"], nodal["UY"]
        s = np.zeros((n, 6))
        for j, item in enumerate(("SX", "SY", "SZ", "SXY")):
            s[:, j] = nodal[item]
        data.update(U=u, S=s, SEQV=nodal["SEQV"])
    mesh = meshio.Mesh(points, _cells(session), point_data=data,
                       field_data={"TIME": np.array([res.time])})
    write_vtu(path, mesh)


def write_state_vtu(path: str | Path, points_rz: np.ndarray, triangles: np.ndarray,
                    temperature_C: np.ndarray, time_s: float,
                    extra: dict[str, np.ndarray] | None = None) -> Path:
    """A state file (module doc): points_rz (n, 2) m, triangles (m, 3) 0-based node ids,
    temperature_C (n,) per node, time_s; `extra` further field data (1-D arrays)."""
    import meshio

    points = np.column_stack([points_rz, np.zeros(len(points_rz))])
    field_data = {"TIME": np.array([float(time_s)])}
    field_data.update({k: np.atleast_1d(np.asarray(v, float)) for k, v in (extra or {}).items()})
    mesh = meshio.Mesh(points, [("triangle", np.asarray(triangles, dtype=np.int64))],
                       point_data={"TEMP": np.asarray(temperature_C, float)},
                       field_data=field_data)
    return write_vtu(path, mesh, compress=True)


def read_state_vtu(path: str | Path) -> tuple[np.ndarray, np.ndarray, float]:
    """(points (n, 2) m, TEMP (n,) °C, TIME s) of a state or result file; InputError naming
    the file if it is not one."""
    from twin.errors import InputError

    mesh = read_vtu(path)
    temp = mesh.point_data.get("TEMP")
    if temp is None or np.ndim(temp) != 1:
        raise InputError("no nodal TEMP array (a state file or an apdl-like result_NNN.vtu "
                         "is needed)", file=str(path))
    time = np.ravel(mesh.field_data.get("TIME", []))
    if time.size != 1 or not np.isfinite(time[0]):
        raise InputError("no TIME field data (the time of the state, s)", file=str(path))
    return np.asarray(mesh.points[:, :2], float), np.asarray(temp, float), float(time[0])


def result_name(step: int) -> str:
    """The file of solved load step `step` (0-based) inside the output folder."""
    return f"result_{step + 1:03d}.vtu"


RESULT_FILE = re.compile(r"result_\d{3,}\.vtu")
"""The names `result_name` gives."""


def output_names(session: SessionState) -> list[str]:
    """The files `write_outputs` writes, by their names inside the output folder."""
    return ["params.json", *(result_name(i) for i in range(len(session.solution.results))),
            "log.txt", *sorted(session.listing.files)]


def write_outputs(session: SessionState, out_dir: str | Path) -> list[Path]:
    """params.json, result_NNN.vtu (one per solved load step), log.txt and the files the deck
    wrote (/OUT, *CFOPEN; names checked when the deck opened them) under `out_dir`, and
    remove the result files an earlier run left there beyond this run's load steps."""
    out = Path(out_dir)
    written = []
    params = out / "params.json"
    write_text(params, json.dumps(session.scalar_parameters(), indent=2, sort_keys=True) + "\n")
    written.append(params)
    for i in range(len(session.solution.results)):
        path = out / result_name(i)
        write_result_vtu(session, i, path)
        written.append(path)
    log = out / "log.txt"
    write_text(log, "\n".join(session.log) + "\n")
    written.append(log)
    for name, lines in sorted(session.listing.files.items()):
        path = out / name
        write_text(path, "".join(line + "\n" for line in lines))
        written.append(path)
    # result_*.vtu are this command's names (a deck may not write one): those an earlier
    # run into `out` left beyond this run's load steps would pass for this run's results
    for stale in sorted(set(out.glob("result_*.vtu")) - set(written)):
        if RESULT_FILE.fullmatch(stale.name) and stale.is_file():
            stale.unlink()
    return written
