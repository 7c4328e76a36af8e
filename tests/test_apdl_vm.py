"""MAPDL Verification Manual decks, run as published (tests/data/apdl_vm, MIT).

Each deck writes its own results table with /OUT,vmNN,vrt and *VWRITE: a label, the
published TARGET, the value apdl-like computed and their ratio.  Every computed value must
lie within 2 % of its target (a zero target: within 2 % of the table's largest target, as
tools/vm_check.py judges).
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from apdl_like.vrt import results_table as read_results_table

DECKS = Path(__file__).parent / "data" / "apdl_vm"
TOLERANCE = 0.02

# the decks that run as published, and the rows of their results tables
ROWS = {"vm102": 8, "vm105": 8, "vm28": 4, "vm98": 12, "vm113": 4, "vm99": 5, "vm227": 3,
        # thermal links and masses (LINK31/33/34, MASS71) and PLANE77 without mid-side nodes
        "vm92": 3, "vm93": 1, "vm94": 2, "vm106": 1, "vm107": 1, "vm109": 3, "vm112": 1,
        # a slab under a stepped gas temperature, Crank-Nicolson with AUTOTS from NSUBST,80
        "vm110": 7,
        "vm114": 6, "vm115": 6, "vm116": 1,
        # an arc line (L in CSYS 1), BFA, ETABLE/SSUM of SURF151 heat rates
        "vm58": 3,
        # mapped AMESH: a side with ESIZE's soft divisions takes the opposite side's LESIZE
        "vm163": 1}


def results_table(path: Path) -> list[tuple[str, float, float]]:
    return read_results_table(path.read_text())


@pytest.mark.parametrize("deck", sorted(ROWS))
def test_verification_deck_runs_as_published(deck, tmp_path):
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(DECKS / f"{deck}.dat"),
                           "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    rows = results_table(out / f"{deck}.vrt")
    assert len(rows) == ROWS[deck], rows
    # a zero target (VM114's far end) is met within 2 % of the table's largest target
    scale = max(abs(target) for _, target, _ in rows)
    for label, target, computed in rows:
        allowed = TOLERANCE * scale if target == 0.0 else 1e-9
        assert computed == pytest.approx(target, rel=TOLERANCE, abs=allowed), (deck, label)


def test_vm111_sphere_center_matches_the_exact_series_solution(tmp_path):
    """VM111's target (28 °F) is read from a Heisler chart; the exact series solution of the
    sphere (Bi = hR/k = 1, Fo = αt/R² = 1.08: λ1 = π/2, C1 = 4/π) gives 28.55 °F at the
    centre.  The published deck, run as is, must land within 0.5 % of that."""
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(DECKS / "vm111.dat"),
                           "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    (label, target, computed), = results_table(out / "vm111.vrt")
    lam, c1 = math.pi / 2, 4 / math.pi
    fourier = (1 / 3) / (62 * 1.0752677) * 6.0 / (1 / 6) ** 2
    exact = 25.0 + (65.0 - 25.0) * c1 * math.exp(-lam**2 * fourier)
    assert exact == pytest.approx(28.55, abs=0.01)
    assert computed == pytest.approx(exact, rel=0.005)


def _slab_modes(biot: float, terms: int = 60) -> tuple[np.ndarray, np.ndarray]:
    """(λn, Cn) of a slab insulated at x = 0 and cooled through Bi at x = 1 (x = position /
    thickness): λn tan λn = Bi, Cn = 4 sin λn/(2λn + sin 2λn)."""
    lam = np.array([brentq(lambda v: v * np.tan(v) - biot, k * np.pi + 1e-12,
                           k * np.pi + np.pi / 2 - 1e-12) for k in range(terms)])
    return lam, 4 * np.sin(lam) / (2 * lam + np.sin(2 * lam))


def _slab_series(biot: float, fourier: float, x: np.ndarray, terms: int = 60) -> np.ndarray:
    """θ/θ_i of that slab: Σ Cn exp(−λn² Fo) cos(λn x)."""
    lam, c = _slab_modes(biot, terms)
    return (c * np.exp(-lam**2 * fourier) * np.cos(np.outer(x, lam))).sum(axis=1)


def _slab_heat_taken(biot: float, fourier: float, terms: int = 60) -> float:
    """Q/Q0 of that slab, the heat it has taken over its capacity × initial difference:
    1 − Σ Cn sin λn/λn exp(−λn² Fo)."""
    lam, c = _slab_modes(biot, terms)
    return float(1.0 - (c * np.sin(lam) / lam * np.exp(-lam**2 * fourier)).sum())


def test_vm113_orthotropic_bar_matches_the_exact_product_solution(tmp_path):
    """VM113 (orthotropic bar 2 × 1 in, cooled on two faces, 3 s): the exact temperature is
    the product of two slab series (Bi = 2.0 along x, 5.55 along y).  Node 13's target,
    279 °F, is itself 2.2 % below that exact value (285.2), node 1's 0.7 % (462.2), which
    is why the deck's own table sits near its 2 % tolerance.  As published (6 × 5 quads) every
    node is within 2 % of the exact value (worst: node 7, the corner where both films meet,
    +1.8 %; it falls to 0.6 and 0.2 % on 12 × 10 and 24 × 20 meshes) and node 13 within
    0.5 %."""
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(DECKS / "vm113.dat"),
                           "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    params = json.loads((out / "params.json").read_text())
    kx, ky, rho_c, h, lx, ly, t = 20.0, 3.6036, 400 * 0.009009, 240.0, 2 / 12, 1 / 12, 3 / 3600
    nodes = {"TN1": (0.0, 0.0), "TN2": (0.0, ly), "TN7": (lx, ly), "TN13": (lx, 0.0)}
    for name, (x, y) in nodes.items():
        exact = 100.0 + 400.0 * (
            _slab_series(h * lx / kx, kx / rho_c * t / lx**2, np.array([x / lx]))[0]
            * _slab_series(h * ly / ky, ky / rho_c * t / ly**2, np.array([y / ly]))[0])
        assert params[name] == pytest.approx(exact, rel=0.02), name
        if name == "TN13":
            assert exact == pytest.approx(285.17, abs=0.01)
            assert params[name] == pytest.approx(exact, rel=0.005)


def test_vm110_slab_matches_the_exact_series_solution(tmp_path):
    """VM110's targets are chart readings (Kreith's Gröber charts).  The exact series of the
    slab (L = 1 ft insulated at x = 0, gas at 1600 °F through h = 5 at x = L, from 100 °F)
    gives the temperatures at t = 14.5 h and the heat the wall has taken,
    Q(t) = ρcL(T∞ − Ti)·(Q/Q0).  The deck integrates the film's heat rate over its stored
    substeps (POST26 INT1), which start at the first substep: AUTOTS takes NSUBST's
    14.5/80 h as that first substep, as MAPDL documents, so the integral is
    Q(14.5) − Q(14.5/80)."""
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(DECKS / "vm110.dat"),
                           "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    rows = results_table(out / "vm110.vrt")
    k, rho_c, h, t_in, t_gas, t_end = 0.54, 144 * 0.20, 5.0, 100.0, 1600.0, 14.5
    biot, alpha = h * 1.0 / k, k / rho_c
    x_ft = np.array([0.0, 0.2, 0.4, 0.6, 0.8, 1.0])  # nodes 1, 3, .., 11
    exact = t_gas + (t_in - t_gas) * _slab_series(biot, alpha * t_end, x_ft)
    for (label, _, computed), expected in zip(rows[:6], exact, strict=True):
        assert computed == pytest.approx(expected, rel=0.005), label
    heat = rho_c * (t_gas - t_in) * (_slab_heat_taken(biot, alpha * t_end)
                                     - _slab_heat_taken(biot, alpha * t_end / 80))
    (label, _, computed) = rows[6]
    assert -computed == pytest.approx(heat, rel=0.01), label


# MAPDL's own VM32 results table (Verification Manual, Release 2024 R2, VM32 "Results
# Comparison", the same deck): the inner axial and hoop stress ratios to Timoshenko's
# 420.42 psi, as printed (F15.3).  Read in a third-party summary of the manual's VM31-VM60
# pages; the outer rows' ratios were not in it.
VM32_MAPDL_RATIOS = {"A_STS psi X=.187": 1.029, "T_STS psi X=.187": 1.014}


def test_vm32_runs_as_published_and_reproduces_mapdls_published_stress_ratios(tmp_path):
    """VM32 (long cylinder): the thermal rows meet the 2 % target; the thermal-stress rows
    come within 3 % of Timoshenko's 420.42 / −194.58 psi (worst: the inner axial stress,
    432.6, +2.9 %), not 2 %, and the inner rows are MAPDL's own published ratios to the
    three decimals it prints (1.029 and 1.014): MAPDL misses 2 % on this deck too.  The 7
    axisymmetric PLANE182 quads run MAPDL's documented KEYOPT(1) = 2 element (Simo &
    Rifai's enhanced strains: four against shear locking, a fifth hoop mode ξη against
    volumetric locking; any mode in ξη is odd in z and stays zero in this problem,
    symmetric in each element), with the nodal stresses extrapolated from the 2 × 2 points
    (ERESX default).  Their corner stress converges as O(h): the coarse published mesh
    decides it (tests/test_apdl_verification.py checks the rates)."""
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(DECKS / "vm32.dat"),
                           "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    rows = results_table(out / "vm32.vrt")
    assert len(rows) == 7, rows
    for label, target, computed in rows[:3]:
        assert computed == pytest.approx(target, rel=TOLERANCE, abs=1e-9), label
    for label, target, computed in rows[3:]:
        assert computed == pytest.approx(target, rel=0.03), label
    ratios = {label: computed / target for label, target, computed in rows[3:]}
    for label, published in VM32_MAPDL_RATIOS.items():
        assert abs(ratios[label] - published) <= 0.0005, (label, ratios[label])


def _run_published(deck_text: str, tmp_path: Path) -> Path:
    """Run a (possibly edited) deck with apdl-like; its --out folder."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    deck, out = tmp_path / "deck.dat", tmp_path / "out"
    deck.write_text(deck_text)
    done = subprocess.run([sys.executable, "-m", "apdl_like", "run", str(deck), "--out",
                           str(out)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return out


VM100_ELEMENTS = "E,4,1,2,5\nE,3,6,5,2\nEGEN,2,3,1,2,1\n"


def test_vm100_targets_are_kreiths_finite_differences_which_triangles_reproduce(tmp_path):
    """VM100's targets are Kreith's finite-difference temperatures on the 0.5 ft grid (the
    five-point stencil, half cells with their film on the faces).  Linear triangles on a
    square grid with a diagonal film matrix are exactly that scheme: with each of the
    deck's squares split into two triangles, every node lands on its target to within
    0.07 °F (node 12: 11.76 against a printed 11.7).  The deck as published meshes the
    squares with PLANE55's bilinear quads, which couple a node to its diagonal neighbour
    too (2 × 2 Gauss points on a unit square: 2/3 on the diagonal, −1/6 along an edge,
    −1/3 across).  At node 11, between the two right triangles 11-7-8 and 12-15-11 and
    the square 8-9-12-11, that gives T11 = 0.4 T8 + 0.4 T12 + 0.2 T9 instead of the
    finite differences' (T8 + T12)/2: 27.6 °F against the 29.6 target (−6.9 %), and 17.3,
    12.5, 5.0 °F at nodes 9, 12, 15 (targets 18.3, 11.7, 4.7).  That is the element, not
    a defect: the deck cannot meet its 2 % on those four nodes."""
    published = (DECKS / "vm100.dat").read_text()
    assert VM100_ELEMENTS in published
    split = ("E,4,1,2,2\nE,4,2,5,5\nE,3,6,5,5\nE,3,5,2,2\nE,7,4,5,5\nE,7,5,8,8\n"
             "E,6,9,8,8\nE,6,8,5,5\n")
    nodes = (1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 15)  # the table's rows, unrounded
    post = "\n/POST1\n" + "".join(f"*GET,T{n},NODE,{n},TEMP\n" for n in nodes)
    out = _run_published(published.replace(VM100_ELEMENTS, split).replace(
        "E,9,12,11,8\n", "E,9,12,11,11\nE,9,11,8,8\n") + post, tmp_path / "split")
    p = json.loads((out / "params.json").read_text())
    rows = results_table(out / "vm100.vrt")
    for n, (label, target, _) in zip(nodes, rows, strict=False):
        assert p[f"T{n}"] == pytest.approx(target, abs=0.07), label
    out = _run_published(published + post, tmp_path / "quads")
    p = json.loads((out / "params.json").read_text())
    assert p["TN11"] == pytest.approx(0.4 * p["T8"] + 0.4 * p["TN12"] + 0.2 * p["T9"],
                                      rel=1e-9)
    assert p["TN11"] < 0.5 * (p["T8"] + p["TN12"]) - 1.0
    rows = results_table(out / "vm100.vrt")
    for label, target, computed in rows[:8] + rows[12:]:  # nodes 1..8 and the heat
        assert computed == pytest.approx(target, rel=TOLERANCE), label


def _neumann_freezing(x_m: np.ndarray, t_s: float, alpha: float, stefan: float,
                      t_wall: float, t_melt: float) -> np.ndarray:
    """Neumann's one-phase solidification of liquid at its melting point (a semi-infinite
    body, the face held at t_wall from t = 0): T = t_wall + (t_melt − t_wall)
    erf(x/2√(αt)) / erf λ in the solid, λ e^{λ²} erf λ = Ste/√π, Ste = ρc ΔT / ρL."""
    from scipy.special import erf

    lam = brentq(lambda v: v * np.exp(v * v) * erf(v) - stefan / math.sqrt(math.pi),
                 1e-9, 5.0)
    front = 2.0 * lam * math.sqrt(alpha * t_s)
    assert np.all(x_m < front)
    return t_wall + (t_melt - t_wall) * erf(x_m / (2 * math.sqrt(alpha * t_s))) / erf(lam)


VM104_TABLE = ("MPTEMP,1,-10,-1,0,10\n"
               "MPDATA,ENTH,1,1,0,37.8E6,79.8E6,121.8E6  ! ENTHALPY\n")


def test_vm104_targets_are_neumanns_solution_with_a_42_mj_latent_heat(tmp_path):
    """VM104 (water freezing from 0 °C, face at −5 °C, ρc = 4.2 MJ/m³K, k = 0.6 W/mK):
    its targets −3.64 and −2.32 °C (x = 2 and 4 mm, t = 500 s) are Neumann's sharp-front
    solution with ρL = 42 MJ/m³ (Ste = 0.5): −3.6412 and −2.3199.  The deck's enthalpy
    table, though, rises 42 MJ/m³ over −1..0 °C, of which 4.2 are the sensible heat of
    that degree: its latent heat is 37.8 MJ/m³, spread over a mushy degree, and the
    exact solution of that table is −3.709 / −2.454 °C (a 1-D enthalpy finite-difference
    reference converged to 1e-4 °C on 50..200 cells), 1.9 % / 5.8 % from the targets;
    apdl-like runs the published deck to −3.715 / −2.467.  Given the table Neumann's
    problem intends (42 MJ/m³ latent over a 0.1 °C mushy zone), the same 15 PLANE55 with
    5 s steps meet Neumann's solution, and so the targets, to within 0.5 %."""
    published = (DECKS / "vm104.dat").read_text()
    assert VM104_TABLE in published
    sharp = "MPTEMP,1,-10,-0.1,0,10\nMPDATA,ENTH,1,1,0,41.58E6,84E6,126E6\n"
    deck = (published.replace(VM104_TABLE, sharp).replace("AUTOTS,ON", "AUTOTS,OFF")
            .replace("DELTIM,3,3,10", "DELTIM,5").replace("TIME,900", "TIME,500"))
    rows = results_table(_run_published(deck, tmp_path) / "vm104.vrt")
    exact = _neumann_freezing(np.array([0.002, 0.004]), 500.0, 0.6 / 4.2e6,
                              4.2e6 * 5.0 / 42e6, -5.0, 0.0)
    for (label, target, computed), expected in zip(rows, exact, strict=True):
        assert round(expected, 2) == target, label
        assert computed == pytest.approx(expected, rel=0.005), label


def _enthalpy_slab(temps: np.ndarray, enthalpy: np.ndarray, k: float, length: float,
                   t_wall: float, t_init: float, t_end: float, x_m: np.ndarray,
                   cells: int = 100) -> np.ndarray:
    """An independent reference: explicit 1-D enthalpy finite differences (nodes at i·dx,
    the face held at t_wall, the far end insulated, half cells at both ends), T = H⁻¹(H)
    from the piecewise-linear table, steps at 0.4 of the stability limit of the smallest
    capacity."""
    dx = length / cells
    volume = np.full(cells + 1, dx)
    volume[[0, -1]] = dx / 2
    T = np.full(cells + 1, float(t_init))
    T[0] = t_wall
    H = np.interp(T, temps, enthalpy)
    dt_max = 0.4 * np.diff(enthalpy).min() / np.diff(temps).max() * dx * dx / k
    t = 0.0
    while t < t_end - 1e-9:
        dt = min(dt_max, t_end - t)
        flux = k * np.diff(T) / dx
        # node i >= 1 gains flux[i] from its right (none at the insulated end), loses
        # flux[i - 1] to its left
        H[1:] += dt * (np.concatenate([flux[1:], [0.0]]) - flux) / volume[1:]
        T[1:] = np.interp(H[1:], enthalpy, temps)
        t += dt
    return np.interp(x_m, np.linspace(0.0, length, cells + 1), T)


@pytest.mark.slow
def test_vm104_as_published_meets_the_exact_solution_of_its_own_enthalpy_table(tmp_path):
    """The published VM104 (15 PLANE55, AUTOTS from 3 s) against the converged solution of
    its own ENTH table (37.8 MJ/m³ latent over −1..0 °C): within 1 % at x = 2 and 4 mm,
    t = 500 s, while that solution is 1.9 % and 5.8 % colder than the targets (Neumann's
    with 42 MJ/m³)."""
    temps = np.array([-10.0, -1.0, 0.0, 10.0])
    enthalpy = np.array([0.0, 37.8e6, 79.8e6, 121.8e6])
    x = np.array([0.002, 0.004])
    reference = _enthalpy_slab(temps, enthalpy, 0.6, 0.01, -5.0, 0.0, 500.0, x)
    assert reference == pytest.approx(
        _enthalpy_slab(temps, enthalpy, 0.6, 0.01, -5.0, 0.0, 500.0, x, cells=200), abs=1e-3)
    rows = results_table(_run_published((DECKS / "vm104.dat").read_text(), tmp_path)
                         / "vm104.vrt")
    for (label, target, computed), expected in zip(rows, reference, strict=True):
        assert computed == pytest.approx(expected, rel=0.01), label
        assert abs(expected / target - 1.0) > 0.018, label
