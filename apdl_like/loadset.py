"""The twin's per-window load set and how it is read back from a solved (or recorded) deck.

A window k covers [start_s, start_s + n_steps·dt_s) with loads held constant (KBC,1):

    heat_generation     region   -> HGEN, W/m³             (BFE on the region's elements)
    convection          boundary -> (h W/m²K, T_bulk °C)   (SF,CONV on the boundary's nodes)
    contact_resistance  interface -> R, m²K/W              (TCC = 1/R, real constant 14 of
                                                             the interface's contact pair)

The contact resistance travels through the deck as a conductance, TCC = 1/R, and the
interpreter hands `1/TCC` to twin.fem.  In binary64, 1/(1/R) differs from R in the last bit
for about one value in seven, so a `LoadSet` stores R in that canonical form
(`canonical_resistance`): what you put in is what the solver uses and what a deck reads
back, bit for bit.  The change is at most one unit in the last place.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from apdl_like.errors import ApdlError
from apdl_like.model import record_groups
from twin.contract import STEP_S, STEPS_PER_WINDOW

if TYPE_CHECKING:
    from apdl_like.state import SessionState


def canonical_resistance(r: float) -> float:
    """R as it survives TCC = 1/R and back (idempotent; within one ulp of R)."""
    return 1.0 / (1.0 / float(r))


def _finite(value: float, what: str, of: object = None) -> float:
    """`value` as a float; ValueError naming `what` (of `of`, when given) unless finite.
    The message is made on failure only: the loop makes a load set every solver step."""
    value = float(value)
    if not math.isfinite(value):
        what = what if of is None else f"{what} of {of!r}"
        raise ValueError(f"{what} must be finite, got {value!r}")
    return value


@dataclass(frozen=True)
class LoadSet:
    """Loads of one twin window (see the module docstring for units and meaning)."""

    window: int
    start_s: float
    dt_s: float = STEP_S
    n_steps: int = STEPS_PER_WINDOW
    heat_generation: Mapping[str, float] = field(default_factory=dict)
    convection: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    contact_resistance: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if int(self.window) != self.window or self.window < 0:
            raise ValueError(f"window index must be a non-negative integer, got {self.window!r}")
        if not (_finite(self.start_s, "start time") >= 0.0):
            raise ValueError(f"start time must be ≥ 0 s, got {self.start_s!r}")
        if not (_finite(self.dt_s, "time step") > 0.0):
            raise ValueError(f"time step must be positive, got {self.dt_s!r}")
        if int(self.n_steps) != self.n_steps or not 1 <= self.n_steps <= 100_000:
            raise ValueError(f"number of steps must be an integer in 1..100000, "
                             f"got {self.n_steps!r}")
        object.__setattr__(self, "window", int(self.window))
        object.__setattr__(self, "n_steps", int(self.n_steps))
        heat = {str(k): _finite(v, "heat generation", k)
                for k, v in self.heat_generation.items()}
        conv = {}
        for k, hc in self.convection.items():
            h, tb = hc
            if not (_finite(h, "film coefficient", k) >= 0.0):
                raise ValueError(f"film coefficient of {k!r} must be ≥ 0, got {h!r}")
            conv[str(k)] = (float(h), _finite(tb, "bulk temperature", k))
        contact = {}
        for k, r in self.contact_resistance.items():
            if not (_finite(r, "contact resistance", k) > 0.0):
                raise ValueError(f"contact resistance of {k!r} must be > 0, got {r!r}")
            contact[str(k)] = canonical_resistance(r)
        object.__setattr__(self, "heat_generation", heat)
        object.__setattr__(self, "convection", conv)
        object.__setattr__(self, "contact_resistance", contact)

    @property
    def end_s(self) -> float:
        return self.start_s + self.n_steps * self.dt_s


def record_solve(session: SessionState) -> dict:
    """What a SOLVE would solve, by mesh names (SOLVE with `record_only` set)."""
    from apdl_like.solve import fem_model, refuse_deck_mesh_loads
    from apdl_like.state import TCC_LOCATION

    refuse_deck_mesh_loads(session, "read")
    fem = fem_model(session)
    db = session.db
    el = db.elements.arrays
    cell_rec = el["hgen_record"][fem.cell_element]
    heat = {}
    for cells in record_groups(cell_rec):
        heat[fem.region_for(cells)] = float(el["hgen"][fem.cell_element[cells[0]]])
    faces = db.faces
    conv = {}
    for idx in record_groups(faces.conv_record):
        conv[fem.boundary_for(fem.face_facets[idx])] = (float(faces.conv_h[idx[0]]),
                                                        float(faces.conv_bulk[idx[0]]))
    contact = {}
    for name, real in session.db.contact_real_sets.items():
        tcc = db.real_sets.get(real, {}).get(TCC_LOCATION)
        if tcc is not None:
            contact[name] = 1.0 / tcc
    s = db.settings
    return {"params": dict(session.params), "time": s.time, "deltim": s.deltim,
            "nsubst": s.nsubst, "kbc": s.kbc, "antype": s.antype, "heat": heat,
            "convection": conv, "contact": contact}


def load_set_from_record(rec: dict, file: str) -> LoadSet:
    """The window's load set from what its one SOLVE recorded (`record_solve`)."""
    params = rec["params"]
    for name in ("WINDOW", "T_START"):
        if name not in params:
            raise ApdlError(f"a window deck must set the parameter {name}", file=file)
    if rec["antype"] != "TRANS" or rec["kbc"] != 1 or rec["time"] is None or \
            rec["deltim"] is None:
        raise ApdlError("a window deck is a stepped transient (ANTYPE,TRANS; KBC,1; DELTIM; "
                        "TIME)", file=file)
    start, dt = params["T_START"], rec["deltim"]
    return LoadSet(
        window=int(round(params["WINDOW"])),
        start_s=start,
        dt_s=dt,
        n_steps=int(round((rec["time"] - start) / dt)),
        heat_generation=rec["heat"],
        convection=rec["convection"],
        contact_resistance=rec["contact"],
    )
