"""/AUX12 radiation view factors of a 2-D model: V2DOPT, VFQUERY and *GET,,RAD,,VFAVG.

The radiating surfaces are the exterior element faces loaded with RDSF (SF/SFL/SFE,
emissivity, enclosure number).  View factors are computed when VFQUERY first needs them
(`apdl_like.radiation`: numerical integration with shading by every face of the enclosure),
planar or, after V2DOPT,1, axisymmetric (faces revolved about the Y axis).  VFOPT's file
options change nothing: the factors are always computed from the model.  STEF, SPCTEMP,
RADOPT and HEMIOPT only serve a radiosity solve, which apdl_like does not run (a thermal
SOLVE with RDSF faces is refused).  TOFFST sets the temperature offset that LINK31
radiation links use (`apdl_like.line_thermal`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import AUX12, MODEL, Call, CommandSpec, command, ignored, specs_of
from apdl_like.commands.selection import component, component_mask
from apdl_like.errors import ApdlError

if TYPE_CHECKING:
    from apdl_like.state import SessionState


@command("V2DOPT", AUX12, 4)
def v2dopt(s: SessionState, c: Call) -> None:
    """V2DOPT,GEOM,NDIV,HIDOPT,NZONE: GEOM 0 planar, 1 axisymmetric (the rest set MAPDL's
    own integration resolution; apdl_like uses its own)."""
    geom = c.int(1, 0, what="GEOM")
    if geom not in (0, 1):
        raise ApdlError(f"field 1 (GEOM) must be 0 (planar) or 1 (axisymmetric), got {geom}")
    s.radiation.axisymmetric = geom == 1
    s.radiation.factors = None


def _faces(s: SessionState) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                     np.ndarray]:
    """The RDSF faces: ends a, b (m, 2), unit normals out of their element (m, 2), owning
    element indices (m,) and enclosure numbers (m,)."""
    # the solvers of a deck's own mesh load with the first command that needs them
    from apdl_like.plane_solve import corners_and_midside, deck_faces

    db = s.db
    table = deck_faces(s)
    rad = np.nonzero(~np.isnan(db.faces.rdsf_emis))[0]
    if not rad.size:
        raise ApdlError("no face is a radiation surface (SF/SFL/SFE,,RDSF)")
    xy = db.nodes.xy
    a, b = xy[table.face_nodes[0, rad]], xy[table.face_nodes[1, rad]]
    owner = table.owner[rad]
    corners, _, _ = corners_and_midside(db)
    centroid = xy[corners[owner]].mean(axis=1)
    edge = b - a
    normal = np.column_stack([edge[:, 1], -edge[:, 0]]) / np.hypot(*edge.T)[:, None]
    outward = np.einsum("ij,ij->i", normal, 0.5 * (a + b) - centroid) > 0.0
    normal[~outward] *= -1.0
    return a, b, normal, owner, db.faces.rdsf_encl[rad]


def _factors(s: SessionState) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(F, face areas, owning element indices) of the RDSF faces, cached for the model."""
    from apdl_like.plane_solve import analysis_mode
    from apdl_like.radiation import view_factors

    axisymmetric = s.radiation.axisymmetric
    if axisymmetric is None:
        axisymmetric = analysis_mode(s.db) == "axisymmetric"
    a, b, normal, owner, enclosure = _faces(s)
    key = (s.db.mesh_key(), axisymmetric, a.tobytes(), enclosure.tobytes())
    cached = s.radiation.factors
    if cached is not None and cached[0] == key:
        return cached[1]
    F = np.zeros((a.shape[0], a.shape[0]))
    area = np.zeros(a.shape[0])
    for number in np.unique(enclosure):
        idx = np.nonzero(enclosure == number)[0]
        F_e, area[idx] = view_factors(a[idx], b[idx], normal[idx], axisymmetric)
        F[np.ix_(idx, idx)] = F_e
    s.radiation.factors = (key, (F, area, owner))
    return F, area, owner


def _element_set(s: SessionState, c: Call, i: int) -> np.ndarray:
    """Field i: an element component, or ALL / blank (the selected elements)."""
    name = c.label(i, "ALL")
    if name == "ALL":
        return s.db.elements.selected.copy()
    comp = component(s, name)
    if comp.entity != "ELEM":
        raise ApdlError(f"field {i}: component {name} holds nodes, not elements")
    return component_mask(s, comp)


@command("VFQUERY", AUX12, 2)
def vfquery(s: SessionState, c: Call) -> None:
    """VFQUERY,SRCELEM,TARGELEM: the area-weighted average view factor from the radiating
    faces of the source elements to those of the target elements (*GET,,RAD,,VFAVG)."""
    from apdl_like.radiation import average_view_factor

    source_elements, target_elements = _element_set(s, c, 1), _element_set(s, c, 2)
    F, area, owner = _factors(s)
    source, target = source_elements[owner], target_elements[owner]
    if not source.any():
        raise ApdlError("field 1: the source elements have no radiation surface (RDSF)")
    s.radiation.average = average_view_factor(F, area, source, target)
    s.say(f"VFQUERY: average view factor {s.radiation.average:.6f}")


@command("TOFFST", MODEL, 1)
def toffst(s: SessionState, c: Call) -> None:
    """TOFFST,VALUE: the absolute temperature of the model's zero (460 for °F, 273.15 for
    °C); radiation works with T + VALUE."""
    value = c.num(1, 0.0, what="VALUE")
    if value < 0.0:
        raise ApdlError(f"field 1 (VALUE) must not be negative, got {value!r}")
    s.db.settings.toffst = value


COMMANDS = (
    *specs_of(v2dopt, vfquery, toffst),
    *(CommandSpec(name, MODEL, 8, ignored)
      for name in ("STEF", "SPCTEMP", "RADOPT", "HEMIOPT", "VFOPT")),
)
