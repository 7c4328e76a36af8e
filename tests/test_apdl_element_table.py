"""ETABLE VOLU and HEAT, ESORT with *GET,,SORT, PRETAB, PRRSOL and PRESOL, and nodal HGEN
(BF,Node,HGEN), each checked against a volume, a heat balance or a closed form worked out
here by hand, never against numbers from the code.

The two-element model: PLANE55 quads 1 (1 ≤ x ≤ 2) and 2 (2 ≤ x ≤ 4), 0 ≤ y ≤ 0.5, and a
LINK32 bar 3 (area 0.01) from node 1 (x = 1) to node 3 (x = 4), held at 100 °C at x = 1
and 0 °C at x = 4.  Volumes: planar (unit thickness) 0.5 and 1.0; axisymmetric, the full
360°, π(2² − 1²)·0.5 = 1.5π and π(4² − 2²)·0.5 = 6π; the bar A·L = 0.03 either way.
"""

from __future__ import annotations

import math

import pytest

from apdl_like.errors import ApdlError
from apdl_like.session import Session
from tests.apdl_decks import SOLVE_THEN_POST


def two_quads(axisymmetric: bool, loads: str, post: str) -> Session:
    s = Session()
    s.run_text(f"""/PREP7
ET,1,PLANE55,,,{1 if axisymmetric else 0}
ET,2,LINK32
R,1,0.01
MP,KXX,1,10
N,1,1,0
N,2,2,0
N,3,4,0
N,4,1,0.5
N,5,2,0.5
N,6,4,0.5
TYPE,1
E,1,2,5,4
E,2,3,6,5
TYPE,2
REAL,1
E,1,3
D,1,TEMP,100
D,4,TEMP,100
D,3,TEMP,0
D,6,TEMP,0
{loads}
{SOLVE_THEN_POST}
{post}
""", "two.inp")
    return s


VOLUMES = """ETABLE,V,VOLU
*GET,V1,ELEM,1,ETAB,V
*GET,V2,ELEM,2,ETAB,V
*GET,V3,ELEM,3,ETAB,V
SSUM
*GET,VS,SSUM,,ITEM,V
"""


@pytest.mark.parametrize("axisymmetric, v1, v2", [(False, 0.5, 1.0),
                                                  (True, 1.5 * math.pi, 6 * math.pi)])
def test_etable_volu_is_the_element_volume_full_360_degrees_when_axisymmetric(
        axisymmetric, v1, v2):
    # MAPDL's VOLU: unit thickness for planar elements, the full 360° for axisymmetric ones;
    # a LINK32's A·L (its area is on the full circumference already).  Before: refused.
    p = two_quads(axisymmetric, "", VOLUMES).params
    assert p["V1"] == pytest.approx(v1, rel=1e-12)
    assert p["V2"] == pytest.approx(v2, rel=1e-12)
    assert p["V3"] == pytest.approx(0.01 * 3.0, rel=1e-12)
    assert p["VS"] == pytest.approx(v1 + v2 + 0.03, rel=1e-12)


def test_etable_volu_of_an_axisymmetric_rod_sums_to_pi_r2_l():
    # the user deck's heated rod (PLANE77, 10 × 2 elements): SSUM of VOLU is π R² L
    from tests.test_apdl_user_decks import USER_DECKS

    deck = (USER_DECKS / "rod_hgen.inp").read_text().split("*MSG")[0]
    s = Session()
    s.run_text(deck + "ETABLE,V,VOLU\nSSUM\n*GET,VS,SSUM,,ITEM,V\n", "rod.inp")
    assert s.params["VS"] == pytest.approx(math.pi * 0.025**2 * 0.01, rel=1e-12)


def test_etable_heat_is_the_generated_heat_of_an_element_and_fsum_balances_it():
    # HEAT (an element force item: MAPDL sums its nodal values) with FSUM's sign: an element
    # with heat generation q and no face load gives q·V (its conduction part sums to zero),
    # one without loads 0.  Over the whole model, SSUM of HEAT is FSUM of all nodes: the
    # heat generated, q·V1, leaving through the held nodes (PRRSOL's reactions: -q·V1)
    q = 1000.0
    for axisymmetric, v1 in ((False, 0.5), (True, 1.5 * math.pi)):
        s = two_quads(axisymmetric, f"BFE,1,HGEN,,{q}", VOLUMES + """ETABLE,Q,HEAT
*GET,Q1,ELEM,1,ETAB,Q
*GET,Q2,ELEM,2,ETAB,Q
*GET,Q3,ELEM,3,ETAB,Q
SSUM
*GET,QS,SSUM,,ITEM,Q
FSUM
*GET,QF,FSUM,,ITEM,HEAT
PRRSOL,HEAT
""")
        p = s.params
        assert p["Q1"] == pytest.approx(q * v1, rel=1e-10)
        assert abs(p["Q2"]) < 1e-9 * q * v1 and abs(p["Q3"]) < 1e-9 * q * v1
        assert p["QS"] == pytest.approx(q * v1, rel=1e-10)
        assert p["QF"] == pytest.approx(q * v1, rel=1e-10)
        total = [line for line in s.log if line.strip().startswith("TOTAL")][-1]
        assert float(total.split()[1]) == pytest.approx(-q * v1, rel=1e-6)


SORT_ITEMS = """*GET,MX,SORT,,MAX
*GET,IMX,SORT,,IMAX
*GET,MN,SORT,,MIN
*GET,IMN,SORT,,IMIN
"""


def test_esort_sorts_the_element_table_for_get_sort():
    # the linear field between the held faces (no heat generation): TG,X = -100/3 °C/m in
    # both quads, 0 for the bar (it has no gradient item).  ESORT reads the column it names;
    # *GET,,SORT gives the extremes of the last sort and their elements, the lower number
    # on a tie, as NSORT's does
    s = two_quads(False, "", VOLUMES + "ETABLE,G,TG,X\nESORT,ETAB,G\n" + SORT_ITEMS)
    p = s.params
    assert (p["MX"], p["IMX"], p["IMN"]) == (0.0, 3.0, 1.0)
    assert p["MN"] == pytest.approx(-100.0 / 3.0, rel=1e-10)
    s = two_quads(False, "", VOLUMES + "ETABLE,G,TG,X\nESORT,ETAB,G,0,1\n" + SORT_ITEMS)
    p = s.params  # |value|: the quads tie at 100/3, the bar has the smallest
    assert (p["IMX"], p["MN"], p["IMN"]) == (1.0, 0.0, 3.0)
    assert p["MX"] == pytest.approx(100.0 / 3.0, rel=1e-10)
    s = two_quads(False, "", VOLUMES + "ESORT,ETAB,V,1,0,2\n" + SORT_ITEMS)
    p = s.params  # ascending, the first NUMB = 2 kept: the bar (0.03) and quad 1 (0.5)
    assert (p["IMX"], p["IMN"]) == (1.0, 3.0)
    assert (p["MX"], p["MN"]) == pytest.approx((0.5, 0.03), rel=1e-12)
    with pytest.raises(ApdlError, match="no element table column 'NOPE'"):
        two_quads(False, "", "ESORT,ETAB,NOPE\n")


def test_pretab_lists_columns_in_esort_order_and_eusort_restores_it():
    # (MAPDL: "Changing the selected element set [ESEL] also restores the original element
    # order", as EUSORT does)
    s = two_quads(False, "", VOLUMES + "ETABLE,G,TG,X\nESORT,ETAB,V\nPRETAB,V,G\nEUSORT\n"
                  "PRETAB\nESORT,ETAB,V\nESEL,ALL\nPRETAB,V\n")
    rows = [line.split() for line in s.log if line[:8].strip().isdigit()]
    assert [r[0] for r in rows] == ["2", "1", "3", "1", "2", "3", "1", "2", "3"]
    assert [float(r[1]) for r in rows[:3]] == pytest.approx([1.0, 0.5, 0.03])
    assert float(rows[0][2]) == pytest.approx(-100.0 / 3.0)
    assert len(rows[3]) == 3  # blank: the stored columns, V and G


def test_presol_says_once_that_its_printout_is_not_produced():
    s = two_quads(False, "", "PRESOL,TG\nPRESOL,HEAT\n")
    told = [w for w in s.state.listing.warnings if "PRESOL" in w]
    assert len(told) == 1 and "not produced" in told[0] and "two.inp:" in told[0]
    with pytest.raises(ApdlError, match="PRESOL.*--strict"):
        s = Session(strict=True)
        s.run_text("/POST1\nPRESOL,TG\n", "strict.inp")


# ------------------------------------------------------------------ nodal HGEN
def strip(loads: str, post: str, element: str = "PLANE55", keyopt3: int = 0) -> Session:
    """A PLANE55 strip 0 ≤ x ≤ 1, 0 ≤ y ≤ 0.1 of four elements (nodes 1..5 at the bottom,
    6..10 above them), k = 2, held at 0 °C at both ends."""
    s = Session()
    s.run_text(f"""/PREP7
ET,1,{element},,,{keyopt3}
MP,KXX,1,2
*DO,I,1,5
N,I,(I-1)*0.25,0
N,I+5,(I-1)*0.25,0.1
*ENDDO
*DO,I,1,4
E,I,I+1,I+6,I+5
*ENDDO
NSEL,S,LOC,X,0
NSEL,A,LOC,X,1
D,ALL,TEMP,0
NSEL,ALL
{loads}
{SOLVE_THEN_POST}
FSUM
*GET,QF,FSUM,,ITEM,HEAT
*GET,T2,NODE,2,TEMP
*GET,T3,NODE,3,TEMP
*GET,T4,NODE,4,TEMP
{post}
""", "strip.inp")
    return s


def test_nodal_hgen_varying_linearly_gives_the_exact_slab_temperatures():
    # BF,n,HGEN,q0·x at every node: MAPDL multiplies a nodal rate "by the weighted nodal
    # volume of each element adjacent to that node", ∫ N_n dV.  For q = q0·x/L in a slab
    # held at 0 at x = 0 and L, T = q0 (L² x − x³) / (6 k L); on this uniform mesh the
    # nodal loads q_n·h·H equal the consistent ∫ q N dV, so linear elements are exact at
    # the nodes, and all the heat, q0 L H / 2, leaves through the held ends.  Before: BF
    # with HGEN at nodes was refused.
    q0, k, L, H = 1000.0, 2.0, 1.0, 0.1
    p = strip("*DO,I,1,10\nBF,I,HGEN,1000*NX(I)\n*ENDDO", "").params
    for name, x in (("T2", 0.25), ("T3", 0.5), ("T4", 0.75)):
        assert p[name] == pytest.approx(q0 * (L * L * x - x**3) / (6 * k * L), rel=1e-12)
    assert p["QF"] == pytest.approx(q0 * L * H / 2, rel=1e-12)


def test_uniform_nodal_hgen_in_an_axisymmetric_rod_generates_q_times_the_volume():
    # BF,ALL,HGEN,q on a solid rod (axisymmetric strip 0 ≤ r ≤ 1, height 0.1, held at 0 at
    # r = 1; the r = 0 "held" nodes lie on the axis and take no heat): the weights ∫ N_n dV
    # add up to the rod's volume π R² H, so the heat leaving is q π R² H exactly, and the
    # centre temperature approaches q R² / (4k) = 125 °C (four linear rings: 129.4, 3.5 %
    # high; the same as BFE,ALL,HGEN,q gives, a uniform nodal rate loading as BFE does)
    q, k, R, H = 1000.0, 2.0, 1.0, 0.1
    s = strip("BF,ALL,HGEN,1000\nDDELE,1,TEMP\nDDELE,6,TEMP", "*GET,T1,NODE,1,TEMP",
              keyopt3=1)
    p = s.params
    assert p["QF"] == pytest.approx(q * math.pi * R**2 * H, rel=1e-12)
    assert p["T1"] == pytest.approx(q * R**2 / (4 * k), rel=0.04)
    same = strip("BFE,ALL,HGEN,,1000\nDDELE,1,TEMP\nDDELE,6,TEMP", "*GET,T1,NODE,1,TEMP",
                 keyopt3=1).params
    assert (same["T1"], same["QF"]) == pytest.approx((p["T1"], p["QF"]), rel=1e-12)


@pytest.mark.parametrize("loads, message", [
    ("BF,ALL,HGEN,5\nBFE,1,HGEN,,5", "element 1 has both BFE,,HGEN and nodal HGEN"),
    ("*DIM,Q,TABLE,2,1,1,TIME\nBF,ALL,HGEN,%Q%", "nodal HGEN from a table"),
])
def test_nodal_hgen_refusals(loads, message):
    with pytest.raises(ApdlError, match=message):
        strip(loads, "")


def test_nodal_hgen_on_quadratic_elements_is_refused():
    s = Session()
    with pytest.raises(ApdlError, match="quadratic elements"):
        s.run_text("""/PREP7
ET,1,PLANE77
MP,KXX,1,2
N,1,0,0
N,2,2,0
N,3,2,1
N,4,0,1
N,5,1,0
N,6,2,0.5
N,7,1,1
N,8,0,0.5
E,1,2,3,4,5,6,7,8
D,1,TEMP,0
BF,ALL,HGEN,10
FINISH
/SOLU
SOLVE
""", "q8.inp")


@pytest.mark.parametrize("kbc, expected", [(1, 4.0 * 10.0), (0, 4.0 * sum(range(1, 11)) / 10)])
def test_nodal_hgen_heats_an_insulated_block_at_q_over_rho_c(kbc, expected):
    # an insulated block with a uniform nodal rate q: every node's load q·∫N_n dV meets its
    # lumped capacity ρc·∫N_n dV, so T rises at q/ρc everywhere (4 °C/s here): 40 °C in
    # 10 s stepped (KBC,1).  Ramped from zero (KBC,0) the rate is q·t/10; backward Euler
    # (θ = 1) in 1 s substeps takes each substep's end value: 4·(1 + 2 + ... + 10)/10 = 22
    # (the exact ramp would give 20)
    q, rho_c = 4.0e6, 1.0e6
    s = Session()
    s.run_text(f"""/PREP7
ET,1,PLANE55
MP,KXX,1,5
MP,DENS,1,1000
MP,C,1,1000
RECTNG,0,0.02,0,0.01
ESIZE,0.005
AMESH,ALL
TUNIF,0
FINISH
/SOLU
ANTYPE,TRANS
KBC,{kbc}
TIME,10
DELTIM,1
BF,ALL,HGEN,{q}
SOLVE
FINISH
/POST1
*GET,TA,NODE,1,TEMP
NSORT,TEMP
*GET,TMAX,SORT,,MAX
*GET,TMIN,SORT,,MIN
""", "block.inp")
    p = s.params
    assert q / rho_c == 4.0
    assert (p["TMIN"], p["TMAX"]) == pytest.approx((expected, expected), rel=1e-9)
