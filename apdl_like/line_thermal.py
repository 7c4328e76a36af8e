"""Thermal line and point elements of a 2-D deck: LINK31/32/33/34 and MASS71 as MAPDL
defines them (element reference and theory reference, chapters LINK31..MASS71).

Each element couples the temperature dofs of its nodes I, J directly (no quadrature):

    LINK32/33 conduction bar   K = k·A/L [[1,-1],[-1,1]], k = KXX at (TI+TJ)/2;
                               C = ρ·c·A·L/2 on each node (the row sums of the consistent
                               matrix, as MAPDL diagonalizes it); HGEN q̇ gives q̇·A·L/2 each
    LINK34 convection link     K = h·A [[1,-1],[-1,1]], h = MP,HF at KEYOPT(3): 0 (TI+TJ)/2,
                               1 TI, 2 TJ, 3 |TI−TJ|
    LINK31 radiation link      Q = σ·ε·F·A·((TI+Toff)⁴ − (TJ+Toff)⁴), real constants AREA,
                               FORM FACTOR F, EMISSIVITY ε, SBC σ (default 0.119E-10,
                               Btu/(hr·in²·°R⁴)); Toff from TOFFST.  It enters as the secant
                               conductance σεFA(θI²+θJ²)(θI+θJ) of absolute temperatures θ,
                               so the Picard iteration of the thermal solver converges to
                               the radiation balance.
    MASS71 thermal mass        C = R1 with KEYOPT(3) = 1 (a capacitance), else
                               R1 (mass) · c; it has one node.

A link's area is as written: MAPDL does not multiply it by 2πr in an axisymmetric model
(the element reference: "the area must be expressed on a full 360° basis").
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from apdl_like.errors import ApdlError

LINK_KINDS = {"LINK32": "conduction", "LINK33": "conduction", "LINK34": "convection",
              "LINK31": "radiation", "MASS71": "mass"}
DEFAULT_SBC = 0.119e-10  # LINK31's default Stefan-Boltzmann constant, Btu/(hr·in²·°R⁴)

Property = Callable[[np.ndarray], np.ndarray]


@dataclass
class ThermalLinks:
    """The line/point elements of a model: per element its kind and constants.

    elements   index in the deck's element table
    i, j       thermal dofs of nodes I and J (j = i for MASS71)
    kind       one of LINK_KINDS' values
    length     |IJ| (m)
    area       real constant 1 (AREA) of links; capacitance or mass of MASS71
    mat        material numbers
    film_at    LINK34 KEYOPT(3) (where h is evaluated)
    emission   LINK31 σ·ε·F
    mass_is_capacitance  MASS71 KEYOPT(3) = 1
    """

    elements: np.ndarray
    i: np.ndarray
    j: np.ndarray
    kind: np.ndarray
    length: np.ndarray
    area: np.ndarray
    mat: np.ndarray
    film_at: np.ndarray
    emission: np.ndarray
    mass_is_capacitance: np.ndarray
    offset: float  # TOFFST, absolute temperature of the model's zero

    @property
    def size(self) -> int:
        return int(self.elements.size)

    def _pair(self, g: np.ndarray, n: int) -> sp.csr_matrix:
        """Σ g_e [[1,-1],[-1,1]] on (i_e, j_e)."""
        rows = np.concatenate([self.i, self.j, self.i, self.j])
        cols = np.concatenate([self.i, self.j, self.j, self.i])
        vals = np.concatenate([g, g, -g, -g])
        return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))

    def conductance(self, T: np.ndarray, kxx: list[Property], hf: list[Property | None]
                    ) -> np.ndarray:
        """Per element the conductance g (W/K) between I and J at temperatures T."""
        TI, TJ = T[self.i], T[self.j]
        g = np.zeros(self.size)
        for e in range(self.size):
            kind, m = self.kind[e], int(self.mat[e])
            if kind == "conduction":
                k = float(kxx[m](np.array([0.5 * (TI[e] + TJ[e])]))[0])
                g[e] = k * self.area[e] / self.length[e]
            elif kind == "convection":
                at = {0: 0.5 * (TI[e] + TJ[e]), 1: TI[e], 2: TJ[e],
                      3: abs(TI[e] - TJ[e])}[int(self.film_at[e])]
                h = hf[m] if m < len(hf) else None
                if h is None:
                    raise ApdlError(f"material {m} has no HF (MP,HF,{m},...), needed by a "
                                    "LINK34 convection link")
                g[e] = float(h(np.array([at]))[0]) * self.area[e]
            elif kind == "radiation":
                a, b = TI[e] + self.offset, TJ[e] + self.offset
                g[e] = self.emission[e] * self.area[e] * (a * a + b * b) * (a + b)
        return g

    def stiffness(self, T: np.ndarray, kxx: list[Property], hf: list[Property | None],
                  n: int) -> sp.csr_matrix:
        return self._pair(self.conductance(T, kxx, hf), n)

    def capacity(self, T: np.ndarray, rho_c: list[Property], specific_heat: list[Property],
                 n: int) -> sp.csr_matrix:
        """The diagonal capacity (J/K) of the bars and masses."""
        diag = np.zeros(n)
        for e in range(self.size):
            kind, m = self.kind[e], int(self.mat[e])
            if kind == "conduction":
                Tm = np.array([0.5 * (T[self.i[e]] + T[self.j[e]])])
                half = 0.5 * float(rho_c[m](Tm)[0]) * self.area[e] * self.length[e]
                diag[self.i[e]] += half
                diag[self.j[e]] += half
            elif kind == "mass":
                cap = self.area[e]
                if not self.mass_is_capacitance[e]:
                    c = specific_heat[m] if m < len(specific_heat) else None
                    if c is None:
                        raise ApdlError(f"material {m} has no C (MP,C,{m},...), needed by a "
                                        "MASS71 mass")
                    cap *= float(c(T[self.i[e]:self.i[e] + 1])[0])
                diag[self.i[e]] += cap
        return sp.diags(diag).tocsr()

    def heat_load(self, hgen: np.ndarray, n: int) -> np.ndarray:
        """Nodal heat (W) of the bars' generation rate (W/m³ per deck element)."""
        q = np.nan_to_num(hgen[self.elements])
        half = np.where(self.kind == "conduction", 0.5 * q * self.area * self.length, 0.0)
        return np.bincount(self.i, half, n) + np.bincount(self.j, half, n)

    def nodal_heat(self, T: np.ndarray, kxx: list[Property], hf: list[Property | None],
                   hgen: np.ndarray, which: np.ndarray, n: int) -> np.ndarray:
        """Heat flow (W) at the dofs of the chosen links (a mask over `elements`), steady:
        K_e T_e less their generation, summed over them."""
        g = np.where(which, self.conductance(T, kxx, hf), 0.0)
        flow = g * (T[self.i] - T[self.j])
        out = np.bincount(self.i, flow, n) - np.bincount(self.j, flow, n)
        q = np.where(which, np.nan_to_num(hgen[self.elements]), 0.0)
        half = np.where(self.kind == "conduction", 0.5 * q * self.area * self.length, 0.0)
        return out - np.bincount(self.i, half, n) - np.bincount(self.j, half, n)

    def heat_rate(self, T: np.ndarray, kxx: list[Property], hf: list[Property | None]
                  ) -> np.ndarray:
        """Per element the HEAT RATE MAPDL outputs (SMISC 1): Q = g·(TI − TJ), W."""
        return self.conductance(T, kxx, hf) * (T[self.i] - T[self.j])


def link_constants(kind: str, real: dict[int, float], keyopt: dict[int, int],
                   where: str) -> tuple[float, float, int, bool]:
    """(area or capacitance, σεF, KEYOPT(3) of LINK34, MASS71 capacitance?) of one element
    from its real constant set (1-based locations)."""
    area = real.get(1, 0.0)
    if kind == "radiation":
        form, emis = real.get(2, 0.0), real.get(3, 0.0)
        sbc = real.get(4, 0.0) or DEFAULT_SBC
        if not area > 0.0:
            raise ApdlError(f"{where}: LINK31 needs a positive AREA (R, location 1)")
        return area, sbc * form * emis, 0, False
    if kind == "convection":
        if real.get(2, 0.0) or real.get(3, 0.0):
            raise ApdlError(f"{where}: LINK34 empirical terms EN and CC are not supported")
        k3 = keyopt.get(3, 0)
        if k3 not in (0, 1, 2, 3):
            raise ApdlError(f"{where}: LINK34 KEYOPT(3) must be 0..3, got {k3}")
        return area, 0.0, k3, False
    if kind == "mass":
        return area, 0.0, 0, keyopt.get(3, 0) == 1
    if not area > 0.0:
        raise ApdlError(f"{where}: a conduction bar needs a positive AREA (R, location 1)")
    return area, 0.0, 0, False
