"""Deck-based verification of apdl_like on twin.fem against closed forms.

Every expected value is a textbook formula evaluated here, never a number from the code.
Meshes come both from N/E commands and from RECTNG/ESIZE/AMESH.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from apdl_like.errors import ApdlError
from apdl_like.session import Session
from tests.apdl_decks import (
    SOLVE_THEN_POST,
    STEEL_SQUARE,
    column_of_quads,
    film_heat_sum,
    held_faces,
)

RI, RO, H = 0.02, 0.05, 0.01  # hollow cylinder, m
K = 50.0  # W/mK


def ring_model(mesh: str) -> str:
    """/PREP7 of the hollow cylinder (RI, RO, H as parameters) with `mesh` and k = K."""
    return f"/PREP7\nRI = {RI}\nRO = {RO}\nH = {H}\n{mesh}\nMP,KXX,1,{K}\n"


def run(text: str) -> Session:
    s = Session()
    s.run_text(text, "verify.inp")
    return s


def ring_nodes_elements(n: int, element: str, quad8: bool = False) -> str:
    """N/E of a radial strip RI..RO × 0..H with n elements (4-node or 8-node quads)."""
    if not quad8:
        return f"""
ET,1,{element},,,1
*DO,I,0,{n}
  N,I+1,RI+(RO-RI)*I/{n},0
  N,I+1001,RI+(RO-RI)*I/{n},H
*ENDDO
*DO,I,1,{n}
  E,I,I+1,I+1001,I+1000
*ENDDO
"""
    # corner nodes at even positions, mid-side nodes at odd ones (2n+1 along r)
    return f"""
ET,1,{element},,,1
*DO,I,0,{2 * n}
  N,I+1,RI+(RO-RI)*I/{2 * n},0
  N,I+1001,RI+(RO-RI)*I/{2 * n},H
*ENDDO
*DO,I,0,{n}
  N,2*I+2001,RI+(RO-RI)*2*I/{2 * n},H/2
*ENDDO
*DO,I,1,{n}
  A0 = 2*I-1
  E,A0,A0+2,A0+1002,A0+1000,A0+1,2*I+2001,A0+1001,2*I+1999
*ENDDO
"""


AMESH_STRIP = """
ET,1,{element},,,1
RECTNG,RI,RO,0,H
ESIZE,{size}
AMESH,ALL
"""


def log_profile(r, q_in, t_outer):
    """Hollow cylinder, flux q_in (W/m²) into the bore at RI, T fixed at RO."""
    return t_outer + q_in * RI / K * np.log(RO / r)


MESHES = {
    "N/E PLANE55": (ring_nodes_elements(20, "PLANE55"), 3e-3),
    "N/E PLANE77": (ring_nodes_elements(10, "PLANE77", quad8=True), 2e-4),
    "AMESH PLANE55": (AMESH_STRIP.format(element="PLANE55", size=0.002), 3e-3),
    "AMESH PLANE77": (AMESH_STRIP.format(element="PLANE77", size=0.004), 3e-4),
}


@pytest.mark.parametrize("name", list(MESHES))
def test_steady_flux_and_fixed_temperature(name):
    mesh, tol = MESHES[name]
    s = run(ring_model(mesh) + """
/SOLU
ANTYPE,STATIC
NSEL,S,LOC,X,RI
SF,ALL,HFLUX,2E5
NSEL,S,LOC,X,RO
D,ALL,TEMP,30
ALLSEL
SOLVE
*GET,T_IN,NODE,NODE(RI,0),TEMP
*GET,T_MID,NODE,NODE((RI+RO)/2,H),TEMP
X_MID = NX(NODE((RI+RO)/2,H))
""")
    p = s.params
    assert p["T_IN"] == pytest.approx(log_profile(RI, 2e5, 30.0), rel=tol)
    assert p["T_MID"] == pytest.approx(log_profile(p["X_MID"], 2e5, 30.0), rel=tol)


@pytest.mark.parametrize("name", ["N/E PLANE55", "AMESH PLANE77"])
def test_steady_convection(name):
    mesh, tol = MESHES[name]
    h, t_bulk, q = 800.0, 25.0, 1e5
    s = run(ring_model(mesh) + f"""
FINISH
/SOLU
NSEL,S,LOC,X,RI
SF,ALL,HFLUX,{q}
NSEL,S,LOC,X,RO
SF,ALL,CONV,{h},{t_bulk}
ALLSEL
SOLVE
FINISH
/POST1
*GET,T_IN,NODE,NODE(RI,H),TEMP
*GET,T_OUT,NODE,NODE(RO,0),TEMP
""")
    t_out = t_bulk + q * RI / (h * RO)  # all heat entering at RI leaves at RO
    t_in = t_out + q * RI / K * math.log(RO / RI)
    assert s.params["T_OUT"] == pytest.approx(t_out, rel=tol)
    assert s.params["T_IN"] == pytest.approx(t_in, rel=tol)


def test_convection_by_sfe_on_element_faces():
    """SFE (element face 2 = J-K, the outer face of the last element) = SF on those nodes."""
    h, t_bulk, q = 800.0, 25.0, 1e5
    s = run(ring_model(ring_nodes_elements(20, "PLANE55")) + f"""
/SOLU
SFE,1,4,HFLUX,,{q}
SFE,20,2,CONV,1,{h}
SFE,20,2,CONV,2,{t_bulk}
SOLVE
*GET,T_OUT0,NODE,21,TEMP
*GET,T_OUT1,NODE,1021,TEMP
""")
    # the heat balance holds exactly for the face mean (both ends of the face are at RO)
    t_mean = 0.5 * (s.params["T_OUT0"] + s.params["T_OUT1"])
    assert t_mean == pytest.approx(t_bulk + q * RI / (h * RO), rel=1e-9)


TRANSIENT_BLOCK = """
/PREP7
ET,1,PLANE55
KEYOPT,1,3,1
MP,KXX,1,45
MP,DENS,1,7800
MP,C,1,460
RECTNG,0.01,0.03,0,0.02
ESIZE,0.005
AMESH,ALL
/SOLU
ANTYPE,TRANS
TUNIF,20
BFE,ALL,HGEN,,5E6
TIME,12
DELTIM,1.5
KBC,{kbc}
SOLVE
*GET,T_A,NODE,1,TEMP
*GET,T_B,NODE,NODE(0.03,0.02),TEMP
"""


def test_transient_uniform_heating_stepped():
    """Insulated body, uniform HGEN: T = T0 + q t/(ρc) exactly (any mesh, any Δt)."""
    s = run(TRANSIENT_BLOCK.format(kbc=1))
    expected = 20.0 + 5e6 * 12.0 / (7800 * 460)
    assert s.params["T_A"] == pytest.approx(expected, rel=1e-10)
    assert s.params["T_B"] == pytest.approx(expected, rel=1e-10)
    assert len(s.state.solution.substep_temperatures) == 8


def test_transient_uniform_heating_ramped():
    """KBC,0 ramps HGEN from 0: backward Euler adds q·(k/n)·Δt/(ρc) in step k, so
    T(t_end) = T0 + q Δt (n+1) / (2 ρc) (hand sum over n = 8 steps)."""
    s = run(TRANSIENT_BLOCK.format(kbc=0))
    expected = 20.0 + 5e6 * 1.5 * 9 / (2 * 7800 * 460)
    assert s.params["T_A"] == pytest.approx(expected, rel=1e-10)


@pytest.mark.parametrize("autots, deltim, first, count", [
    ("OFF", 0.4, 1 / 3, 3),  # DELTIM's own example: 1/0.4 = 2.5 rounds to 3 substeps
    ("OFF", 0.9, 1.0, 1),  # 1/0.9 rounds to one substep
    ("ON", 0.4, 1 / 3, None),  # with AUTOTS: the starting substep, the same rounding
])
def test_deltim_substeps_divide_the_load_step_as_documented(autots, deltim, first, count):
    """DELTIM: "the program calculates the initial incremental time so that (EndingTime −
    StartingTime)/DTIME is an integer", rounding to the nearest; with AUTOTS, DTIME is the
    starting time substep.  Uniform heating of an insulated body is exact for any step."""
    s = run(f"""
{STEEL_SQUARE}
/SOLU
ANTYPE,TRANS
TUNIF,20
BFE,ALL,HGEN,,5E6
KBC,1
AUTOTS,{autots}
TIME,1
DELTIM,{deltim}
SOLVE
*GET,T_A,NODE,1,TEMP
""")
    times = s.state.solution.substep_times
    assert times[0] == pytest.approx(first, rel=1e-12) and times[-1] == 1.0
    if count is not None:
        assert len(times) == count
    assert s.params["T_A"] == pytest.approx(20.0 + 5e6 / (7800 * 460), rel=1e-10)


def _heated_block(t_end: float) -> tuple[Session, float]:
    """A block heated by HGEN q and cooled by a film to its start temperature (20 °C), with
    AUTOTS and DELTIM,10,1,60: its loads and start span no temperature range, so the range
    AUTOTS measures against is the rise.  k is large (Bi = hL/k ≈ 2e-5), so the block is
    lumped: T = 20 + (qL/h)(1 − exp(−t/τ)), τ = ρcL/h = 200 s (L = 0.02 m, film on one
    side).  Returns the session and the exact temperature at t_end."""
    h, q, rho, c, length = 358.8, 1e6, 7800.0, 460.0, 0.02
    s = run(f"""
/PREP7
ET,1,PLANE55
MP,KXX,1,4.5E5
MP,DENS,1,{rho}
MP,C,1,{c}
RECTNG,0,{length},0,{length}
ESIZE,0.01
AMESH,ALL
/SOLU
ANTYPE,TRANS
TUNIF,20
NSEL,S,LOC,X,{length}
SF,ALL,CONV,{h},20
ALLSEL
BFE,ALL,HGEN,,{q}
KBC,1
AUTOTS,ON
TIME,{t_end}
DELTIM,10,1,60
SOLVE
*GET,T_A,NODE,1,TEMP
""")
    tau = rho * c * length / h
    return s, 20.0 + q * length / h * (1.0 - math.exp(-t_end / tau))


def test_autots_heat_up_grows_the_substep_and_meets_the_exponential():
    """A smooth heat-up driven by heat generation: AUTOTS starts at DTIME (10 s), is never
    below DTMIN (1 s) nor above DTMAX (60 s), lands on the end and, as the response
    settles, grows its substeps (over 6τ: to DTMAX; over 3τ: well above DTMIN, where it
    used to take every substep at DTMIN, 591 and 1014 of them); the end temperature is
    within 0.1 % of the rise of the exact exponential (measured: 0.05 % at 3τ, 0.012 % at
    6τ, backward Euler lagging)."""
    for t_end, most in ((600.0, 400), (1200.0, 450)):
        s, exact = _heated_block(t_end)
        times = np.array(s.state.solution.substep_times)
        sizes = np.diff(np.concatenate([[0.0], times]))
        assert sizes[0] == 10.0 and times[-1] == t_end
        assert np.all(sizes >= 1.0 * (1 - 1e-12)) and np.all(sizes <= 60.0 * (1 + 1e-12))
        assert len(times) < most, t_end
        assert sizes[-3:].min() > 3.0, t_end
        assert abs(s.params["T_A"] - exact) < 1e-3 * (exact - 20.0), t_end
    s, _ = _heated_block(2400.0)
    assert max(np.diff(s.state.solution.substep_times)) == pytest.approx(60.0)


def test_autots_heat_up_converges_as_the_tolerance_falls(monkeypatch):
    """Backward Euler's error is first order in the substep, and step doubling sizes
    substeps as the square root of the tolerance: 16 times the tolerance, 4 times the
    error at the end (measured 3.9 at 6τ)."""
    import apdl_like.plane_thermal as plane_thermal

    errors = []
    for tolerance in (16 * plane_thermal.STEP_TOLERANCE, plane_thermal.STEP_TOLERANCE):
        monkeypatch.setattr(plane_thermal, "STEP_TOLERANCE", tolerance)
        s, exact = _heated_block(1200.0)
        errors.append(abs(s.params["T_A"] - exact))
    assert 3.0 < errors[0] / errors[1] < 5.0


def _sphere_center_cooling(n_radial: int) -> float:
    """VM111's sphere (R = 1/6 ft, k = 1/3, ρc = 66.67, h = 2 to 25 °F from 65 °F, 6 h) as a
    2° PLANE55 wedge of n_radial elements (VM111 itself: 15° and 3), AUTOTS from DTIME =
    0.01 h; the centre temperature, °F."""
    s = run(f"""
/PREP7
ANTYPE,TRANS
ET,1,PLANE55,,,1
MP,KXX,1,(1/3)
MP,DENS,1,62
MP,C,1,1.0752677
CSYS,1
N,1
N,2,(1/6/{n_radial}),-1
N,{n_radial + 1},(1/6),-1
FILL
NGEN,2,100,1,{n_radial + 1},1,,2
E,2,102,1,1
E,3,103,102,2
EGEN,{n_radial - 1},1,2
CP,1,TEMP,2,102
CPSGEN,{n_radial},1,1
AUTOTS,ON
DELTIM,.01
TIME,6
TUNIF,65
KBC,1
NSEL,S,LOC,X,(1/6)
SF,ALL,CONV,2,25
NSEL,ALL
/SOLU
SOLVE
*GET,T_C,NODE,1,TEMP
""")
    return s.params["T_C"]


def test_transient_sphere_cooling_converges_to_the_series_solution():
    """A sphere cooled by a film, Bi = hR/k = 1: λn = (2n − 1)π/2 and the centre follows
    T∞ + (Ti − T∞) Σ 2 sin λn/λn exp(−λn² Fo), 28.545 °F at Fo = αt/R² = 1.08.  With AUTOTS
    the deck's value approaches it as the radial mesh is refined (the wedge's straight outer
    face and backward Euler's lag keep it slightly above)."""
    fourier = (1 / 3) / (62 * 1.0752677) * 6.0 / (1 / 6) ** 2
    lam = (2 * np.arange(1, 40) - 1) * math.pi / 2
    exact = 25.0 + 40.0 * float(np.sum(2 * np.sin(lam) / lam * np.exp(-lam**2 * fourier)))
    assert exact == pytest.approx(28.545, abs=1e-3)
    coarse, fine = _sphere_center_cooling(12), _sphere_center_cooling(24)
    assert exact < fine < coarse
    assert fine == pytest.approx(exact, rel=0.0015)


def test_transient_conduction_series_solution():
    """Slab 0..L (a cylinder insulated on r), T(0, t) = T1 for t > 0, insulated at z = L:
    T(L, t) = T1 + (T0 − T1) Σ 4(−1)^n/((2n+1)π) exp(−((2n+1)π/2L)² α t)."""
    k, rho, c, L, t_end = 1.0, 1000.0, 1000.0, 0.01, 20.0
    alpha = k / (rho * c)
    s = run(f"""
/PREP7
ET,1,PLANE55,,,1
MP,KXX,1,{k}
MP,DENS,1,{rho}
MP,C,1,{c}
{column_of_quads(L, 0.01, 0.02)}
/SOLU
ANTYPE,TRANS
TUNIF,0
NSEL,S,LOC,Y,0
D,ALL,TEMP,100
ALLSEL
KBC,1
TIME,{t_end}
DELTIM,0.05
SOLVE
*GET,T_END,NODE,NZE+1,TEMP
""")
    series = sum(4 * (-1) ** n / ((2 * n + 1) * math.pi)
                 * math.exp(-((2 * n + 1) * math.pi / (2 * L)) ** 2 * alpha * t_end)
                 for n in range(50))
    expected = 100.0 + (0.0 - 100.0) * series
    # backward Euler with Δt = 0.05 s: first-order error ≈ 0.4 °C of the 100 °C step
    assert s.params["T_END"] == pytest.approx(expected, abs=0.6)


STRESS_STEPS = """
/SOLU
ANTYPE,STATIC
D,ALL,TEMP,{t_hot}
SOLVE
FINISH
/PREP7
ETCHG,TTS
MP,EX,1,{E}
MP,PRXY,1,{nu}
MP,ALPX,1,{alpha}
TREF,20
/SOLU
DDELE,ALL,TEMP
NSEL,S,LOC,X,{ro}
D,ALL,UX,0
NSEL,S,LOC,Y,0
D,ALL,UY,0
ALLSEL
LDREAD,TEMP
SOLVE
FINISH
/POST1
NP = NODE({ro}/2,{h})
*GET,UY_TOP,NODE,NP,U,Y
*GET,UX_MID,NODE,NP,U,X
*GET,S_R,NODE,NP,S,X
*GET,S_Z,NODE,NP,S,Y
*GET,S_HOOP,NODE,NP,S,Z
*GET,S_EQV,NODE,NP,S,EQV
"""


@pytest.mark.parametrize("how", ["N/E", "AMESH"])
def test_thermal_stress_radially_held_cylinder(how):
    """Solid cylinder heated uniformly by ΔT, outer surface held radially, ends free:
    u_r = 0, σ_rr = σ_θθ = −EαΔT/(1−ν), σ_zz = 0, u_z = αΔT (1+ν)/(1−ν) z."""
    E, nu, alpha, dT, ro, h = 200e9, 0.3, 1.2e-5, 80.0, 0.04, 0.03
    if how == "N/E":
        mesh = f"""
ET,1,PLANE55,,,1
*DO,I,0,4
  *DO,J,0,3
    N,10*J+I+1,{ro}*I/4,{h}*J/3
  *ENDDO
*ENDDO
*DO,I,1,4
  *DO,J,0,2
    E,10*J+I,10*J+I+1,10*J+I+11,10*J+I+10
  *ENDDO
*ENDDO
"""
    else:
        mesh = f"ET,1,PLANE55\nKEYOPT,1,3,1\nRECTNG,0,{ro},0,{h}\nESIZE,0.01\nAMESH,ALL\n"
    s = run(f"/PREP7\n{mesh}MP,KXX,1,40\n" + STRESS_STEPS.format(
        t_hot=20 + dT, E=E, nu=nu, alpha=alpha, ro=ro, h=h))
    p = s.params
    sigma = -E * alpha * dT / (1 - nu)
    assert p["UY_TOP"] == pytest.approx(alpha * dT * (1 + nu) / (1 - nu) * h, rel=1e-8)
    assert abs(p["UX_MID"]) < 1e-8 * alpha * dT * ro
    assert p["S_R"] == pytest.approx(sigma, rel=1e-6)
    assert p["S_HOOP"] == pytest.approx(sigma, rel=1e-6)
    assert abs(p["S_Z"]) < 1e-6 * abs(sigma)
    assert p["S_EQV"] == pytest.approx(abs(sigma), rel=1e-6)


def test_free_thermal_expansion_quadratic_triangles():
    """PLANE183 as 6-node triangles (KEYOPT(1)=1) from AMESH, body temperature by BF:
    a free body heated uniformly expands u_r = αΔT r with no stress."""
    alpha, dT = 1.1e-5, 50.0
    s = run(f"""
/PREP7
ET,1,PLANE183
KEYOPT,1,1,1
KEYOPT,1,3,1
MP,EX,1,2E11
MP,PRXY,1,0.28
MP,ALPX,1,{alpha}
TREF,20
RECTNG,0.01,0.05,0,0.04
ESIZE,0.01
AMESH,ALL
/SOLU
NSEL,S,LOC,Y,0
D,ALL,UY,0
ALLSEL
BF,ALL,TEMP,{20 + dT}
SOLVE
NP = NODE(0.05,0.04)
*GET,UX_OUT,NODE,NP,U,X
*GET,UY_TOP,NODE,NP,U,Y
*GET,S_EQV,NODE,NP,S,EQV
""")
    assert s.params["UX_OUT"] == pytest.approx(alpha * dT * 0.05, rel=1e-8)
    assert s.params["UY_TOP"] == pytest.approx(alpha * dT * 0.04, rel=1e-8)
    assert s.params["S_EQV"] < 1e-6 * 2e11 * alpha * dT


LONG_CYLINDER = """
/PREP7
ET,1,PLANE55,,,1
MP,KXX,1,3
N,1,.1875
N,41,.625
FILL
NGEN,2,100,1,41,1,,.1
E,1,2,102,101
EGEN,40,1,1
/SOLU
ANTYPE,STATIC
D,1,TEMP,{t_in},,101,100
D,41,TEMP,0,,141,100
SOLVE
FINISH
/PREP7
ETCHG,TTS
KEYOPT,1,1,{keyopt1}
KEYOPT,1,3,1
MP,EX,1,30E6
MP,ALPX,1,1.435E-5
MP,NUXY,1,.3
CPNGEN,1,UY,101,141
*DO,I,1,41
CP,NEXT,UX,I,I+100
*ENDDO
FINISH
/SOLU
ANTYPE,STATIC
D,1,UY,,,41
LDREAD,TEMP
SOLVE
FINISH
/POST1
*GET,HOOP_IN,NODE,1,S,Z
*GET,AXIAL_IN,NODE,1,S,Y
*GET,HOOP_OUT,NODE,41,S,Z
"""


@pytest.mark.parametrize("keyopt1, rel", [(2, 0.015), (0, 0.06)])
def test_long_cylinder_thermal_stress_on_quads(keyopt1, rel):
    """Timoshenko (Strength of Materials II, p. 234; VM32): a long cylinder, a = 0.1875,
    b = 0.625 in, T = −1 at a, 0 at b (steady, ln r profile), free ends (UY coupled):
    σθ(a) = σz(a) = Eα/(2(1−ν) ln(b/a)) · T(a) · (1 − 2b²/(b²−a²) ln(b/a)) = 420.42 psi.
    40 bilinear quads: enhanced strain (KEYOPT(1)=2) within 1.5 %, B-bar (KEYOPT(1)=0)
    within 6 % (−4.4 %: the corner stress converges as O(h))."""
    a, b, E, alpha, nu = 0.1875, 0.625, 30e6, 1.435e-5, 0.3
    ln = math.log(b / a)
    exact = E * alpha / (2 * (1 - nu) * ln) * (-1.0) * (1 - 2 * b**2 / (b**2 - a**2) * ln)
    assert exact == pytest.approx(420.42, abs=0.01)
    s = run(LONG_CYLINDER.format(t_in=-1, keyopt1=keyopt1))
    assert s.params["HOOP_IN"] == pytest.approx(exact, rel=rel)
    assert s.params["AXIAL_IN"] == pytest.approx(exact, rel=rel)
    uniform = run(LONG_CYLINDER.format(t_in=5, keyopt1=keyopt1).replace(
        "D,41,TEMP,0,,141,100", "D,41,TEMP,5,,141,100"))
    assert abs(uniform.params["HOOP_IN"]) < 1e-6 * E * alpha * 5  # free expansion: no stress


def thick_cylinder_deck(nr: int, nz: int, keyopt1: int, nu: float = 0.3,
                        distort: float = 0.0) -> str:
    """VM32's cylinder (a = 0.1875, b = 0.625 in, T = −1 at a, 0 at b) on nr × nz PLANE55
    quads, then PLANE182 (KEYOPT(1) given) in generalised plane strain: UY held at z = 0
    and coupled on the top row.  distort shifts the interior nodes radially by ± that
    fraction of the local spacing, alternately (trapezoids)."""
    r = np.linspace(0.1875, 0.625, nr + 1)
    lines = ["/PREP7", "ET,1,PLANE55,,,1", "MP,KXX,1,3"]
    for j in range(nz + 1):
        for i in range(nr + 1):
            x = float(r[i])
            if 0 < i < nr and 0 < j < nz:
                x += distort * float(r[i + 1] - r[i - 1]) / 2 * (1 if (i + j) % 2 else -1)
            lines.append(f"N,{1000 * j + i + 1},{x!r},{0.1 * j / nz!r}")
    lines += [f"E,{n},{n + 1},{n + 1001},{n + 1000}"
              for j in range(nz) for i in range(nr) for n in [1000 * j + i + 1]]
    lines += ["/SOLU", f"D,1,TEMP,-1,,{1000 * nz + 1},1000",
              f"D,{nr + 1},TEMP,0,,{1000 * nz + nr + 1},1000", "SOLVE", "FINISH",
              "/PREP7", "ETCHG,TTS", f"KEYOPT,1,1,{keyopt1}", "KEYOPT,1,3,1", "MP,EX,1,30E6",
              "MP,ALPX,1,1.435E-5", f"MP,NUXY,1,{nu}",
              f"CPNGEN,1,UY,{1000 * nz + 1},{1000 * nz + nr + 1}", "FINISH", "/SOLU",
              f"D,1,UY,,,{nr + 1}", "LDREAD,TEMP", "SOLVE", "FINISH", "/POST1",
              "*GET,U_IN,NODE,1,U,X", "*GET,HOOP_IN,NODE,1,S,Z", "*GET,AXIAL_IN,NODE,1,S,Y"]
    return "\n".join(lines) + "\n"


def thick_cylinder_exact(nu: float) -> tuple[float, float]:
    """Timoshenko's bore stress σθ(a) = σz(a) (psi) and the bore's radial displacement
    u(a) = a (σθ(1 − ν)/E + α T(a)) (in; σr(a) = 0) for `thick_cylinder_deck`."""
    a, b, E, alpha, t_a = 0.1875, 0.625, 30e6, 1.435e-5, -1.0
    ln = math.log(b / a)
    stress = E * alpha * t_a / (2 * (1 - nu) * ln) * (1 - 2 * b**2 / (b**2 - a**2) * ln)
    return stress, a * (stress * (1 - nu) / E + alpha * t_a)


@pytest.mark.parametrize("keyopt1, worst_stress", [(2, 0.01), (0, 0.03)])
def test_plane182_thick_cylinder_converges_at_the_element_rates(keyopt1, worst_stress):
    """VM32's cylinder on 16, 32, 64 uniform PLANE182 quads (enhanced strain, B-bar):
    the bore displacement converges as O(h²) and the nodal stresses extrapolated to the
    bore corner as O(h) (halving h divides their error by about 4 and 2), toward the
    closed form.  (Measured: enhanced strain +0.32/+0.08 % displacement, +1.36/+0.73 %
    axial stress at 32/64 elements; B-bar +0.07/+0.02 %, −5.4/−2.8 %.)"""
    stress, u_bore = thick_cylinder_exact(0.3)
    err = {}
    for nr in (16, 32, 64):
        p = run(thick_cylinder_deck(nr, 1, keyopt1)).params
        err[nr] = np.array([p["U_IN"] / u_bore, p["HOOP_IN"] / stress,
                            p["AXIAL_IN"] / stress]) - 1.0
    u_rate = err[32][0] / err[64][0]
    s_rates = err[32][1:] / err[64][1:]
    assert 3.5 < u_rate < 4.5, err
    assert np.all((1.7 < s_rates) & (s_rates < 2.3)), err
    assert np.all(np.abs(err[64][1:]) < worst_stress), err


@pytest.mark.parametrize("keyopt1, bound", [(2, 0.1), (0, 0.05), (3, None)])
def test_plane182_keyopt1_volumetric_locking_on_a_distorted_mesh(keyopt1, bound):
    """ν = 0.4999 on a distorted 16 × 8 mesh of VM32's cylinder: the bore displacement
    (independent of ν) is within 10 % with enhanced strain (KEYOPT(1) = 2: its fifth,
    volumetric mode, the hoop strain ξη) and within 5 % with B-bar (0), and refining to
    32 × 16 halves that and brings the bore stresses within 6 % (measured +2.7 %,
    −4.2 %); with the four shear modes alone (3, "to prevent shear locking"
    only, as MAPDL documents) the element locks: the bore moves several times too far
    (measured 3.6×)."""
    stress, u_bore = thick_cylinder_exact(0.4999)
    ratio = run(thick_cylinder_deck(16, 8, keyopt1, 0.4999, 0.3)).params["U_IN"] / u_bore
    if bound is None:
        assert ratio > 2.0
        return
    assert abs(ratio - 1.0) < bound
    finer = run(thick_cylinder_deck(32, 16, keyopt1, 0.4999, 0.3)).params
    assert abs(finer["U_IN"] / u_bore - 1.0) < 0.5 * abs(ratio - 1.0)
    # the bore stresses too (B-bar averages the thermal dilatation with the total one: a
    # pointwise thermal one against the averaged total one made them ~100 times too big)
    for name in ("HOOP_IN", "AXIAL_IN"):
        assert finer[name] == pytest.approx(stress, rel=0.06), name


def wall_end_C(t0: float, tb: float, h: float, length: float = 0.1, k: float = 20.0) -> float:
    """Planar wall, T0 at x = 0, film h to T_b at x = L, conduction k in series with the
    film: T(L) = T_b + (T0 − T_b)/(1 + hL/k)."""
    return tb + (t0 - tb) / (1.0 + h * length / k)


def convecting_slab(size: float, types: str, surface: str) -> str:
    """/PREP7 of the slab 0..0.1 × 0..0.05 (k = 20, element size `size`) meshed by AMESH;
    `surface` runs with the nodes at x = 0.1 selected, the element `types` come first."""
    return f"""
/PREP7
{types}
MP,KXX,1,20
RECTNG,0,0.1,0,0.05
ESIZE,{size}
AMESH,1
NSEL,S,LOC,X,0.1
{surface}
"""


def test_surf151_convection_matches_the_one_dimensional_wall():
    """A slab 0.1 m long, T = 100 at x = 0, SURF151 elements (ESURF) at x = 0.1 carrying
    SFE convection h = 50, T_bulk = 20; k = 20: T(L) = T_b + (T_0 − T_b)/(1 + hL/k) = 84."""
    s = run(convecting_slab(0.01, "ET,1,PLANE55\nET,2,SURF151", "ESLN,S,0\nTYPE,2\nESURF") + """
ALLSEL
/SOLU
NSEL,S,LOC,X,0
D,ALL,TEMP,100
ALLSEL
ESEL,S,TYPE,,2
SFE,ALL,1,CONV,1,50
SFE,ALL,1,CONV,2,20
ALLSEL
SOLVE
*GET,T_END,NODE,NODE(0.1,0,0),TEMP
""")
    assert s.params["T_END"] == pytest.approx(wall_end_C(100.0, 20.0, 50.0), rel=1e-9)


@pytest.mark.parametrize("quadratic", [False, True])
def test_bfa_heat_leaves_through_the_surf151_films_etable_ssum(quadratic):
    """BFA heats the slab's area (q̇ W/m³), SURF151 films carry it away at x = 0.1 (h, T_b),
    every other side insulated.  Steady: the films' heat rates (ETABLE,,SMISC,2; SSUM) add
    up to q̇ · area (unit thickness), and the 1-D wall gives T(L) = T_b + q̇ L / h."""
    qdot, h, tb, length = 2e5, 80.0, 20.0, 0.1
    solid = "PLANE77" if quadratic else "PLANE55"
    s = run(convecting_slab(0.01, f"ET,1,{solid}\nET,2,SURF151",
                            "ESLN,S,0\nTYPE,2\nESURF") + f"""
ALLSEL
BFA,1,HGEN,{qdot}
/SOLU
ESEL,S,TYPE,,2
SFE,ALL,1,CONV,1,{h}
SFE,ALL,1,CONV,2,{tb}
ALLSEL
SOLVE
FINISH
/POST1
*GET,T_END,NODE,NODE(0.1,0,0),TEMP
{film_heat_sum("Q")}
""")
    p = s.params
    assert p["Q"] == pytest.approx(qdot * length * 0.05, rel=1e-9)
    assert p["T_END"] == pytest.approx(tb + qdot * length / h, rel=1e-9)


def test_lswrite_lssolve_solves_each_written_load_step():
    """Two load steps written with LSWRITE and solved by LSSOLVE: a slab with T_0 at x = 0
    and convection h = 50, T_b = 20 at x = L: T(L) = T_b + (T_0 − T_b)/(1 + hL/k)."""
    s = run(convecting_slab(0.025, "ET,1,PLANE55", "SF,ALL,CONV,50,20") + """
NSEL,S,LOC,X,0
D,ALL,TEMP,100
ALLSEL
LSWRITE,1
NSEL,S,LOC,X,0
D,ALL,TEMP,200
ALLSEL
LSWRITE,2
FINISH
/SOLU
LSSOLVE,1,2
FINISH
/POST1
SET,1
*GET,T_ONE,NODE,NODE(0.1,0,0),TEMP
SET,2
*GET,T_TWO,NODE,NODE(0.1,0,0),TEMP
""")
    for t0, name in ((100.0, "T_ONE"), (200.0, "T_TWO")):
        assert s.params[name] == pytest.approx(wall_end_C(t0, 20.0, 50.0), rel=1e-9)


@pytest.mark.parametrize("technology", ["bbar", "enhanced", "enhanced_shear"])
@pytest.mark.parametrize("mode", ["axisymmetric", "plane_strain", "plane_stress"])
def test_plane182_quad_passes_the_patch_test_when_distorted(mode, technology):
    """Patch test (Taylor, Simo & Zienkiewicz): a linear displacement field u = 1e-3 r,
    v = 2e-3 z on a distorted PLANE182 quad must give the exact uniform stress σ = D ε,
    with ε = (1e-3, 2e-3, 1e-3 (hoop u/r; 0 in plane strain), 0), whatever KEYOPT(1) picks.
    The enhanced strains must not pick up energy from it: in an axisymmetric ring they are
    scaled by the centre's r·detJ over the point's (an element scaled by detJ alone was
    off by 30 % here); B-bar replaces the dilatation by its mean, which a uniform strain
    leaves unchanged."""
    from apdl_like.plane_elastic import elasticity_matrix, plane182_quads

    xy = np.array([[[1.0, 0.0], [2.2, 0.1], [2.0, 1.3], [1.1, 0.9]]])
    E, nu = 2e5, 0.3
    u_e = np.concatenate([1e-3 * xy[0, :, 0], 2e-3 * xy[0, :, 1]])[None]
    _, _, recover = plane182_quads(xy, mode, np.array([E]), np.array([nu]), np.zeros((1, 4)),
                                   technology)
    hoop = 1e-3 if mode == "axisymmetric" else 0.0
    exact = elasticity_matrix(np.array(E), np.array(nu), mode) @ np.array(
        [1e-3, 2e-3, hoop, 0.0])
    if mode == "plane_stress":
        exact[2] = 0.0
    np.testing.assert_allclose(recover(u_e)[:, 0, :], np.repeat(exact[:, None], 4, axis=1),
                               atol=1e-9 * E)


SOLID_MODEL_SLAB = """
/PREP7
ET,1,PLANE55
MP,KXX,1,{k}
K,1,0,0
K,2,{length},0
K,3,{length},{height}
K,4,0,{height}
L,1,2
L,2,3
L,3,4
L,4,1
AL,1,2,3,4
ESIZE,{size}
AMESH,1
/SOLU
{left}
{right}
ALLSEL
SOLVE
*GET,T_END,NODE,NODE({length},{height}/2),TEMP
*GET,T_MID,NODE,NODE(0.4*{length},0),TEMP
"""


@pytest.mark.parametrize("left, right", [
    ("DL,4,,TEMP,{t0}", "SFL,2,CONV,{h},,{tb}"),
    ("LSEL,S,LOC,X,0\nDL,ALL,,TEMP,{t0}", "LSEL,S,LOC,X,{length}\nSFL,ALL,CONV,{h},,{tb}"),
    ("LSEL,S,LINE,,4\nDL,ALL,,TEMP,{t0}",
     "LSEL,S,LOC,Y,0,1\nLSEL,R,LOC,X,0.09,1\nSFL,ALL,CONV,{h},,{tb}"),
    # the same values from tables (%NAME%) of one row, their value at every TIME
    ("*DIM,TT,TABLE,1,1,1,TIME\nTT(1,1) = {t0}\nDL,4,,TEMP,%TT%",
     "*DIM,TH,TABLE,1,1,1,TIME\nTH(1,1) = {h}\n*DIM,TB,TABLE,1,1,1,TIME\nTB(1,1) = {tb}\n"
     "SFL,2,CONV,%TH%,,%TB%"),
])
def test_solid_model_loads_dl_and_sfl_on_a_convecting_slab(left, right):
    """Planar slab (k, length L), DL: T0 on the line x = 0, SFL: film h to T_b on the line
    x = L, the other lines insulated: 1-D conduction in series with the film,
    q = (T0 − T_b)/(L/k + 1/h), T(L) = T_b + q/h, T linear in x (bilinear quads are exact)."""
    k, length, h, t0, tb = 20.0, 0.1, 400.0, 100.0, 20.0
    values = dict(k=k, length=length, h=h, t0=t0, tb=tb)
    s = run(SOLID_MODEL_SLAB.format(height=0.04, size=0.01, left=left.format(**values),
                                    right=right.format(**values), **values))
    t_end = wall_end_C(t0, tb, h, length, k)
    assert s.params["T_END"] == pytest.approx(t_end, rel=1e-9)
    assert s.params["T_MID"] == pytest.approx(t0 + 0.4 * (t_end - t0), rel=1e-9)


@pytest.mark.parametrize("right", ["DK,2,TEMP,10\nDK,3,TEMP,10",
                                   "KSEL,S,LOC,X,0.1\nDK,ALL,TEMP,10"])
def test_solid_model_loads_dk_fixes_the_node_on_a_keypoint(right):
    """One row of elements (ESIZE = height): the right edge has only the nodes on keypoints
    2 and 3, so DK there is a fixed end and T falls linearly from T0 to T1."""
    s = run(SOLID_MODEL_SLAB.format(k=20.0, length=0.1, height=0.02, size=0.02,
                                    left="DL,4,,TEMP,100", right=right))
    assert s.params["T_END"] == pytest.approx(10.0, rel=1e-12)
    assert s.params["T_MID"] == pytest.approx(100.0 - 0.4 * 90.0, rel=1e-9)


@pytest.mark.parametrize("deck, message", [
    ("/PREP7\nK,1,0,0\nK,2,1,0\nL,1,2\n/SOLU\nDL,1,,TEMP,5\n", "line 1 has no nodes"),
    ("/PREP7\n/SOLU\nDL,ALL,,TEMP,5\n", "no line is selected"),
    ("/PREP7\nK,1,0,0\nK,2,1,0\nL,1,2\nLSEL,S,LOC,X,2,3\nDL,ALL,,TEMP,5\n",
     "no line is selected"),
    ("/PREP7\nK,1,0,0\n/SOLU\nDK,1,TEMP,5\n", "keypoint 1 has no node"),
    ("/PREP7\n/SOLU\nSFL,3,CONV,10,,20\n", "line 3 does not exist"),
])
def test_solid_model_loads_refuse_what_they_cannot_transfer(deck, message):
    with pytest.raises(ApdlError, match=message):
        run(deck)


def test_fsum_heat_of_selected_elements_and_nodes():
    """FSUM sums the element nodal heat flows of the selected elements at the selected nodes,
    positive into the model (MAPDL's sign: VM99's fin reports -HEAT at its wall, VM100's
    chimney +HEAT through its heated film).  A ring heated by a film at RI and held at RO:
    the film element, the held element at the held nodes and the whole model all carry the
    ring's heat flow Q = ΔT / (R_film + R_wall)."""
    n, h, t_bulk, t_outer = 20, 400.0, 200.0, 20.0
    s = run(ring_model(ring_nodes_elements(n, "PLANE55")) + f"""
FINISH
/SOLU
NSEL,S,LOC,X,RI
SF,ALL,CONV,{h},{t_bulk}
NSEL,S,LOC,X,RO
D,ALL,TEMP,{t_outer}
ALLSEL
SOLVE
FINISH
/POST1
FSUM
*GET,Q_ALL,FSUM,,ITEM,HEAT
ESEL,S,ELEM,,1
FSUM
*GET,Q_FILM,FSUM,,ITEM,HEAT
ESEL,S,ELEM,,{n}
NSEL,S,LOC,X,RO
FSUM
*GET,Q_HELD,FSUM,,ITEM,HEAT
NSEL,S,LOC,X,RI
FSUM
*GET,Q_NONE,FSUM,,ITEM,HEAT
""")
    area_in = 2 * math.pi * RI * H
    q = (t_bulk - t_outer) / (1 / (h * area_in) + math.log(RO / RI) / (2 * math.pi * K * H))
    p = s.params
    for name in ("Q_ALL", "Q_FILM", "Q_HELD"):
        assert p[name] == pytest.approx(q, rel=2e-3), name
    assert p["Q_NONE"] == 0.0  # the selected element has no selected node


def test_enthalpy_table_melts_an_insulated_block_and_set_reads_between_times():
    """MPDATA,ENTH replaces DENS·C: with uniform HGEN q the insulated block's enthalpy
    rises as H(T) = H(T0) + q t.  H: 4.2 MJ/m³K below -1 °C and above 0 °C, a 42 MJ/m³
    latent step between; from -5 °C at q = 4.2 MW/m³: -1 °C at 4 s, 0 °C at 14 s, 6 °C at
    20 s (1 s steps land on the breakpoints, so backward Euler is exact).  SET,,,,,TIME
    between stored times interpolates linearly (MAPDL's rule): -0.45 °C at 9.5 s."""
    s = run("""
/PREP7
ET,1,PLANE55
MP,KXX,1,0.6
MPTEMP,1,-10,-1,0,10
MPDATA,ENTH,1,1,0,37.8E6,79.8E6,121.8E6
RECTNG,0,0.01,0,0.002
ESIZE,0.001
AMESH,ALL
/SOLU
ANTYPE,TRANS
TUNIF,-5
BFE,ALL,HGEN,,4.2E6
KBC,1
TIME,20
DELTIM,1
SOLVE
FINISH
/POST1
*GET,T_END,NODE,1,TEMP
SET,,,,,4
*GET,T_4,NODE,1,TEMP
SET,,,,,9.5
*GET,T_9H,NODE,NODE(0.01,0.002),TEMP
SET,,,,,14
*GET,T_14,NODE,1,TEMP
SET,LAST
*GET,T_LAST,NODE,1,TEMP
""")
    p = s.params
    assert p["T_4"] == pytest.approx(-1.0, abs=1e-9)
    assert p["T_9H"] == pytest.approx(-0.45, abs=1e-9)
    assert p["T_14"] == pytest.approx(0.0, abs=1e-9)
    assert p["T_END"] == pytest.approx(6.0, abs=1e-9)
    assert p["T_LAST"] == p["T_END"]


@pytest.mark.parametrize("midside", [",5", ",5,6", ",5,6,7"])
def test_plane77_with_mid_side_nodes_left_out_holds_a_linear_field(midside):
    """MAPDL's E takes PLANE77 with any trailing mid-side nodes omitted (and ET its ninth
    field, INOPR).  A 1×1 planar square held at 0 °C on x = 0 and 100 °C on x = 1 conducts
    linearly: T = 100 x at every node, whichever mid-side nodes exist."""
    s = run(f"""/PREP7
ET,1,PLANE77,,,0,,,,1
MP,KXX,1,3
N,1,0,0
N,2,1,0
N,3,1,1
N,4,0,1
N,5,0.5,0
N,6,1,0.5
N,7,0.5,1
N,8,0,0.5
E,1,2,3,4{midside}
{held_faces("X", (0, 0), (1, 100))}
FINISH
/SOLU
SOLVE
FINISH
/POST1
*GET,T5,NODE,5,TEMP
*GET,T3,NODE,3,TEMP
""")
    assert s.params["T5"] == pytest.approx(50.0, abs=1e-9)
    assert s.params["T3"] == pytest.approx(100.0, abs=1e-9)


def test_line_in_csys1_is_an_arc_and_amesh_follows_it():
    """L in CSYS 1 between keypoints of one radius is MAPDL's circular arc: a 30° sector
    of a wire (radius R, k, generating q̇) meshed free, its arc coupled (CP) and cooled by
    SURF151 films (h, T_b): T_s = T_b + q̇R/(2h), the centre T_s + q̇R²/(4k), and the
    films take out q̇ × the sector's area πR²/12 (per unit thickness)."""
    r, k, qdot, h, tb = 0.05, 20.0, 1e6, 100.0, 20.0
    s = run(f"""/PREP7
ET,1,PLANE35
ET,2,SURF151
MP,KXX,1,{k}
CSYS,1
K,1
K,2,{r},-15
K,3,{r},15
L,2,3
CSYS
A,1,2,3
AMESH,1
CSYS,1
NSEL,S,LOC,X,{r}
*GET,N_ARC,NODE,,NUM,COUNT
CP,1,TEMP,ALL
TYPE,2
ESURF
NSEL,ALL
ESEL,S,TYPE,,2
SFE,ALL,,CONV,,{h}
SFE,ALL,,CONV,2,{tb}
ESEL,ALL
BFA,1,HGEN,{qdot}
FINISH
/SOLU
SOLVE
FINISH
/POST1
*GET,T_C,NODE,1,TEMP
*GET,T_S,NODE,2,TEMP
{film_heat_sum("Q")}
""")
    p = s.params
    t_s = tb + qdot * r / (2 * h)
    assert p["N_ARC"] >= 5  # the nodes gmsh placed along the arc lie on radius R
    # the elements' straight edges between arc nodes (length ℓ ≈ R/10) cut off a
    # fraction ≈ (ℓ/R)²/6 of the area: the rises and the heat are within 3e-3
    assert p["T_S"] - tb == pytest.approx(t_s - tb, rel=3e-3)
    assert p["T_C"] - tb == pytest.approx(t_s - tb + qdot * r**2 / (4 * k), rel=3e-3)
    assert p["Q"] == pytest.approx(qdot * math.pi * r**2 / 12, rel=3e-3)


TWO_BLOCKS = """/PREP7
ET,1,PLANE77
MP,KXX,1,{k1}
MP,KXX,2,{k2}
K,1,0,0
K,2,1,0
KGEN,2,1,2,1,0,0.5
L,1,2
L,2,4
L,4,3
L,3,1
AL,1,2,3,4
LESIZE,1,,,4
LESIZE,3,,,4
LESIZE,2,,,2
LESIZE,4,,,2
MAT,1
AMESH,1
*GET,NE_MAPPED,ELEM,0,COUNT
N,1001,1,0
N,1005,2,0
FILL
NGEN,3,10,1001,1005,1,,0.25
MAT,2
E,1001,1002,1012,1011
*REPEAT,4,1,1,1,1
EGEN,2,10,-4
EMID
*GET,NE,ELEM,0,COUNT
NSEL,S,LOC,X,1
*GET,N_FACE,NODE,0,COUNT
ALLSEL
{join}
{held}
{solve}
T_FACE=TEMP(NODE(1,0.25,0))
T_MID2=TEMP(NODE(1.5,0.25,0))
T_MID1=TEMP(NODE(0.5,0.25,0))
"""


@pytest.mark.parametrize("join", ["CPINTF,TEMP", "NUMMRG,NODE"])
def test_two_blocks_built_two_ways_and_joined_conduct_in_series(join):
    """Block 1 (0 ≤ x ≤ 1, k1) from K/KGEN/L/AL/LESIZE and a mapped AMESH of PLANE77; block
    2 (1 ≤ x ≤ 2, k2) from N/FILL/NGEN/E/*REPEAT/EGEN with EMID's mid-side nodes; the
    coincident nodes at x = 1 joined by CPINTF (coupled sets) or NUMMRG (merged).  Held at
    T_hot and 0: one flux through resistances 1/k1 + 1/k2, T_face = T_hot·(1/k2)/(1/k1 + 1/k2),
    linear within each block (exact for quadratic elements)."""
    k1, k2, t_hot = 1.0, 3.0, 100.0
    s = run(TWO_BLOCKS.format(k1=k1, k2=k2, join=join, solve=SOLVE_THEN_POST,
                              held=held_faces("X", (0, t_hot), (2, 0))))
    p = s.params
    assert (p["NE_MAPPED"], p["NE"]) == (8, 16)  # 4 × 2 mapped quads, then 4 × 2 by E/EGEN
    assert p["N_FACE"] == 10  # 3 corner + 2 mid-side nodes on each side of x = 1
    t_face = t_hot * (1 / k2) / (1 / k1 + 1 / k2)
    assert p["T_FACE"] == pytest.approx(t_face, rel=1e-9)
    assert p["T_MID1"] == pytest.approx(0.5 * (t_hot + t_face), rel=1e-9)
    assert p["T_MID2"] == pytest.approx(0.5 * t_face, rel=1e-9)


def test_cpsgen_copies_a_coupled_set_to_the_next_node_pair():
    """Two PLANE55 strips, x 0..1 (nodes 1-3, 11-13) and 1..2 (101-103, 111-113), touching at
    x = 1: CP couples 3 with 101, CPSGEN,2,10 the copy 13 with 111; in series the face sits
    at T_hot·(1/k2)/(1/k1 + 1/k2)."""
    k1, k2, t_hot = 2.0, 1.0, 60.0
    s = run(f"""/PREP7
ET,1,PLANE55
MP,KXX,1,{k1}
MP,KXX,2,{k2}
N,1,0,0
N,3,1,0
FILL
N,101,1,0
N,103,2,0
FILL
NGEN,2,10,1,3,1,,1
NGEN,2,10,101,103,1,,1
MAT,1
E,1,2,12,11
EGEN,2,1,-1
MAT,2
E,101,102,112,111
EGEN,2,1,-1
CP,1,TEMP,3,101
CPSGEN,2,10,1
{held_faces("X", (0, t_hot), (2, 0))}
{SOLVE_THEN_POST}
*GET,T3,NODE,3,TEMP
*GET,T111,NODE,111,TEMP
""")
    t_face = t_hot * (1 / k2) / (1 / k1 + 1 / k2)
    assert s.params["T3"] == pytest.approx(t_face, rel=1e-9)
    assert s.params["T111"] == pytest.approx(t_face, rel=1e-9)


@pytest.mark.parametrize("element", ["PLANE35", "PLANE55\nMSHAPE,1", "PLANE55",
                                     "PLANE77\nMSHAPE,1", "PLANE77", "PLANE55,,,1",
                                     "PLANE77,,,1"])
def test_wall_held_and_cooled_by_surf151_films_every_element_kind(element):
    """A wall 0.5 ≤ x ≤ 1.5 (height 0.5, k = 2) held at 100 at x = 0.5 and cooled at
    x = 1.5 by SURF151 films (h = 10, T_b = 0), meshed as native quads, degenerate
    triangles (MSHAPE,1) and 6-node triangles, planar or axisymmetric (KEYOPT(3) = 1):
    the heat Q = ΔT / (R_wall + R_film) (planar per unit thickness: R = L/(kA) + 1/(hA);
    axisymmetric R = ln(ro/ri)/(2πkH) + 1/(h 2π ro H)) is what FSUM finds at the held
    nodes over every element (the films' SURF151 included) and what the films take out
    (ETABLE SMISC 2, SSUM); the film face sits at T_b + Q/(hA)."""
    k, h, t_held, ri, ro, height = 2.0, 10.0, 100.0, 0.5, 1.5, 0.5
    s = run(f"""/PREP7
ET,1,{element}
MP,KXX,1,{k}
RECTNG,{ri},{ro},0,{height}
ESIZE,0.1
AMESH,1
ET,2,SURF151
TYPE,2
NSEL,S,LOC,X,{ro}
ESURF
ESEL,S,TYPE,,2
SFE,ALL,,CONV,,{h}
SFE,ALL,,CONV,2,0
ALLSEL
NSEL,S,LOC,X,{ri}
D,ALL,TEMP,{t_held}
ALLSEL
/SOLU
SOLVE
FINISH
/POST1
*GET,T_S,NODE,NODE({ro},{height / 2},0),TEMP
NSEL,S,LOC,X,{ri}
FSUM
*GET,Q_HELD,FSUM,0,ITEM,HEAT
ALLSEL
ESEL,S,TYPE,,2
ETABLE,HF,SMISC,2
SSUM
*GET,Q_FILM,SSUM,,ITEM,HF
""")
    if element.endswith(",,,1"):
        area_out = 2 * math.pi * ro * height
        r_wall = math.log(ro / ri) / (2 * math.pi * k * height)
    else:
        area_out = height
        r_wall = (ro - ri) / (k * height)
    q = t_held / (r_wall + 1 / (h * area_out))
    p = s.params
    # planar: linear in x, exact; axisymmetric: ln r on 10 elements, within 0.2 %
    assert p["Q_FILM"] == pytest.approx(q, rel=2e-3)
    assert p["Q_HELD"] == pytest.approx(-q, rel=2e-3)  # MAPDL's sign: the held wall feeds it
    assert p["T_S"] == pytest.approx(q / (h * area_out), rel=2e-3)


def test_set_by_time_reads_substeps_of_every_load_step():
    """A 1 × 1 plate (k = 1000: Biot ≈ 0) cooled toward 100 by films h = 1 on its 4 sides,
    ρc = 1: T = 100 (1 − e^(−t/τ)), τ = ρc A/(h P) = 0.25 s.  Solved as two load steps
    (to 1 s and 2 s, OUTRES,ALL), SET,,,,,TIME inside the first reads its substeps (MAPDL
    keeps them in the results file), *GET ACTIVE SET TIME/LSTP name the set SET read."""
    s = run("""/PREP7
ET,1,PLANE55
MP,KXX,1,1000
MP,DENS,1,1
MP,C,1,1
N,1
N,2,1
N,3,1,1
N,4,0,1
E,1,2,3,4
SF,ALL,CONV,1,100
IC,ALL,TEMP,0
FINISH
/SOLU
ANTYPE,TRANS
KBC,1
TIME,1
DELTIM,0.001
OUTRES,ALL,ALL
SOLVE
TIME,2
SOLVE
FINISH
/POST1
SET,,,,,0.5
*GET,T_HALF,NODE,1,TEMP
SET,,,,,1.5
*GET,T_ONE_HALF,NODE,1,TEMP
SET,FIRST
*GET,T_ONE,NODE,1,TEMP
*GET,TIME_FIRST,ACTIVE,0,SET,TIME
SET,LAST
*GET,STEP_LAST,ACTIVE,0,SET,LSTP
""")
    p = s.params
    for name, t in (("T_HALF", 0.5), ("T_ONE", 1.0), ("T_ONE_HALF", 1.5)):
        # backward Euler at Δt = τ/250 is within 0.1 % of the exponential
        assert p[name] == pytest.approx(100 * (1 - math.exp(-t / 0.25)), rel=1e-3), name
    assert (p["TIME_FIRST"], p["STEP_LAST"]) == (1.0, 2.0)


# PLANE55 with k = 1 and the keypoints 1-4 of the unit square, counter-clockwise from 0,0
UNIT_SQUARE_KEYPOINTS = "/PREP7\nET,1,PLANE55\nMP,KXX,1,1\nK,1,0,0\nK,2,1,0\nK,3,1,1\nK,4,0,1"


def joint_then_solve(axis: str, joint_point: str) -> str:
    """Deck lines for two parts joined at `axis` = 1 and held at 100 (axis = 0) and 0
    (axis = 2): N_JOINT nodes on the joint, the heat Q at the held-hot nodes (FSUM) and
    T_JOINT at the joint node nearest `joint_point` ("x,y")."""
    return f"""NSEL,S,LOC,{axis},1
*GET,N_JOINT,NODE,0,COUNT
ALLSEL
{held_faces(axis, (0, 100), (2, 0))}
{SOLVE_THEN_POST}
NSEL,S,LOC,{axis},0
FSUM
*GET,Q,FSUM,0,ITEM,HEAT
ALLSEL
T_JOINT=TEMP(NODE({joint_point},0))"""


def test_mapped_mesh_gives_a_soft_side_the_hard_divisions_opposite():
    """Two unit squares stacked, each with its own keypoints at y = 1 (as VM163 builds its
    caisson): LESIZE 4 on both bottoms, ESIZE,,3 elsewhere.  As MAPDL does, the lower
    square's top (soft: ESIZE) takes its bottom's 4 divisions, so both map 4 × 3 and
    NUMMRG joins their nodes at y = 1 one to one; held at 100 and 0 the model is the 1-D
    wall: 50 at the interface, heat k ΔT w / L."""
    s = run(f"""{UNIT_SQUARE_KEYPOINTS}
K,5,0,1
K,6,1,1
K,7,1,2
K,8,0,2
L,1,2
L,5,6
LESIZE,ALL,,,4
A,1,2,3,4
A,5,6,7,8
ESIZE,,3
AMESH,ALL
*GET,N_ELEM,ELEM,0,COUNT
NUMMRG,NODE
{joint_then_solve("Y", "0.25,1")}
""")
    p = s.params
    assert p["N_ELEM"] == 24  # 4 × 3 mapped quads in each square
    assert p["N_JOINT"] == 5  # the squares share the 5 nodes of y = 1 (MAPDL: after NUMMRG)
    assert p["T_JOINT"] == pytest.approx(50.0, rel=1e-12)
    assert p["Q"] == pytest.approx(-50.0, rel=1e-12)


def test_etable_thermal_gradient_and_flux_at_element_centroids():
    """ETABLE TG and TF on two walls whose closed forms are known at every point.
    Orthotropic (KXX = 2, KYY = 5) triangles held 100/20 across y = 0..1: ∇T = (0, −80),
    flux (0, KYY·80) in every element.  k = 10 + 0.05 T (MP C1) quads held 100/20 across
    x = 0..2: the flux is the same everywhere, q = (U(100) − U(20))/L with the Kirchhoff
    transform U(T) = 10 T + 0.025 T²."""

    def wall(rectangle: str, axis: str, length: float) -> str:
        """The rectangle meshed at 0.25, held at 100 and 20 across `axis`, solved."""
        return (f"RECTNG,{rectangle}\nESIZE,0.25\nAMESH,1\n"
                f"{held_faces(axis, (0, 100), (length, 20))}\n{SOLVE_THEN_POST}")

    s = run(f"""/PREP7
ET,1,PLANE55
MP,KXX,1,2
MP,KYY,1,5
MSHAPE,1
{wall("0,1,0,1", "Y", 1)}
ETABLE,GY,TG,Y
ETABLE,GS,TG,SUM
ETABLE,FX,TF,X
ETABLE,FY,TF,Y
*GET,N_ELEM,ELEM,0,COUNT
SSUM
*GET,SUM_GY,SSUM,,ITEM,GY
*GET,SUM_GS,SSUM,,ITEM,GS
*GET,SUM_FX,SSUM,,ITEM,FX
*GET,SUM_FY,SSUM,,ITEM,FY
*GET,FY_1,ELEM,1,ETAB,FY
""")
    p = s.params
    n = p["N_ELEM"]
    assert p["FY_1"] == pytest.approx(-5 * -80.0, rel=1e-9)
    assert p["SUM_GY"] == pytest.approx(-80.0 * n, rel=1e-9)
    assert p["SUM_GS"] == pytest.approx(80.0 * n, rel=1e-9)
    assert p["SUM_FY"] == pytest.approx(400.0 * n, rel=1e-9)
    assert abs(p["SUM_FX"]) <= 1e-9 * 400.0 * n
    s = run(f"""/PREP7
ET,1,PLANE77
MP,KXX,1,10,0.05
{wall("0,2,0,0.5", "X", 2)}
ETABLE,FX,TF,X
*GET,F_FIRST,ELEM,1,ETAB,FX
*GET,F_LAST,ELEM,16,ETAB,FX
""")
    q = ((10 * 100 + 0.025 * 100**2) - (10 * 20 + 0.025 * 20**2)) / 2
    # quadratic quads of 0.25 across T(x) = (−10 + √(100 + 0.1 U(x)))/0.05: within 0.1 %
    assert s.params["F_FIRST"] == pytest.approx(q, rel=1e-3)
    assert s.params["F_LAST"] == pytest.approx(q, rel=1e-3)


def test_free_and_mapped_areas_share_the_nodes_of_their_common_line():
    """A square mapped (4 sides, LESIZE 7) beside a pentagon meshed free: MAPDL meshes
    their common line once, so both use its 8 nodes.  Held at 100 and 0 across the two the
    field is linear (T = 50 on the joint, heat k ΔT h / L = 50), which a mesh cracked along
    the joint (each area's own nodes there) cannot represent."""
    s = run(f"""{UNIT_SQUARE_KEYPOINTS}
K,5,1.5,0
K,6,2,0
K,7,2,1
A,1,2,3,4
A,2,5,6,7,3
LESIZE,ALL,,,7
AMESH,ALL
{joint_then_solve("X", "1,0.43")}
""")
    p = s.params
    assert p["N_JOINT"] == 8
    assert p["T_JOINT"] == pytest.approx(50.0, rel=1e-9)
    assert p["Q"] == pytest.approx(-50.0, rel=1e-9)
