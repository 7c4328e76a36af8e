"""Radiation view factors (/AUX12, VFQUERY) against closed forms and published values."""

from __future__ import annotations

import math

import numpy as np
import pytest

from apdl_like.errors import ApdlError
from apdl_like.radiation import average_view_factor, view_factors
from apdl_like.session import Session


def test_planar_parallel_plates_match_the_crossed_strings():
    """Two directly opposed strips of width w, gap h: F = √(1 + H²) − H, H = h/w."""
    w, h = 1.0, 0.5
    a = np.array([[0.0, 0.0], [w, h]])
    b = np.array([[w, 0.0], [0.0, h]])
    normal = np.array([[0.0, 1.0], [0.0, -1.0]])
    F, area = view_factors(a, b, normal, axisymmetric=False)
    H = h / w
    assert F[0, 1] == pytest.approx(math.sqrt(1 + H * H) - H, rel=2e-3)
    assert F[0, 0] == 0.0 and area == pytest.approx([w, w])


def test_planar_concentric_tubes_shade_the_outer_tube_from_itself():
    """Long concentric tubes r1 < r2 (planar section): F21 = r1/r2, F22 = 1 − r1/r2; the
    outer tube sees itself only past the inner one."""
    n, r1, r2 = 32, 1.0, 2.0
    t = np.linspace(0.0, 2 * np.pi, n + 1)
    p, q = np.column_stack([np.cos(t[:-1]), np.sin(t[:-1])]), \
        np.column_stack([np.cos(t[1:]), np.sin(t[1:])])
    mid = (p + q) / np.linalg.norm(p + q, axis=1)[:, None]
    a = np.vstack([r1 * p, r2 * q])
    b = np.vstack([r1 * q, r2 * p])
    normal = np.vstack([mid, -mid])
    F, area = view_factors(a, b, normal, axisymmetric=False)
    inner = np.arange(2 * n) < n
    assert average_view_factor(F, area, ~inner, inner) == pytest.approx(r1 / r2, rel=5e-3)
    assert average_view_factor(F, area, ~inner, ~inner) == pytest.approx(1 - r1 / r2, rel=3e-2)
    assert F.sum(axis=1) == pytest.approx(np.ones(2 * n), rel=3e-2)  # a closed enclosure
    assert average_view_factor(F, area, inner, inner) == 0.0


def test_axisymmetric_coaxial_disks():
    """Parallel coaxial disks of radius r a distance h apart (revolved faces):
    F = (X − √(X² − 4)) / 2, X = 2 + (h/r)² (Howell's catalogue, equal disks)."""
    r, h, n = 1.0, 1.0, 8
    edges = np.linspace(0.0, r, n + 1)
    a = np.vstack([np.column_stack([edges[:-1], np.zeros(n)]),
                   np.column_stack([edges[1:], np.full(n, h)])])
    b = np.vstack([np.column_stack([edges[1:], np.zeros(n)]),
                   np.column_stack([edges[:-1], np.full(n, h)])])
    normal = np.vstack([np.tile([0.0, 1.0], (n, 1)), np.tile([0.0, -1.0], (n, 1))])
    F, area = view_factors(a, b, normal, axisymmetric=True)
    lower = np.arange(2 * n) < n
    X = 2.0 + (h / r) ** 2
    assert area[lower].sum() == pytest.approx(math.pi * r * r, rel=1e-12)
    assert average_view_factor(F, area, lower, ~lower) == pytest.approx(
        (X - math.sqrt(X * X - 4.0)) / 2.0, rel=1e-2)


COAXIAL_CYLINDERS = """
/PREP7
BLC4,0,0,1,10
BLC4,3,0,1,10
ET,1,PLANE77,,,1
LESIZE,ALL,,,10
AMESH,ALL
SFL,2,RDSF,1,,1
SFL,8,RDSF,1,,1
FINISH
/AUX12
V2DOPT,1,20
ASEL,S,,,1
ESLA,S
CM,INSIDE,ELEM
ASEL,S,,,2
ESLA,S
CM,OUTSIDE,ELEM
ALLSEL
VFQUERY,INSIDE,INSIDE
*GET,F11,RAD,,VFAVG
VFQUERY,OUTSIDE,INSIDE
*GET,F21,RAD,,VFAVG
VFQUERY,OUTSIDE,OUTSIDE
*GET,F22,RAD,,VFAVG
"""


def test_vfquery_finite_coaxial_cylinders_match_modest():
    """Coaxial cylinders r1 = 1, r2 = 3, length 10 built as MAPDL's VM227 does (BLC4 lines
    2 and 8 face each other, ASEL/ESLA components): Modest, Radiative Heat Transfer,
    F(2-1) = 0.288, F(2-2) = 0.503, and the convex inner cylinder sees nothing of itself."""
    s = Session()
    s.run_text(COAXIAL_CYLINDERS, "cylinders.inp")
    p = s.params
    assert p["F11"] == 0.0
    assert p["F21"] == pytest.approx(0.288, rel=5e-3)
    assert p["F22"] == pytest.approx(0.503, rel=2e-2)


def test_a_thermal_solve_with_radiation_surfaces_is_refused():
    s = Session()
    with pytest.raises(ApdlError, match="RDSF surfaces is not solved"):
        s.run_text(COAXIAL_CYLINDERS.split("FINISH")[0] + """
MP,KXX,1,10
D,ALL,TEMP,20
FINISH
/SOLU
SOLVE
""", "radiating.inp")


def test_esla_selects_the_elements_of_the_selected_area_free_or_mapped():
    """ASEL + ESLA pick exactly the elements lying in the chosen area: two touching
    rectangles meshed together with triangles (free), then a third one mapped."""
    s = Session()
    s.run_text("""
/PREP7
ET,1,PLANE55
BLC4,0,0,1,1
BLC4,1,0,2,1
MSHAPE,1
ESIZE,0.25
AMESH,1,2
MSHAPE,0
BLC4,0,2,1,1
AMESH,3
ASEL,S,AREA,,2
ESLA,S
*GET,N2,ELEM,,NUM,COUNT
ASEL,S,AREA,,3
ESLA,S
*GET,N3,ELEM,,NUM,COUNT
ASEL,ALL
ESLA,S
*GET,NALL,ELEM,,NUM,COUNT
""", "areas.inp")
    db = s.db
    el = db.elements
    xy = db.nodes.xy[db.nodes.index(el.nodes[:, :3].ravel()).reshape(-1, 3)]
    centroid = xy.mean(axis=1)
    in_2 = (centroid[:, 0] > 1.0) & (centroid[:, 1] < 1.0)
    in_3 = centroid[:, 1] > 2.0
    assert s.params["N2"] == in_2.sum() > 0
    assert s.params["N3"] == in_3.sum() == 16  # 4 × 4 mapped quads
    assert s.params["NALL"] == len(el.ids)
