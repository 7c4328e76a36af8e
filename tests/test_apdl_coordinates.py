"""Coordinate systems: CSYS 0/1 and LOCAL/CLOCAL systems (origin, rotation θxy) as MAPDL
documents them -- N, NGEN, FILL, K, L, NSEL LOC, *GET LOC, NX/NY and NODE() read and write
coordinates in the active system, and LOCAL makes its system active.

Expected values are hand trigonometry and closed-form conduction, never the code's output.
"""

from __future__ import annotations

import math

import pytest

from apdl_like.errors import ApdlError
from apdl_like.session import Session
from tests.apdl_decks import SOLVE_THEN_POST


def run(text: str) -> Session:
    s = Session()
    s.run_text(text, "coords.inp")
    return s


X0, Y0, ROT = 5.0, -3.0, 30.0  # origin and rotation of the local cylindrical system


def test_local_cylindrical_ring_by_n_fill_ngen_conducts_like_a_ring():
    """A planar ring sector 1 ≤ r ≤ 2, 0..90° built with N/FILL/NGEN in a cylindrical
    LOCAL about (5, -3) turned 30°: nodes land at origin + r(cos(θ+30°), sin(θ+30°)),
    NSEL LOC picks the radii, and the inner-hot/outer-cold conduction gives
    T(r) = T1 ln(b/r)/ln(b/a) (the plane ring's closed form)."""
    s = run(f"""/PREP7
ET,1,PLANE55
MP,KXX,1,10
LOCAL,11,1,{X0},{Y0},,{ROT}
N,1,1,0
N,11,2,0
FILL
NGEN,10,100,1,11,1,,10
E,1,2,102,101
EGEN,10,1,1
EGEN,9,100,1,10
NSEL,S,LOC,X,1
*GET,N_IN,NODE,0,COUNT
D,ALL,TEMP,100
NSEL,S,LOC,X,2
D,ALL,TEMP,0
NSEL,ALL
{SOLVE_THEN_POST}
*GET,T_MID,NODE,506,TEMP
*GET,R_MID,NODE,506,LOC,X
*GET,A_MID,NODE,506,LOC,Y
NX_LOCAL=NX(506)
CSYS,0
*GET,X_MID,NODE,506,LOC,X
*GET,Y_MID,NODE,506,LOC,Y
NX_GLOBAL=NX(506)
NY_GLOBAL=NY(506)
CSYS,11
NEAR=NODE(1.52,49,0)
""")
    p = s.params
    t = math.radians(ROT + 50.0)  # node 506: r = 1.5, θ = 50° in the local system
    assert p["N_IN"] == 10
    assert p["R_MID"] == pytest.approx(1.5, abs=1e-12)
    assert p["A_MID"] == pytest.approx(50.0, abs=1e-9)
    assert p["NX_LOCAL"] == pytest.approx(1.5, abs=1e-12)
    assert p["X_MID"] == pytest.approx(X0 + 1.5 * math.cos(t), abs=1e-12)
    assert p["Y_MID"] == pytest.approx(Y0 + 1.5 * math.sin(t), abs=1e-12)
    assert (p["NX_GLOBAL"], p["NY_GLOBAL"]) == (p["X_MID"], p["Y_MID"])
    assert p["NEAR"] == 506
    assert p["T_MID"] == pytest.approx(100.0 * math.log(2 / 1.5) / math.log(2), rel=5e-4)


def test_local_cylindrical_area_is_mapped_on_its_arcs_and_carries_the_ring_heat():
    """K/L/AL in a cylindrical LOCAL about (-2, 7) turned -40°: the lines at one radius are
    arcs about that origin, AMESH maps the 4-sided area (LESIZE 8 on every line: 9 nodes on
    each arc, all at the arc's radius), and the heat through the 60° sector of a plane ring
    is Q = k θ ΔT / ln(b/a) per unit thickness (FSUM at the held inner nodes: the heat the
    elements take in there, negative in MAPDL's sign)."""
    k, dt = 10.0, 100.0
    s = run(f"""/PREP7
ET,1,PLANE55
MP,KXX,1,{k}
LOCAL,12,CYLIN,-2,7,,-40
K,1,1,0
K,2,2,0
K,3,2,60
K,4,1,60
L,1,2
L,2,3
L,3,4
L,4,1
AL,1,2,3,4
LESIZE,ALL,,,8
AMESH,1
*GET,N_ELEM,ELEM,0,COUNT
NSEL,S,LOC,X,1
*GET,N_IN,NODE,0,COUNT
D,ALL,TEMP,{dt}
NSEL,S,LOC,X,2
*GET,N_OUT,NODE,0,COUNT
D,ALL,TEMP,0
NSEL,ALL
{SOLVE_THEN_POST}
NSEL,S,LOC,X,1
FSUM
*GET,Q,FSUM,0,ITEM,HEAT
""")
    p = s.params
    assert (p["N_ELEM"], p["N_IN"], p["N_OUT"]) == (64, 9, 9)
    q = k * math.radians(60) * dt / math.log(2)
    # 7.5° chords shave the sector's area by (1 - sin x / x) ≈ 0.1 %: the heat within 0.5 %
    assert p["Q"] == pytest.approx(-q, rel=5e-3)


def test_local_cartesian_rotated_and_clocal_inside_it():
    """A Cartesian LOCAL at (2, 3) turned 90°: local (1, 0) is global (2, 4), and NGEN's
    DX steps along the local X axis (global +Y).  CLOCAL places a system in the active one
    (origin at local (0, 1) = global (1, 3), turned a further 90°) and becomes active;
    CSDELE of the active system falls back to CSYS 0."""
    s = run("""/PREP7
LOCAL,11,0,2,3,,90
N,1,1,0
NGEN,2,1,1,1,1,0.5
CSYS,0
*GET,X1,NODE,1,LOC,X
*GET,Y1,NODE,1,LOC,Y
*GET,X2,NODE,2,LOC,X
*GET,Y2,NODE,2,LOC,Y
CSYS,11
CLOCAL,12,0,0,1,,90
N,3,1,0
CSYS,0
*GET,X3,NODE,3,LOC,X
*GET,Y3,NODE,3,LOC,Y
CSYS,12
CSDELE,12
N,4,1,0
*GET,X4,NODE,4,LOC,X
""")
    p = s.params
    assert (p["X1"], p["Y1"]) == pytest.approx((2.0, 4.0), abs=1e-12)
    assert (p["X2"], p["Y2"]) == pytest.approx((2.0, 4.5), abs=1e-12)
    assert (p["X3"], p["Y3"]) == pytest.approx((0.0, 3.0), abs=1e-12)
    assert p["X4"] == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize(("deck", "message"), [
    ("/PREP7\nCSYS,12", r"coords.inp:2: CSYS: coordinate system 12 is not defined"),
    ("/PREP7\nCSYS,2", r"field 1 \(KCN\): coordinate system 2 is not supported"),
    ("/PREP7\nLOCAL,5,1", r"field 1 \(KCN\): a local system's number must be ≥ 11"),
    ("/PREP7\nLOCAL,11,2", r"field 2 \(KCS\): only 0 \(Cartesian\) and 1"),
    ("/PREP7\nLOCAL,11,1,0,0,0,0,45", r"field 7 \(THYZ\) must be 0"),
    ("/PREP7\nLOCAL,11,1,0,0,1", r"field 5 \(ZC\) must be 0"),
])
def test_coordinate_system_errors_name_line_and_field(deck, message):
    with pytest.raises(ApdlError, match=message):
        run(deck)
