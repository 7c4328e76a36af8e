"""Writing the twin's per-window deck from a `LoadSet`.

The deck only changes loads and time; it runs in a session that already holds the spindle
model (`Session.from_mesh`), so mesh, materials and assembled operators stay loaded.  Every
number is written with `repr`, which reads back to the identical binary64 value.

    /PREP7                        contact pairs: TCC (real constant 14) = 1/R
    RMODIF,101,14,<1/R>
    FINISH
    /SOLU
    WINDOW = k, T_START = t0      the window, kept in params.json
    ANTYPE,TRANS[,REST]           REST continues from the carried-over temperature state
    TIMINT,ON / KBC,1 / DELTIM,dt / TIME,t0+n·dt / OUTRES,ALL,ALL
    CMSEL,S,<REGION>   BFE,ALL,HGEN,,q          per heated region (element component)
    CMSEL,S,<BOUNDARY> SF,ALL,CONV,h,T_bulk     per convective boundary (node component)
    ALLSEL
    SOLVE
    FINISH
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from apdl_like.loadset import LoadSet
from twin.io.atomic import write_text

if TYPE_CHECKING:
    from twin.fem import AxiMesh


def component_name(name: str) -> str:
    """The APDL component name of a mesh set: upper-case, letters/digits/_, ≤ 32 chars."""
    out = "".join(ch if ch.isascii() and (ch.isalnum() or ch == "_") else "_" for ch in name)
    out = out.upper()
    if not out or not out[0].isalpha():
        out = "C" + out
    return out[:32]


CONTACT_REAL_BASE = 101


@dataclass(frozen=True)
class DeckLayout:
    """Names the deck uses for the model's sets (fixed by the mesh's own names).

    regions     region -> element component
    boundaries  boundary -> node component (suffix _N if a region already has the name)
    interfaces  interface -> real-constant set of its contact pair (101, 102, ... by name)
    """

    regions: dict[str, str]
    boundaries: dict[str, str]
    interfaces: dict[str, int]

    @classmethod
    def from_names(cls, regions: Iterable[str], boundaries: Iterable[str],
                   interfaces: Iterable[str]) -> DeckLayout:
        reg = {name: component_name(name) for name in sorted(regions)}
        taken = set(reg.values())
        bnd = {}
        for name in sorted(boundaries):
            c = component_name(name)
            if c in taken:
                c = component_name(name[:30] + "_N")
            taken.add(c)
            bnd[name] = c
        ifc = {name: CONTACT_REAL_BASE + i for i, name in enumerate(sorted(interfaces))}
        return cls(reg, bnd, ifc)

    @classmethod
    def for_mesh(cls, mesh: AxiMesh) -> DeckLayout:
        return cls.from_names(mesh.regions, mesh.boundaries, mesh.interfaces)


def _num(x: float) -> str:
    return repr(float(x))


HOW_TO_RUN = (
    "! loads only: runs on the spindle model (apdl-like run DECK --spindle --out DIR); a",
    "! restart (a later window, a warm start's first) runs from the field the run carried",
    "! in: --start with the previous deck's last result_NNN.vtu, or window_kkk_start.vtu",
    "! where written (README, Usage)",
)


def window_deck(loads: LoadSet, layout: DeckLayout,
                start_temperature_C: float | None = None,
                load_step: tuple[int, int] | None = None, notes: tuple[str, ...] = (),
                after: LoadSet | None = None, from_state: bool = False) -> str:
    """The APDL text of one window, or of one load step of a window written as several.

    start_temperature_C  the uniform field a run's first window (start 0 s) starts from,
                         written as TUNIF so that the deck runs alone (`apdl-like run
                         --spindle`); None: the session's (a later window restarts from the
                         field its session carries)
    load_step            (i, n): this text is load step i of the window's n (1-based): the
                         title says so, and only the first says how the deck runs
    notes                comment lines (without "! ") saying where the step's loads come from
    after                the load set of the load step this text follows in the same deck
                         (i > 1): a load it holds with the same value is not restated, as
                         loads stay until changed (in MAPDL and here).  Where the two name
                         different regions, boundaries or interfaces, all is written.
    from_state           a run's first window (start 0 s) that starts from a non-uniform
                         field handed in (a recording that begins on a warm spindle): a
                         restart (ANTYPE,TRANS,REST) from that state, as a later window's,
                         run with `--start window_000_start.vtu`
    """
    if from_state and start_temperature_C is not None:
        raise ValueError("a window starts either from a uniform TUNIF or from a state")
    for name in loads.heat_generation:
        if name not in layout.regions:
            raise ValueError(f"heat generation on unknown region {name!r}")
    for name in loads.convection:
        if name not in layout.boundaries:
            raise ValueError(f"convection on unknown boundary {name!r}")
    for name in loads.contact_resistance:
        if name not in layout.interfaces:
            raise ValueError(f"contact resistance on unknown interface {name!r}")
    end = loads.start_s + loads.n_steps * loads.dt_s
    steps = f"{loads.n_steps} step{'s' if loads.n_steps != 1 else ''} of {loads.dt_s:g} s"
    if load_step is None:
        out = [f"! spindle twin, window {loads.window}: t = {loads.start_s:g} .. {end:g} s, "
               f"{steps}, loads held over the window", *HOW_TO_RUN]
    else:
        i, n = load_step
        first = [f"! spindle twin, window {loads.window}: {n} load steps, each with its own "
                 "loads", *HOW_TO_RUN]
        out = [*(first if i == 1 else []),
               f"! ---- window {loads.window}, load step {i} of {n}: "
               f"t = {loads.start_s:g} .. {end:g} s, {steps}"]
    out += [f"! {line}" for line in notes]
    heat, films, contacts = (loads.heat_generation, loads.convection,
                             loads.contact_resistance)
    if after is not None and load_step is not None and load_step[0] > 1 and (
            heat.keys() == after.heat_generation.keys()
            and films.keys() == after.convection.keys()
            and contacts.keys() == after.contact_resistance.keys()):
        # what load step i-1 set and this one keeps stays set: only the changes are written
        heat = {k: v for k, v in heat.items() if after.heat_generation[k] != v}
        films = {k: v for k, v in films.items() if after.convection[k] != v}
        contacts = {k: v for k, v in contacts.items() if after.contact_resistance[k] != v}
        out.append("! loads not restated here stay as the load step before set them")
    if contacts:
        out.append("/PREP7")
        for name, r in sorted(contacts.items()):
            out.append(f"RMODIF,{layout.interfaces[name]},14,{_num(1.0 / r)}"
                       f"   ! {name}: TCC = 1/R, R = {r:.6g} m2K/W")
        out.append("FINISH")
    out += [
        "/SOLU",
        f"WINDOW = {loads.window}",
        f"T_START = {_num(loads.start_s)}",
        "ANTYPE,TRANS,REST" if loads.start_s > 0.0 or from_state else "ANTYPE,TRANS",
        *([f"TUNIF,{_num(start_temperature_C)}   ! C, the uniform start field"]
          if start_temperature_C is not None and loads.start_s == 0.0 else []),
        "TIMINT,ON",
        "KBC,1                 ! loads held over the load step (stepped)",
        f"DELTIM,{_num(loads.dt_s)}",
        f"TIME,{_num(end)}",
        "OUTRES,ALL,ALL",
    ]
    for name, q in sorted(heat.items()):
        out += [f"CMSEL,S,{layout.regions[name]}", f"BFE,ALL,HGEN,,{_num(q)}   ! W/m3"]
    for name, (h, tb) in sorted(films.items()):
        out += [f"CMSEL,S,{layout.boundaries[name]}",
                f"SF,ALL,CONV,{_num(h)},{_num(tb)}   ! W/m2K, C"]
    out += ["ALLSEL", "SOLVE", "FINISH", ""]
    return "\n".join(out)


def write_window_deck(loads: LoadSet, layout: DeckLayout, path: str | Path) -> Path:
    """Write the window deck atomically (temp file in the same folder, then rename)."""
    return write_text(path, window_deck(loads, layout))
