"""Thermal decks as a MAPDL user writes them (AATT, *VGET, *VOPER, POST26 VGET, *GET into an
array element, *AFUN, SINH/COSH/TANH), checked against closed forms evaluated here, never
against numbers from the code.
"""

from __future__ import annotations

import numpy as np
import pytest

from apdl_like.errors import ApdlError
from apdl_like.session import Session


def run(text: str) -> Session:
    s = Session()
    s.run_text(text, "user.inp")
    return s


# ------------------------------------------------------------------- *VOPER
def test_voper_operates_down_the_columns():
    s = run("*DIM,A,ARRAY,4\n*DIM,B,ARRAY,4\n*DIM,R,ARRAY,4,2\n"
            "*VFILL,A(1),DATA,1,2,3,4\n*VFILL,B(1),DATA,8,4,2,1\n"
            "*VOPER,R(1,1),A(1),DIV,B(1)\n*VOPER,R(2,2),A(2),MULT,10\n"
            "*DIM,M,ARRAY,4\n*VOPER,M(1),A(1),MAX,2.5\n*DIM,G,ARRAY,4\n*VOPER,G(1),A(1),GT,B(1)\n"
            "*DIM,S,ARRAY,4\n*VOPER,S(1),A(1),SUB,B(1)\n")
    p = s.params
    np.testing.assert_array_equal(p["R"][:, 0, 0], [1 / 8, 2 / 4, 3 / 2, 4 / 1])
    # from row 2 of R and of A: 20, 30, 40 (the rows before are left alone)
    np.testing.assert_array_equal(p["R"][:, 1, 0], [0.0, 20.0, 30.0, 40.0])
    np.testing.assert_array_equal(p["M"].ravel(), [2.5, 2.5, 3.0, 4.0])
    np.testing.assert_array_equal(p["G"].ravel(), [0.0, 0.0, 1.0, 1.0])
    np.testing.assert_array_equal(p["S"].ravel(), [-7.0, -2.0, 1.0, 3.0])
    for deck, message in [
        ("*DIM,A,ARRAY,2\n*DIM,B,ARRAY,2\n*VOPER,A(1),A(1),DIV,B(1)\n", "division by zero"),
        ("*DIM,A,ARRAY,2\n*VOPER,A(1),A(1),DER1,A(1)\n", "supports ADD, SUB"),
        ("*VOPER,Q(1),1,ADD,2\n", "Q is not a numeric array"),
    ]:
        with pytest.raises(ApdlError, match=message):
            run(deck)


# ------------------------------------------------------------ AATT, two materials
def test_aatt_gives_each_area_its_material_and_amesh_all_meshes_the_selected():
    # a two-layer plane wall, fixed temperatures on its faces: the interface temperature is
    # T1 − (T1 − T2) (L1/k1) / (L1/k1 + L2/k2), and the heat flux (T1 − T2)/(L1/k1 + L2/k2)
    L1, L2, k1, k2, T1, T2, W = 0.02, 0.05, 40.0, 0.8, 300.0, 20.0, 0.01
    deck = f"""/PREP7
ET,1,PLANE55
MP,KXX,1,{k1}
MP,KXX,2,{k2}
RECTNG,0,{L1},0,{W}
RECTNG,{L1},{L1 + L2},0,{W}
ASEL,S,LOC,X,{L1 / 2}
AATT,1,,1
ASEL,S,LOC,X,{L1 + L2 / 2}
AATT,2,,1
ASEL,S,AREA,,1
ESIZE,{W / 2}
AMESH,ALL
*GET,NE1,ELEM,0,COUNT
ASEL,ALL
AMESH,ALL
*GET,NE2,ELEM,0,COUNT
NSEL,S,LOC,X,0
D,ALL,TEMP,{T1}
NSEL,S,LOC,X,{L1 + L2}
D,ALL,TEMP,{T2}
ALLSEL
FINISH
/SOLU
SOLVE
FINISH
/POST1
NSEL,S,LOC,X,{L1}
*GET,NI,NODE,0,NUM,MIN
TI = TEMP(NI)
NSEL,S,LOC,X,0
FSUM
*GET,QB,FSUM,,ITEM,HEAT
ALLSEL
ESEL,S,MAT,,2
*GET,NM2,ELEM,0,COUNT
"""
    s = run(deck)
    p = s.params
    r1, r2 = L1 / k1, L2 / k2
    assert p["TI"] == pytest.approx(T1 - (T1 - T2) * r1 / (r1 + r2), rel=1e-10)
    assert abs(p["QB"]) == pytest.approx((T1 - T2) / (r1 + r2) * W, rel=1e-10)
    # AMESH,ALL with area 1 selected meshed area 1 only; then area 2, all MAT 2
    assert 0 < p["NE1"] < p["NE2"] and p["NM2"] == p["NE2"] - p["NE1"]
    with pytest.raises(ApdlError, match="ESYS, SECN"):
        run("/PREP7\nRECTNG,0,1,0,1\nAATT,1,1,1,11\n")


# ------------------------------------------- lumped cooling, POST26 VGET of a history
def test_post26_vget_moves_a_lumped_cooling_history_into_arrays():
    # a copper square (Bi = h a/(4k) ≈ 1e-4) cooling by a film on its four sides, DELTIM
    # fixed, the film stepped (KBC,1): backward Euler on the lumped body gives T_n = T_a + (T_0 − T_a)(1 + Δt/τ)^−n,
    # τ = ρ c a / (4 h)
    a, k, rho, c, h, T0, Ta = 0.01, 400.0, 8900.0, 385.0, 15.0, 200.0, 20.0
    tau = rho * c * a / (4 * h)
    deck = f"""/PREP7
ET,1,PLANE55
MP,KXX,1,{k}
MP,DENS,1,{rho}
MP,C,1,{c}
BLC4,0,0,{a},{a}
ESIZE,{a / 2}
AMESH,ALL
SFL,ALL,CONV,{h},,{Ta}
TUNIF,{T0}
FINISH
/SOLU
ANTYPE,TRANS
KBC,1
TIME,{tau / 2}
DELTIM,{tau / 20}
OUTRES,ALL,ALL
SOLVE
FINISH
/POST26
NSOL,2,NODE({a / 2},{a / 2},0),TEMP,,TC
*DIM,TT,ARRAY,12
*DIM,TC,ARRAY,12
VGET,TT(1),1
VGET,TC(2),2,{tau / 10}
"""
    p = {k: v.ravel() for k, v in run(deck).params.items() if isinstance(v, np.ndarray)}
    n = np.arange(1, 11)
    np.testing.assert_allclose(p["TT"][:10], n * tau / 20, rtol=1e-12)
    assert list(p["TT"][10:]) == [0.0, 0.0]  # the history has 10 substeps
    # from t = τ/10 (substep 2) on, written from row 2
    be = Ta + (T0 - Ta) * (1 + 1 / 20) ** -n[1:]
    np.testing.assert_allclose(p["TC"][1:10], be, rtol=2e-4)
    assert p["TC"][0] == 0.0 and list(p["TC"][10:]) == [0.0, 0.0]
