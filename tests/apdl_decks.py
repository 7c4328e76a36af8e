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


# leave /PREP7, solve the load step, and read its results in /POST1
SOLVE_THEN_POST = "FINISH\n/SOLU\nSOLVE\nFINISH\n/POST1"
