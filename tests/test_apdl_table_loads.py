"""Tabular loads (`D,ALL,TEMP,%T%`, F,,HEAT, SF/SFE CONV and HFLUX, BF/BFE HGEN) and nodal
heat flows (F,,HEAT) against closed forms.

Every expected value is a textbook formula (series, Duhamel superposition, energy balance,
linear profiles) evaluated here, never a number taken from the code.
"""

from __future__ import annotations

import math
import subprocess
import sys
from collections.abc import Callable

import numpy as np
import pytest
from scipy.optimize import brentq

from apdl_like.errors import ApdlError
from apdl_like.session import Session
from tests.apdl_decks import STEEL_SQUARE, column_of_quads
from twin.fem import AxiMesh, Material

K, RHO, C, L = 1.0, 1000.0, 1000.0, 0.01  # W/mK, kg/m³, J/kgK, m: α = 1e-6 m²/s
ALPHA = K / (RHO * C)
RAMP_END_S, RAMP_TO_C, T_END_S = 10.0, 100.0, 20.0  # the tables: 0 -> 100 °C over 10 s, then held

# a column 0 <= y <= L of NZE PLANE55 quads, one 1 mm element wide: 1-D conduction along y
SLAB = f"""
/PREP7
ET,1,PLANE55
MP,KXX,1,{K}
MP,DENS,1,{RHO}
MP,C,1,{C}
{column_of_quads(L, 0.0, 0.001)}
*DIM,RAMP,TABLE,2,1,1,TIME
RAMP(1,0) = 0,{RAMP_END_S}
RAMP(1,1) = 0,{RAMP_TO_C}
"""


def run(text: str) -> Session:
    s = Session()
    s.run_text(text, "deck.inp")
    return s


def transient(load: str, dt: float, kbc: int = 1) -> float:
    """The insulated end's temperature (°C) at T_END_S, the face y = 0 loaded by `load`."""
    s = run(SLAB + f"""
/SOLU
ANTYPE,TRANS
TUNIF,0
NSEL,S,LOC,Y,0
{load}
ALLSEL
KBC,{kbc}
AUTOTS,OFF
TIME,{T_END_S}
DELTIM,{dt}
SOLVE
*GET,T_END,NODE,NZE+1,TEMP
""")
    return s.params["T_END"]


def ramp_then_hold(ramp_response: Callable[[float], float], t: float) -> float:
    """Duhamel: the response to a face value rising at RAMP_TO_C/RAMP_END_S and then held is
    the unit-ramp response less itself delayed by RAMP_END_S, times the slope."""
    slope = RAMP_TO_C / RAMP_END_S
    return slope * (ramp_response(t) - (ramp_response(t - RAMP_END_S) if t > RAMP_END_S else 0))


def fixed_face_ramp_response(t: float) -> float:
    """Slab 0..L, insulated at L, T(0, t) = t: T(L, t) = t − Σ 4(−1)^n/((2n+1)π)
    (1 − exp(−λn² α t))/(λn² α), λn = (2n+1)π/(2L) (the step response's integral)."""
    total = t
    for n in range(200):
        lam = (2 * n + 1) * math.pi / (2 * L)
        total -= 4 * (-1) ** n / ((2 * n + 1) * math.pi) * (1 - math.exp(-lam**2 * ALPHA * t)) \
            / (lam**2 * ALPHA)
    return total


def film_ramp_response(h: float) -> Callable[[float], float]:
    """Slab 0..L, insulated at L, a film h at 0 with bulk temperature t: T(L, t) = t −
    Σ Cn (1 − exp(−λn² α t))/(λn² α), μn = λn L the roots of μ tan μ = Bi = hL/k and
    Cn = 4 sin μn/(2μn + sin 2μn) (the step response's integral)."""
    bi = h * L / K
    mus = [brentq(lambda m: m * math.tan(m) - bi, n * math.pi + 1e-12,
                  n * math.pi + math.pi / 2 - 1e-12) for n in range(200)]

    def response(t: float) -> float:
        total = t
        for mu in mus:
            lam = mu / L
            cn = 4 * math.sin(mu) / (2 * mu + math.sin(2 * mu))
            total -= cn * (1 - math.exp(-lam**2 * ALPHA * t)) / (lam**2 * ALPHA)
        return total

    return response


def test_face_temperature_from_a_time_table_converges_to_duhamels_solution():
    """D,ALL,TEMP,%RAMP%: the face follows the table at every substep (held past its last
    time); backward Euler's error halves with Δt (first order) down to the mesh's."""
    exact = ramp_then_hold(fixed_face_ramp_response, T_END_S)
    errors = [transient("D,ALL,TEMP,%RAMP%", dt) - exact for dt in (0.4, 0.2, 0.1)]
    assert exact == pytest.approx(13.68, abs=0.01)  # 13.7 % of the 100 °C the face reaches
    assert abs(errors[-1]) < 0.01 * exact
    for coarse, fine in zip(errors, errors[1:], strict=False):
        assert 1.8 < coarse / fine < 2.1
    # the extrapolated error (the mesh's, Δt -> 0) is a small part of the time error
    assert abs(2 * errors[-1] - errors[-2]) < 0.15 * abs(errors[-1])


def test_table_loads_are_not_ramped_by_kbc():
    """MAPDL: tabular loads are evaluated at the current time, never ramped: KBC,0 (ramped)
    and KBC,1 (stepped) give the same answer."""
    assert transient("D,ALL,TEMP,%RAMP%", 0.4, kbc=0) == transient("D,ALL,TEMP,%RAMP%", 0.4,
                                                                       kbc=1)


@pytest.mark.parametrize("film", ["SF,ALL,CONV,%HFILM%,%RAMP%",
                                  "ESEL,S,ELEM,,1\nSFE,ALL,1,CONV,0,%HFILM%\n"
                                  "SFE,ALL,1,CONV,2,%RAMP%\nESEL,ALL"])
def test_film_with_a_tabulated_bulk_temperature_converges_to_the_series_solution(film):
    """A film h = 100 W/m²K (Bi = 1, itself a table constant in time) whose bulk temperature
    follows %RAMP%: the Robin series by Duhamel superposition."""
    h = 100.0
    exact = ramp_then_hold(film_ramp_response(h), T_END_S)
    load = f"*DIM,HFILM,TABLE,2,1,1,TIME\nHFILM(1,0) = 0,1\nHFILM(1,1) = {h},{h}\n{film}"
    errors = [transient(load, dt) - exact for dt in (0.4, 0.2, 0.1)]
    assert exact == pytest.approx(2.568, abs=0.001)
    for coarse, fine in zip(errors, errors[1:], strict=False):
        assert 1.8 < coarse / fine < 2.1
    assert abs(errors[-1]) < 0.02 * exact


def test_steady_load_steps_read_the_table_at_their_time():
    """ANTYPE,STATIC: the table is read at the load step's TIME (clamped past its end).
    Film at y = 0 (h, bulk from %RAMP%), T = 0 at y = L: T(0) = Tb − q/h with
    q = Tb/(1/h + L/k)."""
    h = 100.0
    s = run(SLAB + f"""
/SOLU
ANTYPE,STATIC
NSEL,S,LOC,Y,0
SF,ALL,CONV,{h},%RAMP%
NSEL,S,LOC,Y,{L}
D,ALL,TEMP,0
ALLSEL
TIME,2.5
SOLVE
*GET,T_A,NODE,1,TEMP
TIME,40
SOLVE
*GET,T_B,NODE,1,TEMP
""")
    for tb, got in ((25.0, s.params["T_A"]), (100.0, s.params["T_B"])):
        q = tb / (1 / h + L / K)
        assert got == pytest.approx(tb - q / h, rel=1e-9)


HEAT_BLOCK = STEEL_SQUARE + """
*DIM,QTAB,TABLE,4,1,1,TIME
QTAB(1,0) = 0,10,10.001,20
QTAB(1,1) = 2E6,2E6,5E6,5E6
/SOLU
ANTYPE,TRANS
TUNIF,20
AUTOTS,OFF
DELTIM,0.5
"""


def test_heat_generation_step_from_a_table_equals_two_load_steps():
    """An insulated block: HGEN 2 MW/m³ for 10 s then 5 MW/m³, once from one table (a step
    between index values 10 and 10.001 s) and once as two load steps.  Backward Euler takes
    each substep's load at its end, so both are the same, and the energy balance is exact:
    T = T0 + (q1 t1 + q2 t2)/(ρc)."""
    table = run(HEAT_BLOCK + "BFE,ALL,HGEN,,%QTAB%\nTIME,20\nSOLVE\n*GET,T_A,NODE,1,TEMP\n")
    steps = run(HEAT_BLOCK + "KBC,1\nBFE,ALL,HGEN,,2E6\nTIME,10\nSOLVE\nBFE,ALL,HGEN,,5E6\n"
                "TIME,20\nSOLVE\n*GET,T_A,NODE,1,TEMP\n")
    expected = 20.0 + (2e6 * 10 + 5e6 * 10) / (7800 * 460)
    assert table.params["T_A"] == pytest.approx(expected, rel=1e-10)
    assert table.params["T_A"] == pytest.approx(steps.params["T_A"], rel=1e-12)
    assert np.allclose(table.state.solution.history_temperatures,
                       steps.state.solution.history_temperatures, rtol=1e-12)


def test_a_load_tabular_in_one_step_and_a_value_in_the_next_is_ramped_from_zero():
    """MAPDL: a load tabular in one load step and given a value in the next is a newly
    introduced load, ramped (KBC,0) from zero, not from the table's last value: over n
    substeps backward Euler adds q2 (k/n) Δt/(ρc) in step k, q2 Δt (n+1)/(2ρc) in all."""
    s = run(HEAT_BLOCK + "BFE,ALL,HGEN,,%QTAB%\nTIME,20\nSOLVE\nKBC,0\nBFE,ALL,HGEN,,5E6\n"
            "TIME,30\nSOLVE\n*GET,T_A,NODE,1,TEMP\n")
    n, dt = 20, 0.5
    expected = 20.0 + (2e6 * 10 + 5e6 * 10 + 5e6 * dt * (n + 1) / 2) / (7800 * 460)
    assert s.params["T_A"] == pytest.approx(expected, rel=1e-10)


STRIP = """
/PREP7
ET,1,PLANE55
MP,KXX,1,{k}
RECTNG,0,{w},0,{h}
ESIZE,{size}
AMESH,ALL
/SOLU
ANTYPE,STATIC
"""


def test_tables_by_location_x_and_y():
    """Primary variables X and Y.  D on the whole boundary from a table in X (rows) and Y
    (columns) holding T = 10 + 100 x + 500 y at its corners: bilinear interpolation gives that
    plane, a harmonic field every mesh holds exactly.  HGEN from a table in X, q = q0 x/W,
    with T = 0 at x = 0 and W: T = q0 x (W² − x²)/(6kW)."""
    w, h, k = 0.1, 0.04, 2.0
    s = run(STRIP.format(k=k, w=w, h=h, size=0.01) + f"""
*DIM,TXY,TABLE,2,2,1,X,Y
TXY(1,0) = 0,{w}
TXY(0,1) = 0
TXY(0,2) = {h}
TXY(1,1) = 10,{10 + 100 * w}
TXY(1,2) = {10 + 500 * h},{10 + 100 * w + 500 * h}
NSEL,S,LOC,X,0
NSEL,A,LOC,X,{w}
NSEL,A,LOC,Y,0
NSEL,A,LOC,Y,{h}
D,ALL,TEMP,%TXY%
ALLSEL
SOLVE
""")
    x, y = s.state.db.nodes.xy.T
    got = s.state.solution.results[-1].nodal_temperature
    assert np.allclose(got, 10 + 100 * x + 500 * y, rtol=1e-10)
    assert np.ptp(x) == pytest.approx(w) and np.ptp(y) == pytest.approx(h)
    q0 = 1e5
    s = run(STRIP.format(k=k, w=w, h=0.005, size=0.0025) + f"""
*DIM,QX,TABLE,2,1,1,X
QX(1,0) = 0,{w}
QX(1,1) = 0,{q0}
BFE,ALL,HGEN,,%QX%
NSEL,S,LOC,X,0
NSEL,A,LOC,X,{w}
D,ALL,TEMP,0
ALLSEL
SOLVE
""")
    nodes = s.state.db.nodes
    x = nodes.xy[:, 0]
    exact = q0 * x * (w**2 - x**2) / (6 * k * w)
    got = s.state.solution.results[-1].nodal_temperature
    # q sampled at element centroids: for a linear q the slope terms of the two elements
    # at an interior node cancel, so its load, and the 1-D nodal solution, are exact
    assert np.max(np.abs(got - exact)) < 1e-9 * np.max(exact)


def test_nodal_heat_flow_f_heat_conducts_through_the_slab():
    """F,n,HEAT puts VALUE into each node: 0.05 W on each of the two nodes at y = 0 of the
    1 mm wide (unit thickness) column, T = 0 at y = L: q = 0.1 W / 1e-3 m² and
    T(0) = q L/k = 1 °C, exact for linear elements.  FDELE takes it away again."""
    s = run(SLAB + f"""
/SOLU
ANTYPE,STATIC
NSEL,S,LOC,Y,{L}
D,ALL,TEMP,0
NSEL,S,LOC,Y,0
F,ALL,HEAT,0.05
ALLSEL
SOLVE
*GET,T_A,NODE,1,TEMP
FDELE,ALL,HEAT
SOLVE
*GET,T_B,NODE,1,TEMP
""")
    assert s.params["T_A"] == pytest.approx(0.1 / 1e-3 * L / K, rel=1e-10)
    assert s.params["T_B"] == pytest.approx(0.0, abs=1e-12)


def test_nodal_heat_flow_from_a_table_heats_an_axisymmetric_ring_by_its_energy():
    """F,n,HEAT,%QF% on an axisymmetric ring (MAPDL: the heat of the whole circumference),
    Q(t) = 10 t W for 10 s; with a conductivity high enough to keep it uniform, the insulated
    ring warms by its energy over ρcV, V = π(ro² − ri²)h.  Backward Euler takes each substep's
    load at its end: E = Σ Q(k Δt) Δt = 550 J (the integral is 500 J), exactly."""
    ri, ro, h, rho_c = 0.01, 0.03, 0.02, 7800 * 460
    s = run(f"""
/PREP7
ET,1,PLANE55,,,1
MP,KXX,1,1E9
MP,DENS,1,7800
MP,C,1,460
RECTNG,{ri},{ro},0,{h}
ESIZE,0.005
AMESH,ALL
*DIM,QF,TABLE,2,1,1,TIME
QF(1,0) = 0,10
QF(1,1) = 0,100
/SOLU
ANTYPE,TRANS
TUNIF,20
KBC,1
AUTOTS,OFF
F,NODE({ri},0),HEAT,%QF%
TIME,10
DELTIM,1
SOLVE
*GET,T_A,NODE,NODE({ro},{h}),TEMP
""")
    energy = sum(10.0 * k * 1.0 for k in range(1, 11))
    assert energy == 550.0
    volume = math.pi * (ro**2 - ri**2) * h
    assert s.params["T_A"] == pytest.approx(20.0 + energy / (rho_c * volume), rel=1e-6)


@pytest.mark.parametrize("deck, message", [
    ("NSEL,S,LOC,Y,0\nD,ALL,TEMP,%NOPE%",
     r"deck.inp:\d+: D: field 3: %NOPE% names no parameter"),
    ("*DIM,HT,TABLE,2,1,1,TEMP\nNSEL,S,LOC,Y,0\nSF,ALL,CONV,%HT%,20",
     r"deck.inp:\d+: SF: field 3: table HT: primary variable TEMP \(Var1 \(rows\)\) is not "
     "supported for loads"),
    ("*DIM,QQ,TABLE,2\nBFE,ALL,HGEN,,%QQ%",
     r"deck.inp:\d+: BFE: field 4: table QQ names no primary variable for Var1"),
    ("*DIM,A,ARRAY,2\nBFE,ALL,HGEN,,%A%", r"BFE: field 4: %A% is not a TABLE parameter"),
    ("IC,ALL,TEMP,%RAMP%", r"IC: field 3 \(VALUE\): a table \(%RAMP%\) is not accepted here"),
    ("D,1,UX,%RAMP%", r"D: field 3 \(VALUE\): a table is supported for TEMP only"),
    ("F,1,FX,1", r"F: field 2: nodal load must be HEAT, got 'FX'"),
])
def test_bad_table_loads_are_located_errors(deck, message):
    with pytest.raises(ApdlError, match=message):
        run(SLAB + deck + "\n")


def test_a_table_redefined_without_a_primary_variable_stops_solve():
    """The table is read at SOLVE: one re-dimensioned after the load is checked again."""
    with pytest.raises(ApdlError, match=r"deck.inp:\d+: SOLVE: table RAMP names no primary"):
        run(SLAB + "/SOLU\nANTYPE,TRANS\nNSEL,S,LOC,Y,0\nD,ALL,TEMP,%RAMP%\nALLSEL\n"
            "*DIM,RAMP,TABLE,2\nTIME,1\nSOLVE\n")


def test_an_undefined_table_is_exit_2_from_the_command_line(tmp_path):
    deck = tmp_path / "deck.inp"
    deck.write_text(SLAB + "NSEL,S,LOC,Y,0\nD,ALL,TEMP,%TBOUND%\n")
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(deck), "--out",
                           str(tmp_path / "out")], capture_output=True, text=True, timeout=300)
    assert done.returncode == 2
    line = SLAB.count("\n") + 2
    assert f"deck.inp:{line}: D: field 3: %TBOUND% names no parameter" in done.stderr
    assert "Traceback" not in done.stderr


def test_the_spindle_session_refuses_tabular_loads():
    """A twin session (an AxiMesh solved on twin.fem) takes values only: a table there is a
    located error at SOLVE, and a window deck with one is refused when read."""
    r, z = np.linspace(0.0, 0.02, 3), np.linspace(0.0, 0.04, 5)
    mesh = AxiMesh.structured(r, z, regions={"body": lambda r, z: r >= 0.0},
                              boundaries={"outer": lambda r, z: np.isclose(r, 0.02)})
    deck = ("/SOLU\nANTYPE,TRANS\n*DIM,TB,TABLE,2,1,1,TIME\nTB(1,0) = 0,1\nTB(1,1) = 20,30\n"
            "NSEL,S,LOC,X,0.02\nD,ALL,TEMP,%TB%\nALLSEL\nKBC,1\nTIME,1\nDELTIM,0.5\nSOLVE\n")
    steel = Material(k=45.0, rho=7800.0, c=460.0)
    session = Session.from_mesh(mesh, {"body": steel})
    with pytest.raises(ApdlError, match=r"deck.inp:12: SOLVE: tabular loads \(%table%\) are "
                                        "solved on a deck's own mesh only"):
        session.run_text(deck, "deck.inp")
    with pytest.raises(ApdlError, match=r"tabular loads \(%table%\) are read on a deck's own"):
        Session.from_mesh(mesh, {"body": steel}).read_window_deck(
            "WINDOW = 0\nT_START = 0\n" + deck)
    with pytest.raises(ApdlError, match=r"SOLVE: nodal heat flows \(F,,HEAT\) are solved on a "
                                        "deck's own mesh only"):
        Session.from_mesh(mesh, {"body": steel}).run_text(
            deck.replace("D,ALL,TEMP,%TB%", "F,ALL,HEAT,5"), "deck.inp")
    with pytest.raises(ApdlError, match=r"SOLVE: nodal heat generation \(BF,Node,HGEN\) is "
                                        "solved on a deck's own mesh only"):
        Session.from_mesh(mesh, {"body": steel}).run_text(
            deck.replace("D,ALL,TEMP,%TB%", "BF,ALL,HGEN,5"), "deck.inp")
