"""Thermal line and point elements (LINK31/33/34, MASS71) against closed forms.

Every expected value is a textbook formula evaluated here (series resistances, the
Stefan-Boltzmann law, a root of the radiation-convection balance found by scipy, lumped
exponential cooling), never a number from the code.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from apdl_like.errors import ApdlError
from apdl_like.session import Session
from tests.apdl_decks import SOLVE_THEN_POST


def run(text: str) -> Session:
    s = Session()
    s.run_text(text, "links.inp")
    return s


def cooling_mass(cap: float, h: float, area: float, t0: float, t_air: float, t_end: float,
                 n: int) -> str:
    """MASS71 (capacitance cap) at node 1 tied by LINK34 (h, area) to air held at node 2,
    starting at t0, n fixed backward-Euler substeps to t_end; ends in /SOLU after SOLVE."""
    return f"""/PREP7
ANTYPE,TRANS
ET,1,MASS71,,,1
ET,2,LINK34
R,1,{cap}
R,2,{area}
MP,HF,1,{h}
N,1
N,2
E,1
TYPE,2
REAL,2
E,1,2
FINISH
/SOLU
TIME,{t_end}
NSUBST,{n}
AUTOTS,OFF
BFUNIF,TEMP,{t0}
KBC,1
D,2,TEMP,{t_air}
SOLVE
FINISH
"""


def test_composite_wall_of_bars_and_convection_links_is_a_series_of_resistances():
    """Fluid 1 -LINK34- wall a (LINK33) - wall b (LINK33) -LINK34- fluid 2, unit area:
    q = ΔT / (1/h1 + La/ka + Lb/kb + 1/h2); the inner wall temperatures follow, each
    bar's HEAT RATE (ETABLE,,SMISC,1, summed by SSUM over the two) is q, and the first
    link's nodal heat at the hot fluid node (ESOL, positive out of the element) is −q."""
    h1, ka, la, kb, lb, h2 = 12.0, 0.8, 0.75, 0.1, 0.4, 2.0
    t1, t2 = 3000.0, 80.0
    s = run(f"""/PREP7
ET,1,LINK34
ET,2,LINK33
R,1,1
MP,KXX,1,{ka}
MP,HF,1,{h1}
MP,KXX,2,{kb}
MP,HF,2,{h2}
N,1
N,2
N,3,{la}
N,4,{la + lb}
N,5,{la + lb}
E,1,2
TYPE,2
E,2,3
MAT,2
E,3,4
TYPE,1
E,4,5
D,1,TEMP,{t1}
D,5,TEMP,{t2}
{SOLVE_THEN_POST}
*GET,T2,NODE,2,TEMP
*GET,T4,NODE,4,TEMP
ESEL,S,ELEM,,2,3
ETABLE,QB,SMISC,1
SSUM
*GET,QBARS,SSUM,,ITEM,QB
ESEL,S,ELEM,,2
ETABLE,TI,SMISC,2
SSUM
*GET,TI2,SSUM,,ITEM,TI
FINISH
/POST26
ESOL,2,1,1,HEAT
*GET,Q,VARI,2,EXTREM,VMAX
""")
    q = (t1 - t2) / (1 / h1 + la / ka + lb / kb + 1 / h2)
    p = s.params
    assert p["Q"] == pytest.approx(-q, rel=1e-10)  # heat enters the link at its hot node
    assert p["QBARS"] == pytest.approx(2 * q, rel=1e-10)  # both bars' HEAT RATE (ETABLE)
    assert p["TI2"] == pytest.approx(t1 - q / h1, rel=1e-10)  # bar a's TI (SMISC,2)
    assert p["T2"] == pytest.approx(t1 - q / h1, rel=1e-10)
    assert p["T4"] == pytest.approx(t2 + q / h2, rel=1e-10)


def test_heat_generating_bars_reach_the_parabolic_centre_temperature():
    """A slab 0..L generating q̇, insulated at 0, convecting (h, T∞) at L: the exact
    centre temperature T∞ + q̇L/h + q̇L²/(2k); linear bars with lumped generation give the
    exact nodal values of this quadratic field."""
    k, qdot, length, h, t_inf, n = 25.0, 1e5, 0.02, 14.0, 150.0, 8
    s = run(f"""/PREP7
ET,1,LINK33
ET,2,LINK34
R,1,1
MP,KXX,1,{k}
MP,HF,1,{h}
N,1
N,{n + 1},{length}
FILL
N,{n + 2},{length}
E,1,2
EGEN,{n},1,1
TYPE,2
E,{n + 1},{n + 2}
D,{n + 2},TEMP,{t_inf}
ESEL,S,TYPE,,1
BFE,ALL,HGEN,,{qdot}
ESEL,ALL
{SOLVE_THEN_POST}
*GET,TC,NODE,1,TEMP
""")
    assert s.params["TC"] == pytest.approx(t_inf + qdot * length / h
                                           + qdot * length ** 2 / (2 * k), rel=1e-9)


def test_radiation_link_emits_by_the_stefan_boltzmann_law_with_toffst():
    """Two held nodes: Q = σ ε F A ((T1 + Toff)⁴ − (T2 + Toff)⁴), SBC's default
    0.119E-10 Btu/(hr·in²·°R⁴) when R leaves it blank."""
    area, form, emis, t1, t2, off = 144.0, 1.0, 0.8, 3000.0, 100.0, 460.0
    s = run(f"""/PREP7
ET,1,LINK31
R,1,{area},{form},{emis}
N,1
N,2
E,1,2
TOFFST,{off}
D,1,TEMP,{t1}
D,2,TEMP,{t2}
FINISH
/SOLU
SOLVE
FINISH
/POST26
ESOL,2,1,1,HEAT
*GET,Q,VARI,2,EXTREM,VMAX
""")
    sigma = 0.119e-10
    assert -s.params["Q"] == pytest.approx(  # the emitting node gives the heat: ESOL < 0
        sigma * emis * form * area * ((t1 + off) ** 4 - (t2 + off) ** 4), rel=1e-9)


def test_convection_and_radiation_balance_at_a_free_node():
    """A thermocouple bead: gas --h-- bead --radiation-- wall.  The bead temperature is the
    root of h (Tg − T) = σ ε ((T + Toff)⁴ − (Tw + Toff)⁴), found here by brentq; the
    deck's Picard iteration must reach it."""
    h, emis, sigma, tg, tw, off = 11.85, 0.5, 0.174e-8, 1309.0, 300.0, 460.0
    s = run(f"""/PREP7
ET,1,LINK34
ET,2,LINK31
R,1,1
R,2,1,1,{emis},{sigma}
MP,HF,1,{h}
N,1
N,2
N,3
E,1,2
TYPE,2
REAL,2
E,2,3
TOFFST,{off}
D,1,TEMP,{tg}
D,3,TEMP,{tw}
{SOLVE_THEN_POST}
*GET,TB,NODE,2,TEMP
""")
    bead = brentq(lambda t: h * (tg - t) - sigma * emis * ((t + off) ** 4 - (tw + off) ** 4),
                  tw, tg)
    assert s.params["TB"] == pytest.approx(bead, rel=1e-6)


def test_thermal_mass_cools_exponentially_through_a_convection_link():
    """MASS71 (KEYOPT(3)=1: capacitance C) tied by LINK34 (h, A) to held air: T = T∞ +
    (T0 − T∞) exp(−hA t / C).  Backward Euler with n steps gives (1 + hA Δt / C)^−n
    exactly; with small steps both agree with the exponential to 1e-3."""
    cap, h, area, t0, t_air, t_end, n = 2.7e-4, 2.0, 0.0081812, 300.0, 100.0, 0.0125, 400
    s = run(cooling_mass(cap, h, area, t0, t_air, t_end, n) + """
/POST1
*GET,T1,NODE,1,TEMP
""")
    rate = h * area / cap
    euler = t_air + (t0 - t_air) * (1 + rate * t_end / n) ** -n
    assert s.params["T1"] == pytest.approx(euler, rel=1e-10)
    assert s.params["T1"] == pytest.approx(t_air + (t0 - t_air) * math.exp(-rate * t_end),
                                           rel=1e-3)


def test_a_link_without_its_film_coefficient_names_the_material():
    with pytest.raises(ApdlError, match="material 1 has no HF"):
        run("""/PREP7
ET,1,LINK34
R,1,1
MP,KXX,1,1
N,1
N,2
E,1,2
D,1,TEMP,10
D,2,TEMP,0
FINISH
/SOLU
SOLVE
""")


def test_lmesh_bars_with_bfk_generation_match_the_parabola_on_a_graded_line():
    """LESIZE,1,,,n,ratio grades the divisions (last/first = ratio); LMESH numbers the end
    keypoints' nodes 1, 2 and the interior 3.. from K1.  A bar generating q̇ (BFK on both
    keypoints) held at T0 on both ends: T = T0 + q̇ x (L − x) / (2k), which linear bars
    reproduce exactly at the nodes on any grading."""
    k, qdot, length, t0, n, ratio = 20.0, 4e4, 0.5, 32.0, 6, 3.0
    s = run(f"""/PREP7
ET,1,LINK33
R,1,1
MP,KXX,1,{k}
K,1
K,2,{length}
L,1,2
LESIZE,1,,,{n},{ratio}
LMESH,1
FINISH
/SOLU
DK,1,TEMP,{t0}
DK,2,TEMP,{t0}
BFK,ALL,HGEN,{qdot}
SOLVE
FINISH
/POST1
*GET,X3,NODE,3,LOC,X
*GET,T3,NODE,3,TEMP
*GET,T5,NODE,5,TEMP
*GET,X5,NODE,5,LOC,X
""")
    sizes = ratio ** (np.arange(n) / (n - 1))
    x = length * np.cumsum(sizes) / sizes.sum()
    p = s.params
    assert p["X3"] == pytest.approx(x[0], rel=1e-12)
    assert p["X5"] == pytest.approx(x[2], rel=1e-12)
    for name, xi in (("T3", x[0]), ("T5", x[2])):
        assert p[name] == pytest.approx(t0 + qdot * xi * (length - xi) / (2 * k), rel=1e-9)


def test_link_heat_rate_history_integrates_to_the_heat_the_mass_lost():
    """ESOL,,e,,SMISC,1 is LINK34's HEAT RATE hA(TI − TJ); INT1 integrates it over the
    stored substeps (trapezoid, from the first one).  Backward Euler balances each step,
    C (T_k − T_k+1) = Δt Q_k+1, so the trapezoid sum is exactly the heat the mass gave up,
    C (T_1 − T_n), plus Δt (Q_1 − Q_n) / 2; *GET,,VARI,,RTIME reads the history between
    stored times linearly."""
    cap, h, area, t0, t_air, t_end, n = 2.7e-4, 2.0, 0.0081812, 300.0, 100.0, 0.05, 500
    s = run(cooling_mass(cap, h, area, t0, t_air, t_end, n) + f"""
/POST26
NSOL,2,1,TEMP
ESOL,3,2,,SMISC,1
INT1,4,3,1
*GET,Q,VARI,4,EXTREM,VLAST
*GET,Q1,VARI,3,EXTREM,VMAX
*GET,TM,VARI,2,RTIME,{t_end / n * 2.5}
""")
    rate, dt = h * area / cap, t_end / n
    euler = [t_air + (t0 - t_air) * (1 + rate * dt) ** -k for k in range(n + 1)]
    p = s.params
    assert p["Q1"] == pytest.approx(h * area * (euler[1] - t_air), rel=1e-9)
    q_first, q_last = (h * area * (euler[k] - t_air) for k in (1, n))
    assert p["Q"] == pytest.approx(cap * (euler[1] - euler[n]) + dt * (q_first - q_last) / 2,
                                   rel=1e-9)
    assert p["TM"] == pytest.approx(0.5 * (euler[2] + euler[3]), rel=1e-12)
