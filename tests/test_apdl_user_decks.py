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
