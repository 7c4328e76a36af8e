"""Tabular loads: a load value given as `%NAME%`, a TABLE parameter looked up at the time
and place the load acts (MAPDL's tabular boundary conditions).

A load command (D,,TEMP; F,,HEAT; SF/SFE CONV film coefficient and bulk temperature, HFLUX;
BF/BFE HGEN) that names a table stores the table's slot (its position in `Database.load_tables`)
beside a placeholder value.  SOLVE looks the table up, with the table's linear interpolation
and end values (`apdl_like.table_array`), at

- time: each substep's time in a transient load step, the load step's TIME in a steady one;
- place: the node of a D or F, the middle of an element face for SF/SFE (a face carries one value
  here), the centroid of an element for BF/BFE.

Primary variables (*DIM's Var1..Var3): TIME, and X, Y in global Cartesian coordinates (X is
the radius of an axisymmetric model); Z is 0 in a 2-D model.  A table must name a primary
variable for every dimension with more than one index value.

As MAPDL's KBC documents it, tabular loads are never ramped: every substep takes the table's
value at its time, with KBC,0 as with KBC,1.  A load that was tabular in one load step and is
given a value in the next is ramped as a newly introduced load (from zero or TUNIF), not from
the table's last value.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from apdl_like.errors import ApdlError
from apdl_like.table_array import TableArray, table_values

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

    from apdl_like.call import Call
    from apdl_like.model import Database
    from apdl_like.state import SessionState

State = TypeVar("State", bound="DataclassInstance")
"""A load state: a dataclass of load arrays (`TabularLoads.at` returns a copy of it)."""

LOAD_VARIABLES = ("TIME", "X", "Y", "Z")
_AXES = ("Var1 (rows)", "Var2 (columns)", "Var3 (planes)")


def load_table(params: Mapping[str, Any], name: str) -> TableArray:
    """The TABLE parameter `name`, once checked to be one a load can look up."""
    table = params.get(name)
    if table is None:
        raise ApdlError(f"%{name}% names no parameter: define the table first "
                        f"(*DIM,{name},TABLE,...)")
    if not isinstance(table, TableArray):
        raise ApdlError(f"%{name}% is not a TABLE parameter (*DIM,{name},TABLE,...)")
    for axis, (variable, size) in enumerate(zip(table.variables, table.shape, strict=True)):
        if variable and variable not in LOAD_VARIABLES:
            raise ApdlError(f"table {name}: primary variable {variable} ({_AXES[axis]}) is not "
                            f"supported for loads (only {', '.join(LOAD_VARIABLES)})")
        if not variable and size - 1 > 1:
            raise ApdlError(f"table {name} names no primary variable for {_AXES[axis]}: give "
                            f"it on *DIM (e.g. *DIM,{name},TABLE,{table.shape[0] - 1},1,1,TIME)")
    return table


def table_slot(s: SessionState, c: Call, i: int) -> int | None:
    """The slot of the table field `i` names as `%NAME%` (registered now), or None when the
    field holds a value."""
    name = c.table(i)
    if name is None:
        return None
    try:
        load_table(s.params, name)
    except ApdlError as exc:
        raise ApdlError(f"field {i}: {exc.reason}") from None
    tables = s.db.load_tables
    if name not in tables:
        tables.append(name)
    return tables.index(name)


def mark(db: Database, slots: np.ndarray, where: np.ndarray, slot: int | None) -> None:
    """Note that the loads at `where` now come from table `slot` (None: from a value)."""
    if slot is None and not db.load_tables:
        return  # no load ever named a table: every slot is -1 already
    slots[where] = -1 if slot is None else slot


def in_use(db: Database) -> bool:
    """Whether a load of the database comes from a table."""
    if not db.load_tables:
        return False
    f = db.faces
    return any(bool(np.any(a >= 0)) for a in (
        db.nodes.arrays["d_temp_table"], db.nodes.arrays["f_heat_table"],
        db.elements.arrays["hgen_table"],
        f.conv_h_table, f.conv_bulk_table, f.hflux_table))


@dataclass(frozen=True)
class _Entries:
    """The entries of one load array that come from tables, and where they act."""

    name: str  # the load array (a field of the load state)
    where: np.ndarray  # entry indices
    slots: np.ndarray  # their tables' slots
    xy: np.ndarray  # (n, 2) the points they are looked up at, global X, Y


@dataclass(frozen=True)
class TabularLoads:
    """The tabular entries of a load state (a dataclass of load arrays) and their tables."""

    entries: tuple[_Entries, ...]
    tables: dict[int, tuple[str, TableArray]]  # slot -> (name, table)

    def at(self, state: State, time: float) -> State:
        """A copy of `state` with every tabular entry looked up at `time`."""
        changes = {}
        for e in self.entries:
            values = getattr(state, e.name).copy()
            for slot in np.unique(e.slots):
                pick = e.slots == slot
                values[e.where[pick]] = table_at(*self.tables[int(slot)], time, e.xy[pick])
            changes[e.name] = values
        return replace(state, **changes)

    def cleared(self, state: State) -> State:
        """A copy of `state` without its tabular entries (NaN: no load), as the start of the
        next load step's ramps sees them."""
        changes = {}
        for e in self.entries:
            values = getattr(state, e.name).copy()
            values[e.where] = np.nan
            changes[e.name] = values
        return replace(state, **changes)


def table_at(name: str, table: TableArray, time: float, xy: np.ndarray) -> np.ndarray:
    """The table at `time` and the points `xy` (n, 2), by its primary variables."""
    n = xy.shape[0]
    by_variable = {"TIME": np.full(n, float(time)), "X": xy[:, 0], "Y": xy[:, 1]}
    zero = np.zeros(n)  # Z of a 2-D model; a dimension of one index value needs none
    return table_values(name, table, *(by_variable.get(v, zero) for v in table.variables))


def tabular_loads(db: Database, params: Mapping[str, Any],
                  arrays: Mapping[str, tuple[np.ndarray, Callable[[np.ndarray], np.ndarray]]],
                  ) -> TabularLoads | None:
    """The tabular entries of the load arrays named in `arrays` (name -> (its slots, the
    points (n, 2) of given entries)); None when no load comes from a table."""
    if not db.load_tables:
        return None
    entries = []
    for name, (slots, locate) in arrays.items():
        where = np.nonzero(slots >= 0)[0]
        if where.size:
            entries.append(_Entries(name, where, slots[where], locate(where)))
    if not entries:
        return None
    used = np.unique(np.concatenate([e.slots for e in entries]))
    tables = {}
    for slot in used:
        name = db.load_tables[int(slot)]
        tables[int(slot)] = (name, load_table(params, name))
    return TabularLoads(tuple(entries), tables)
