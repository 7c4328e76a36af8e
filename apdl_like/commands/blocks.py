"""Archive blocks: NBLOCK, EBLOCK, CMBLOCK (as /INPUT of a .cdb reads them)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import MAX_ENTITY_NUMBER, PREP7, Call, command, specs_of
from apdl_like.errors import ApdlError
from apdl_like.model import Component

if TYPE_CHECKING:
    from apdl_like.state import SessionState


@command("NBLOCK", PREP7, 6)
def nblock(s: SessionState, c: Call) -> None:
    from apdl_like.cdb import parse_nblock  # archive blocks: loaded with the first one

    ids, xyz = parse_nblock(c.statement.block)
    if ids.size and (ids.min() < 1 or ids.max() > MAX_ENTITY_NUMBER):
        raise ApdlError("NBLOCK node number out of range")
    if np.any(np.abs(xyz[:, 2]) > 1e-12 * max(1.0, float(np.abs(xyz).max(initial=0.0)))):
        raise ApdlError("NBLOCK has nodes off the XY plane (Z ≠ 0): only 2-D models are supported")
    for num, (x, y, _) in zip(ids.tolist(), xyz, strict=True):
        s.db.nodes.add(num, float(x), float(y))
    s.db.nodes.flush()


@command("EBLOCK", PREP7, 6)
def eblock(s: SessionState, c: Call) -> None:
    from apdl_like.cdb import parse_eblock

    db = s.db
    rows = parse_eblock(c.statement.block)
    for num, etype, mat, real, nodes in rows:
        if not 1 <= num <= MAX_ENTITY_NUMBER:
            raise ApdlError(f"EBLOCK element number {num} out of range")
        if etype not in db.element_types:
            raise ApdlError(f"EBLOCK element {num}: element type {etype} is not defined (ET)")
        if not 3 <= len(nodes) <= 8:
            raise ApdlError(f"EBLOCK element {num}: {len(nodes)} nodes (2-D elements have 3..8)")
        idx = db.nodes.index(np.array(nodes))
        if np.any(idx < 0):
            raise ApdlError(f"EBLOCK element {num} refers to a node that does not exist")
        nodes = list(nodes)
        if len(nodes) == 3:
            nodes.append(nodes[2])
        db.elements.add(num, etype, mat, real, tuple(nodes))
    db.elements.flush()


@command("CMBLOCK", PREP7 | {"BEGIN", "SOLU"}, 4)
def cmblock(s: SessionState, c: Call) -> None:
    from apdl_like.cdb import parse_cmblock

    name = c.raw(1).upper()
    if not name or not name[0].isalpha() or len(name) > 32:
        raise ApdlError(f"field 1: {c.raw(1)!r} is not a valid component name")
    entity = c.label(2)
    if entity not in ("NODE", "ELEM"):
        raise ApdlError(f"field 2: entity must be NODE or ELEM, got {entity!r}")
    numbers = parse_cmblock(c.statement.block)
    table = s.db.nodes if entity == "NODE" else s.db.elements
    missing = numbers[table.index(numbers) < 0] if numbers.size else numbers
    if missing.size:  # an id beyond the model would select nothing, or the wrong entity later
        raise ApdlError(f"CMBLOCK {name}: {entity.lower()} {int(missing[0])} does not exist")
    s.db.components[name] = Component(entity, numbers)


COMMANDS = (
    *specs_of(nblock, eblock, cmblock),
)
