"""Thermal decks as a MAPDL user writes them (AATT, *VGET, *VOPER, POST26 VGET, *GET into an
array element, *AFUN, SINH/COSH/TANH), checked against closed forms evaluated here, never
against numbers from the code.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from apdl_like.errors import ApdlError
from apdl_like.session import Session


def run(text: str) -> Session:
    s = Session()
    s.run_text(text, "user.inp")
    return s


# ------------------------------------------------------------ parameter functions
def test_hyperbolic_functions_and_afun_degrees():
    e = math.e
    s = run("A = SINH(1)\nB = COSH(1)\nC = TANH(1)\n*AFUN,DEG\nD = SIN(30)\nE = COS(60)\n"
            "F = TAN(45)\nG = ATAN2(1,1)\nH = ACOS(-1)\nI = ASIN(0.5)\nJ = ATAN(1)\n"
            "*AFUN,RAD\nK = SIN(30)\nL = ACOS(-1)\n")
    p = s.params
    assert p["A"] == pytest.approx((e - 1 / e) / 2, rel=1e-15)
    assert p["B"] == pytest.approx((e + 1 / e) / 2, rel=1e-15)
    assert p["C"] == pytest.approx((e * e - 1) / (e * e + 1), rel=1e-15)
    # degrees: the textbook angles
    for name, value in {"D": 0.5, "E": 0.5, "F": 1.0, "G": 45.0, "H": 180.0, "I": 30.0,
                        "J": 45.0}.items():
        assert p[name] == pytest.approx(value, rel=1e-14), name
    # back to radians: sin(30 rad) = -0.98803..., acos(-1) = π
    assert p["K"] == pytest.approx(-0.9880316240928618, rel=1e-14)
    assert p["L"] == pytest.approx(math.pi, rel=1e-15)
    with pytest.raises(ApdlError, match="RAD, DEG or STAT"):
        run("*AFUN,GRAD\n")


def test_hyperbolic_overflow_is_a_located_error():
    with pytest.raises(ApdlError, match="user.inp:1: .*COSH overflows"):
        run("A = COSH(1000)\n")


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
    # MAPDL: the rows run to the end of the result's column; an input column that ends
    # before is read as zeros (A(3), A(4), then 0, 0)
    s = run("*DIM,A,ARRAY,4\n*VFILL,A(1),DATA,1,2,3,4\n*DIM,R,ARRAY,4\n"
            "*VOPER,R(1),A(3),ADD,0.5\n")
    np.testing.assert_array_equal(s.params["R"].ravel(), [3.5, 4.5, 0.5, 0.5])
    for deck, message in [
        ("*DIM,A,ARRAY,2\n*DIM,B,ARRAY,2\n*VOPER,A(1),A(1),DIV,B(1)\n", "division by zero"),
        ("*DIM,A,ARRAY,2\n*VOPER,A(1),A(1),DER1,A(1)\n", "supports ADD, SUB"),
        ("*VOPER,Q(1),1,ADD,2\n", "Q is not a numeric array"),
    ]:
        with pytest.raises(ApdlError, match=message):
            run(deck)


def test_vscfun_reduces_a_column_to_a_scalar():
    # x = 3, 1, 4, 1, 5 (from row 2 of a 6-row column whose row 1 is 9)
    s = run("*DIM,X,ARRAY,6\n*VFILL,X(1),DATA,9,3,1,4,1,5\n"
            + "".join(f"*VSCFUN,V{f},{f},X(2)\n" for f in
                      ("MAX", "MIN", "SUM", "MEAN", "MEDI", "VARI", "STDV", "RMS", "NUM"))
            + "*DIM,Y,ARRAY,5\n*VFILL,Y(1),DATA,0,2,7,7,0\n"
            + "".join(f"*VSCFUN,Y{f},{f},Y(1)\n" for f in ("LMAX", "LMIN", "FIRST", "LAST")))
    p = s.params
    mean = 14 / 5
    vari = ((3 - mean) ** 2 + 2 * (1 - mean) ** 2 + (4 - mean) ** 2 + (5 - mean) ** 2) / 5
    assert (p["VMAX"], p["VMIN"], p["VSUM"], p["VMEDI"], p["VNUM"]) == (5.0, 1.0, 14.0, 3.0,
                                                                       5.0)
    assert p["VMEAN"] == pytest.approx(mean, rel=1e-15)
    assert p["VVARI"] == pytest.approx(vari, rel=1e-14)  # 2.16, over NUM as MAPDL documents
    assert p["VSTDV"] == pytest.approx(math.sqrt(vari), rel=1e-14)
    assert p["VRMS"] == pytest.approx(math.sqrt((9 + 1 + 16 + 1 + 25) / 5), rel=1e-15)
    # row numbers: the first maximum (row 3), the first minimum (row 1), nonzero 2..4
    assert (p["YLMAX"], p["YLMIN"], p["YFIRST"], p["YLAST"]) == (3.0, 1.0, 2.0, 4.0)
    with pytest.raises(ApdlError, match="from a row other than 1"):
        run("*DIM,X,ARRAY,3\n*VSCFUN,L,LMAX,X(2)\n")
    with pytest.raises(ApdlError, match="supports MAX"):
        run("*DIM,X,ARRAY,3\n*VSCFUN,L,KURT,X(1)\n")


# ------------------------------------------------- a rod heated inside (axisymmetric)
ROD = """/PREP7
R_O = 0.025
LEN = 0.01
K_R = 15.0
QGEN = 2.0E6
H_F = 200.0
T_F = 30.0
ET,1,PLANE77,,,1
MP,KXX,1,K_R
RECTNG,0,R_O,0,LEN
LESIZE,1,,,6
LESIZE,3,,,6
LESIZE,2,,,1
LESIZE,4,,,1
AMESH,ALL
SFL,2,CONV,H_F,,T_F
BFE,ALL,HGEN,,QGEN
FINISH
/SOLU
SOLVE
FINISH
/POST1
*GET,NCNT,NODE,0,COUNT
*GET,NMAX,NODE,0,NUM,MAX
*DIM,TN,ARRAY,NMAX+2
*DIM,XN,ARRAY,NMAX+2
*DIM,SEL,ARRAY,NMAX+2
*VGET,TN(1),NODE,1,TEMP
*VGET,XN(1),NODE,1,LOC,X
NSEL,S,LOC,X,0
*VGET,SEL(1),NODE,1,NSEL
ALLSEL
*DIM,TG,ARRAY,3
*DO,I,1,3
*GET,TG(I),NODE,I,TEMP
*ENDDO
"""


def test_vget_reads_every_node_of_a_rod_with_heat_generation():
    # T(r) = T_F + q R/(2h) + q (R² − r²)/(4k): quadratic in r, which PLANE77 holds exactly
    s = run(ROD)
    p = {k: v.ravel() if isinstance(v, np.ndarray) else v for k, v in s.params.items()}
    R, q, k, h, Tf = 0.025, 2.0e6, 15.0, 200.0, 30.0
    n = int(p["NMAX"])
    x, T = p["XN"][:n], p["TN"][:n]
    assert p["NCNT"] == n  # nodes 1..n, no gaps
    exact = Tf + q * R / (2 * h) + q * (R**2 - x**2) / (4 * k)
    np.testing.assert_allclose(T, exact, rtol=0, atol=1e-9)
    assert T.max() == pytest.approx(Tf + q * R / (2 * h) + q * R**2 / (4 * k), abs=1e-9)
    # past the last node: 0, as MAPDL gives for node numbers that do not exist
    np.testing.assert_array_equal(p["TN"][n:], [0.0, 0.0])
    # NSEL: 1 selected (the axis), -1 the rest
    sel = p["SEL"][:n]
    np.testing.assert_array_equal(sel, np.where(np.isclose(x, 0.0), 1.0, -1.0))
    # *GET into an array element, in a *DO loop
    np.testing.assert_array_equal(p["TG"], T[:3])


@pytest.mark.parametrize("deck, message", [
    ("*VGET,TQ(1),NODE,1,TEMP\n", "TQ is not a numeric array"),
    ("*DIM,TQ,ARRAY,2\n*VGET,TQ(1),KP,1,LOC,X\n", "supports NODE"),
    ("*DIM,TQ,ARRAY,2\n*VGET,TQ(1),NODE,1,TEMP,,,,1\n", "KLOOP"),
    ("*GET,1X,NODE,0,COUNT\n", "field 1"),
    ("*GET,TQ(1),NODE,0,COUNT\n", "TQ is not an array"),
])
def test_vget_and_get_refuse_what_they_cannot_do(deck, message):
    with pytest.raises(ApdlError, match=message):
        run("/PREP7\nN,1,0,0\n" + deck)


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
    run("/PREP7\nRECTNG,0,1,0,1\nAATT,1,1,1,0,0\n")  # the defaults, written out


# ------------------------------------------- lumped cooling, POST26 VGET of a history
def test_post26_vget_moves_a_lumped_cooling_history_into_arrays():
    # a copper square (Bi = h a/(4k) ≈ 1e-4) cooling by a film on its four sides, DELTIM
    # fixed, the film stepped (KBC,1): backward Euler on the lumped body gives
    # T_n = T_a + (T_0 − T_a)(1 + Δt/τ)^−n, τ = ρ c a / (4 h)
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


@pytest.mark.parametrize("command", ["*VLEN,2", "*VMASK,M(1)", "*VABS,1", "*VFACT,2",
                                     "*VCUM,1"])
def test_vector_controls_are_refused_not_ignored(command, tmp_path):
    # ignored with a warning, *VLEN,2 would leave the *VOPER after it running over every row
    deck = tmp_path / "d.inp"
    deck.write_text(f"*DIM,A,ARRAY,3\n{command}\n*VOPER,A(1),1,ADD,1\n")
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(deck), "--out",
                           str(tmp_path / "o")], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    name = command.split(",")[0]
    assert f"{deck}:2: {name}: not supported" in done.stderr


# ------------------------------- a held and cooled bar: ENAME, PLNSOL, *DOWHILE, SFCUM
BAR = """/PREP7
ET,1,PLANE55
ET,2,PLANE77
MP,KXX,1,1
RECTNG,0,0.1,0,0.01
ESIZE,0.01
AMESH,ALL
ESEL,S,ENAME,,55
*GET,N55,ELEM,0,COUNT
ESEL,S,ENAME,,PLANE77
*GET,N77,ELEM,0,COUNT
ALLSEL
NSEL,S,LOC,X,0
D,ALL,TEMP,100
NSEL,S,LOC,X,0.1
SFCUM,CONV,REPL
SF,ALL,CONV,10,20
ALLSEL
/SOLU
SOLVE
/POST1
PLNSOL,TEMP
*GET,TMAX,PLNSOL,0,MAX
*GET,TMIN,PLNSOL,0,MIN
NSEL,S,LOC,X,0.05,0.1
PLNSOL,TEMP
*GET,THALF,PLNSOL,0,MAX
ALLSEL
N = 0
LEFT = 3
*DOWHILE,LEFT
N = N + 1
LEFT = LEFT - 1
*ENDDO
NEVER = 0
*DOWHILE,NEVER
NEVER = 99
*ENDDO
"""


def test_ename_plnsol_extremes_dowhile_and_sfcum_in_a_cooled_bar():
    # a bar held at 100 °C at x = 0, a film h = 10 at x = L = 0.1 (k = 1, insulated sides):
    # T(x) = 100 − 80 (h x/k)/(1 + h L/k), so T(L) = 60 and T(L/2) = 80
    p = run(BAR).params
    assert (p["N55"], p["N77"]) == (10.0, 0.0)  # every element is a PLANE55
    assert p["TMAX"] == pytest.approx(100.0, abs=1e-9)
    assert p["TMIN"] == pytest.approx(60.0, abs=1e-9)
    assert p["THALF"] == pytest.approx(80.0, abs=1e-9)  # the max over the nodes selected
    assert p["N"] == 3.0 and p["LEFT"] == 0.0  # *DOWHILE loops while Par > 0
    assert p["NEVER"] == 0.0  # Par = 0: the block is skipped
    # outside /POST1 PLNSOL stays a plot command that changes nothing (as before)
    assert run("/PREP7\nPLNSOL,TEMP\nA = 1\n").state.listing.warnings == []
    for deck, message in [
        ("/PREP7\nSFCUM,CONV,ADD\n", "only SFCUM,,REPL"),
        ("/PREP7\nN,1\nET,1,PLANE55\n/POST1\n*GET,X,PLNSOL,0,MAX\n", "PLNSOL has not been run"),
        (BAR + "PLNSOL,TF,SUM\n*GET,X,PLNSOL,0,MAX\n", "PLNSOL,TF,SUM is not supported"),
        (BAR + "PLNSOL\n*GET,X,PLNSOL,0,MEAN\n", "MAX or MIN"),
        ("/POST1\nPLNSOL,TEMP\n", "no results yet"),
        ("I = 0\n*DOWHILE,I\n", "never closed"),
        ("GO = 1\n*DOWHILE,GO\nX = 1\n*ENDDO\n", "loop iterations"),
    ]:
        with pytest.raises(ApdlError, match=message):
            run(deck)


@pytest.mark.parametrize("props, nonlinear", [
    ("MPTEMP,1,0,500\nMPDATA,C,1,1,1000,1000\n", False),  # a constant written as a table
    ("MPTEMP,1,20\nMPDATA,KXX,1,1,5\n", False),  # one point
    ("MP,KXX,1,5,0,0\n", False),  # C1.. of zero
    ("MPTEMP,1,0,500\nMPDATA,C,1,1,1000,1100\n", True),
    ("MP,KXX,1,5,0.01\n", True),
])
def test_a_constant_property_table_solves_linearly(props, nonlinear):
    # a slab's c given as a two-point table of one value iterated every substep (140 s for
    # a deck that takes 10 s with MP,C)
    from apdl_like.plane_solve import _is_nonlinear

    s = run("/PREP7\nMP,DENS,1,1\nMP,KXX,1,1\nMP,C,1,1\n" + props)
    assert _is_nonlinear(s.db, [1]) is nonlinear


# ------------------------------------------ whole decks a thermal engineer brings along
USER_DECKS = Path(__file__).parent / "data" / "user_decks"


def run_deck(name: str) -> dict:
    s = Session()
    s.run_file(USER_DECKS / name)
    assert s.state.listing.warnings == [], name  # every command of these decks is known
    assert s.state.listing.files, name  # each writes its results table
    return {k: v.ravel() if isinstance(v, np.ndarray) else v for k, v in s.params.items()}


def test_user_deck_plane_wall_with_two_films():
    # series resistances 1/h_i + L/k + 1/h_o; linear elements hold the linear field exactly
    p = run_deck("wall.inp")
    q = (20.0 - -10.0) / (1 / 10.0 + 0.2 / 1.4 + 1 / 25.0)
    assert p["T_SI"] == pytest.approx(20.0 - q / 10.0, abs=1e-9)
    assert p["T_SO"] == pytest.approx(-10.0 + q / 25.0, abs=1e-9)


def test_user_deck_rod_with_heat_generation_every_node():
    # T(r) = T_f + q R/(2h) + q (R² − r²)/(4k): PLANE77 holds the quadratic exactly
    p = run_deck("rod_hgen.inp")
    R, q, k, h, Tf = 0.025, 2.0e6, 15.0, 200.0, 30.0
    assert p["TS"] == pytest.approx(Tf + q * R / (2 * h), abs=1e-9)  # 155
    assert p["TC"] == pytest.approx(Tf + q * R / (2 * h) + q * R**2 / (4 * k), abs=1e-9)
    assert p["NCNT"] == 85.0 and p["ERRMAX"] < 1e-9  # every node, read by *VGET


def test_user_deck_lumped_cooling_in_a_do_loop_of_load_steps():
    # τ = ρ c a/(4h); five load steps of τ/2 with Δt = τ/200 (backward Euler):
    # T = T_a + (T_0 − T_a)(1 + 1/200)^−100 i; Bi ≈ 1e-4 leaves the centre 1e-4 warmer
    p = run_deck("lumped.inp")
    i = np.arange(1, 6)
    euler = 20.0 + 180.0 * (1 + 1 / 200) ** (-100.0 * i)
    np.testing.assert_allclose(p["TNUM"], euler, rtol=2e-4)
    exact = 20.0 + 180.0 * np.exp(-i / 2)  # the time step's own error: under 0.3 %
    np.testing.assert_allclose(p["TNUM"], exact, rtol=3e-3)
    assert p["TMIN"] == pytest.approx(p["TNUM"][-1], rel=1e-12)  # POST26, the same node


def test_user_deck_fin_with_tip_convection():
    # 1-D fin, P = 2 per unit depth: q = M (sinh mL + (h/mk) cosh mL)/(cosh mL + (h/mk)
    # sinh mL), θ_tip/θ_b = 1/(cosh mL + (h/mk) sinh mL); Bi = h t/(2k) ≈ 2e-4
    p = run_deck("fin.inp")
    L, t, k, h, Tb, Ta = 0.05, 0.002, 180.0, 40.0, 100.0, 25.0
    m = math.sqrt(2 * h / (k * t))
    a = h / (m * k)
    M = math.sqrt(2 * h * k * t) * (Tb - Ta)
    denominator = math.cosh(m * L) + a * math.sinh(m * L)
    assert p["QNUM"] == pytest.approx(M * (math.sinh(m * L) + a * math.cosh(m * L))
                                      / denominator, rel=1e-4)  # 258.09 W/m
    assert p["TTIP"] == pytest.approx(Ta + (Tb - Ta) / denominator, rel=1e-5)


def test_user_deck_slab_with_a_step_surface_temperature():
    # θ/θ_i at the mid-plane = Σ 2(−1)^n/λ_n exp(−λ_n² Fo), λ_n = (2n + 1)π/2, Fo = 0.2
    p = run_deck("slab.inp")
    lam = (2 * np.arange(30) + 1) * math.pi / 2
    series = float(np.sum(2 * (-1.0) ** np.arange(30) / lam * np.exp(-lam**2 * 0.2)))
    assert p["TC_END"] == pytest.approx(120.0 - 100.0 * series, rel=1e-3)  # 42.77 °C


def test_user_deck_insulated_pipe_with_conductivity_rising_with_temperature():
    # steel wall (k = 45) inside insulation with k = 0.04 + 1e-4 T (the MPDATA points lie on
    # it, so the interpolation is exact): the Kirchhoff transform of the insulation, with
    # the film at R3, solved for the heat per metre by bisection
    p = run_deck("pipe.inp")
    r1, r2, r3, h = 0.050, 0.055, 0.105, 8.0
    k0, b = 0.04, 1e-4

    def temperatures(q: float) -> tuple[float, float, float]:
        t2 = 250.0 - q * math.log(r2 / r1) / (2 * math.pi * 45.0)
        c = k0 * t2 + b / 2 * t2**2 - q * math.log(r3 / r2) / (2 * math.pi)
        t3 = (-k0 + math.sqrt(k0**2 + 2 * b * c)) / b
        return t2, t3, q - h * 2 * math.pi * r3 * (t3 - 20.0)

    lo, hi = 0.0, 300.0
    for _ in range(100):
        mid = (lo + hi) / 2
        lo, hi = (lo, mid) if temperatures(mid)[2] > 0 else (mid, hi)
    t2, t3, _ = temperatures(lo)
    assert p["T2"] == pytest.approx(t2, rel=1e-5)
    assert p["T3"] == pytest.approx(t3, rel=5e-4)  # 40.99 °C
    assert abs(p["Q_PER_M"]) == pytest.approx(lo, rel=5e-4)  # 110.76 W/m


def test_user_deck_film_sweep_in_a_do_loop_of_analyses():
    # an insulated-tip bar cooled on one face: θ_tip/θ_b = 1/cosh(mL), m = √(h/(k t))
    p = run_deck("study.inp")
    h = np.array([5.0, 10.0, 20.0, 40.0])
    exact = 20.0 + 60.0 / np.cosh(np.sqrt(h / (200.0 * 0.004)) * 0.1)
    np.testing.assert_allclose(p["TTIP"], exact, rtol=2e-4)
    assert p["RMAX"] == pytest.approx(float(np.max(p["TTIP"] / exact)), rel=1e-12)
