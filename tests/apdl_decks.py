"""Deck fragments the APDL tests share: MAPDL idioms that several test decks spell alike."""

from __future__ import annotations


def held_faces(axis: str, *faces: tuple[float, float]) -> str:
    """Deck lines holding every node at coordinate `axis` = x at T (°C) for each (x, T) of
    `faces`, then selecting everything again: the two-wall conduction set-up."""
    lines = [f"NSEL,S,LOC,{axis},{x:g}\nD,ALL,TEMP,{t:g}" for x, t in faces]
    return "\n".join([*lines, "ALLSEL"])


def film_heat_sum(name: str) -> str:
    """/POST1 lines summing the convection heat rate of the SURF151 films (element type 2)
    into parameter `name` (SMISC 2 is a SURF151's film heat rate)."""
    return f"ESEL,S,TYPE,,2\nETABLE,{name}_E,SMISC,2\nSSUM\n*GET,{name},SSUM,,ITEM,{name}_E"


def column_of_quads(length: float, x0: float, x1: float, n: int = 40) -> str:
    """N/E lines of a column x0 ≤ x ≤ x1, 0 ≤ y ≤ `length` of n 4-node elements along y
    (1-D conduction along y): parameter NZE = n, nodes 1..n+1 at x0 (node NZE+1 at the top)
    and 101.. at x1."""
    return f"""NZE = {n}
*DO,I,0,NZE
  N,I+1,{x0},{length}*I/NZE
  N,I+101,{x1},{length}*I/NZE
*ENDDO
*DO,I,1,NZE
  E,I,I+100,I+101,I+1
*ENDDO"""


# a 20 mm steel square of four PLANE55 quads (k 45 W/mK, ρ 7800 kg/m³, c 460 J/kgK): with no
# film or fixed temperature it is insulated, and uniform heating is exact on it
STEEL_SQUARE = """/PREP7
ET,1,PLANE55
MP,KXX,1,45
MP,DENS,1,7800
MP,C,1,460
RECTNG,0,0.02,0,0.02
ESIZE,0.01
AMESH,ALL"""

# leave /PREP7, solve the load step, and read its results in /POST1
SOLVE_THEN_POST = "FINISH\n/SOLU\nSOLVE\nFINISH\n/POST1"
