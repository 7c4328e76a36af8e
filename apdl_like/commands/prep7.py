"""/PREP7: element types, materials, real constants, nodes, elements, areas and meshing."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from apdl_like.call import PREP7, Call, CommandSpec, Handler, command, specs_of
from apdl_like.errors import ApdlError
from apdl_like.model import ELEMENT_TYPES, THERMAL_TO_STRUCTURAL, ElementType, Material

if TYPE_CHECKING:
    from apdl_like.state import SessionState

MP_LABELS = ("KXX", "KYY", "KZZ", "DENS", "C", "EX", "EY", "EZ", "PRXY", "NUXY", "ALPX", "ALPY",
             "ALPZ", "EMIS", "HF", "ENTH")
MP_POSITIVE = ("KXX", "KYY", "KZZ", "DENS", "C", "EX")
# labels MAPDL reads whose values nothing here uses (3-D directions, radiation, enthalpy)
MP_UNUSED = ("KZZ", "EY", "EZ", "ALPY", "ALPZ", "EMIS", "HF", "ENTH")
MAX_TABLE_POINTS = 100
CONTACT_TYPES = ("CONTA172", "TARGE169")


# 3-D types that archives written by other tools carry (mapdl-archive writes triangles as
# SHELL181): accepted so the archive reads, to be redefined (ET,n,PLANE55) before SOLVE
FOREIGN_TYPES = {181: "SHELL181", 185: "SOLID185", 186: "SOLID186", 187: "SOLID187"}
_BY_NUMBER = {int("".join(ch for ch in name if ch.isdigit())): name
              for name in ELEMENT_TYPES} | FOREIGN_TYPES | {172: "CONTA172", 169: "TARGE169"}


def _element_name(c: Call) -> str:
    text = c.label(2)
    if not text:
        raise ApdlError("field 2 (element name) is required")
    name = _BY_NUMBER.get(int(text), "") if text.isdigit() else text
    if name in CONTACT_TYPES or name in ELEMENT_TYPES or name in FOREIGN_TYPES.values():
        return name
    raise ApdlError(f"element {text} is not supported (PLANE35, PLANE55, PLANE77, PLANE182, "
                    "PLANE183, SURF151, LINK31, LINK32, LINK33, LINK34, MASS71)")


@command("ET", PREP7, 9)
def et(s: SessionState, c: Call) -> None:
    """ET,ITYPE,Ename,KOP1..KOP6,INOPR (INOPR, print suppression, changes nothing here)."""
    itype = c.entity(1, "ITYPE")
    name = _element_name(c)
    if name in CONTACT_TYPES:
        # contact pairs come with an AxiMesh session (interfaces); accepted for archives
        s.say(f"ET,{itype},{name}: contact pairs act through the session's interfaces")
        return
    keyopt = {}
    for k in range(1, 7):
        if c.given(2 + k):
            keyopt[k] = c.int(2 + k, what=f"KOP{k}")
    s.db.element_types[itype] = ElementType(name, keyopt)


@command("KEYOPT", PREP7, 3)
def keyopt(s: SessionState, c: Call) -> None:
    itype = c.entity(1, "ITYPE")
    knum = c.int_in(2, 1, 18, what="KNUM")
    value = c.int(3, 0, what="VALUE")
    et_ = s.db.element_types.get(itype)
    if et_ is None:
        raise ApdlError(f"element type {itype} is not defined (ET first)")
    et_.keyopt[knum] = value


@command("ETCHG", PREP7, 1)
def etchg(s: SessionState, c: Call) -> None:
    how = c.label(1)
    if how not in ("TTS", "STT"):
        raise ApdlError(f"field 1 must be TTS (thermal to structural) or STT, got {how!r}")
    table = THERMAL_TO_STRUCTURAL if how == "TTS" else \
        {v: k for k, v in THERMAL_TO_STRUCTURAL.items()}
    for et_ in s.db.element_types.values():
        if et_.name in table:
            et_.name = table[et_.name]


def _attribute(name: str) -> Handler:
    def set_attribute(s: SessionState, c: Call) -> None:
        setattr(s.db, f"active_{name}", c.entity(1, name.upper()))

    return set_attribute




@command("MP", PREP7, 7)
def mp(s: SessionState, c: Call) -> None:
    label = c.label(1)
    if label not in MP_LABELS:
        raise ApdlError(f"field 1: property must be one of {', '.join(MP_LABELS)}, got {label!r}")
    mat = c.entity(2, "MAT") if c.given(2) else 1  # MAPDL: MAT defaults to 1
    value = c.num(3, 0.0, what="C0")
    coeffs = [value] + [c.num(i, 0.0, what=f"C{i - 3}") for i in range(4, 8)]
    while len(coeffs) > 1 and coeffs[-1] == 0.0:
        coeffs.pop()
    if label in MP_POSITIVE and len(coeffs) == 1 and not value > 0.0:
        raise ApdlError(f"{label} must be positive, got {value!r}")
    if label in ("PRXY", "NUXY") and not -1.0 < value < 0.5:
        raise ApdlError(f"{label} must lie in (-1, 0.5), got {value!r}")
    material = s.db.materials.setdefault(mat, Material())
    material.props[label] = value
    material.tables.pop(label, None)
    if len(coeffs) > 1:
        material.coefficients[label] = tuple(coeffs)
    else:
        material.coefficients.pop(label, None)


def _table_values(c: Call, values: list[float], start: int, first_field: int,
                  name: str) -> list[float]:
    """`values` with fields first_field.. (up to six: name1..name6) written from table
    location `start` on; a blank field keeps its location, a gap before it is NaN."""
    for k in range(6):
        if c.given(first_field + k):
            i = start - 1 + k
            if not 0 <= i < MAX_TABLE_POINTS:
                raise ApdlError(f"table location {i + 1} out of range 1..{MAX_TABLE_POINTS}")
            values += [float("nan")] * (i + 1 - len(values))
            values[i] = c.num(first_field + k, what=f"{name}{k + 1}")
    return values


@command("MPTEMP", PREP7, 7)
def mptemp(s: SessionState, c: Call) -> None:
    """MPTEMP,STLOC,T1..T6: the temperatures of the next MPDATA tables (blank: erase)."""
    if c.count() == 0:
        s.db.mp_temperatures = []
        return
    start = c.int(1, 1, what="STLOC")
    s.db.mp_temperatures = _table_values(c, list(s.db.mp_temperatures), start, 2, "T")


@command("MPDATA", PREP7, 9)
def mpdata(s: SessionState, c: Call) -> None:
    """MPDATA,Lab,MAT,STLOC,C1..C6: property values at the MPTEMP temperatures."""
    label = c.label(1)
    if label not in MP_LABELS:
        raise ApdlError(f"field 1: property must be one of {', '.join(MP_LABELS)}, got {label!r}")
    mat = c.entity(2, "MAT") if c.given(2) else 1
    start = c.int(3, 1, what="STLOC")
    material = s.db.materials.setdefault(mat, Material())
    old = material.tables.get(label)
    values = _table_values(c, list(old[1]) if old is not None else [], start, 4, "C")
    temps = s.db.mp_temperatures[: len(values)]
    if len(temps) < len(values) or any(np.isnan(temps)) or any(np.isnan(values)):
        raise ApdlError("MPDATA needs a temperature (MPTEMP) for each value, without gaps")
    if len(values) > 1 and np.any(np.diff(temps) <= 0.0):
        raise ApdlError("MPTEMP temperatures must increase")
    material.tables[label] = (np.array(temps, float), np.array(values, float))
    material.props[label] = float(values[0])
    material.coefficients.pop(label, None)


def _real_values(s: SessionState, nset: int, start: int, c: Call, first_field: int,
                 count: int) -> None:
    values = s.db.real_sets.setdefault(nset, {})
    for k in range(count):
        if c.given(first_field + k):
            values[start + k] = c.num(first_field + k, what=f"R{start + k}")


@command("R", PREP7, 7)
def r(s: SessionState, c: Call) -> None:
    nset = c.entity(1, "NSET")
    s.db.real_sets[nset] = {}
    _real_values(s, nset, 1, c, 2, 6)
    s.db.last_real = (nset, 7)


@command("RMORE", PREP7, 6)
def rmore(s: SessionState, c: Call) -> None:
    if s.db.last_real is None:
        raise ApdlError("RMORE needs a preceding R command")
    nset, start = s.db.last_real
    _real_values(s, nset, start, c, 1, 6)
    s.db.last_real = (nset, start + 6)


@command("RMODIF", PREP7, 8)
def rmodif(s: SessionState, c: Call) -> None:
    nset = c.entity(1, "NSET")
    stloc = c.int_in(2, 1, 100, what="STLOC")
    if nset not in s.db.real_sets:
        raise ApdlError(f"real constant set {nset} does not exist")
    _real_values(s, nset, stloc, c, 3, 6)
    s.note_load(c)


@command("N", PREP7, 7)
def n(s: SessionState, c: Call) -> None:
    nodes = s.db.nodes
    if c.given(1):
        num = c.entity(1, "NODE")
    else:
        nodes.flush()
        num = int(nodes.ids.max()) + 1 if len(nodes.ids) else 1
        num = max([num, *nodes.pending]) if nodes.pending else num
    x, y = s.db.active_system.to_global(c.num(2, 0.0, what="X"), c.num(3, 0.0, what="Y"))
    if c.given(4) and c.num(4) != 0.0:
        raise ApdlError("field 4 (Z) must be 0 in a 2-D model")
    nodes.add(num, x, y)
    s.db.node_history = [*s.db.node_history[-1:], num]  # FILL's default pair


# node counts E accepts (quadratic elements without mid-side nodes get them from EMID)
# MAPDL lets any mid-side node of PLANE77/183 be left out (E with 5..7 nodes, or 0 in a field)
_NODE_COUNTS = {"PLANE55": (3, 4), "PLANE182": (3, 4), "PLANE77": (3, 4, 5, 6, 7, 8),
                "PLANE183": (3, 4, 5, 6, 7, 8), "PLANE35": (3, 6), "SURF151": (2, 3),
                "LINK31": (2,), "LINK32": (2,), "LINK33": (2,), "LINK34": (2,), "MASS71": (1,)}


@command("E", PREP7, 8)
def e(s: SessionState, c: Call) -> None:
    db = s.db
    et_ = db.element_types.get(db.active_type)
    if et_ is None:
        raise ApdlError(f"element type {db.active_type} is not defined (ET, then TYPE)")
    given = [i for i in range(1, 9) if c.given(i)]
    if given != list(range(1, len(given) + 1)):
        raise ApdlError("node fields must be given without gaps")
    nums = [c.entity(i, "node") for i in given]
    if et_.name not in _NODE_COUNTS:
        raise ApdlError(f"element type {db.active_type} ({et_.name}) is not supported: "
                        "PLANE35, PLANE55, PLANE77, PLANE182, PLANE183 or a thermal link")
    allowed = (3, 6) if et_.triangle6 else _NODE_COUNTS[et_.name]
    if len(nums) not in allowed:
        shape = "6-node triangle" if et_.triangle6 else et_.name
        raise ApdlError(f"{shape} takes {' or '.join(map(str, allowed))} nodes, got {len(nums)}")
    idx = db.nodes.index(np.array(nums))
    if np.any(idx < 0):
        raise ApdlError(f"node {nums[int(np.nonzero(idx < 0)[0][0])]} does not exist")
    if et_.physics == "surface":
        if nums[0] == nums[1]:
            raise ApdlError("a surface element needs two different nodes (I, J)")
    elif et_.physics != "line" and len(set(nums[:3])) < 3:  # links may join coincident nodes
        raise ApdlError("the first three nodes (I, J, K) must be distinct")
    if len(nums) == 3 and not et_.triangle6 and et_.physics != "surface":
        nums.append(nums[2])  # the triangle is the quad with K = L
    el = db.elements
    el.flush()
    number = int(el.ids.max()) + 1 if len(el.ids) else 1
    el.add(number, db.active_type, db.active_mat, db.active_real, tuple(nums))


@command("EMODIF", PREP7, 3)
def emodif(s: SessionState, c: Call) -> None:
    """EMODIF,IEL|ALL,MAT|TYPE|REAL,value: change an attribute of elements."""
    from apdl_like.commands.loads import element_targets

    what = c.label(2)
    if what not in ("MAT", "TYPE", "REAL"):
        raise ApdlError(f"field 2 must be MAT, TYPE or REAL, got {what or '(empty)'!r}")
    value = c.entity(3, what)
    if what == "TYPE" and value not in s.db.element_types:
        raise ApdlError(f"element type {value} is not defined (ET first)")
    idx = element_targets(s, c, 1)
    getattr(s.db.elements, what.lower())[idx] = value
    s.db.elements.version += 1


COMMANDS = (
    *specs_of(et, keyopt, etchg, mp, mptemp, mpdata, r, rmore, rmodif, n, e, emodif),
    CommandSpec("TYPE", PREP7, 1, _attribute("type")),
    CommandSpec("MAT", PREP7, 1, _attribute("mat")),
    CommandSpec("REAL", PREP7, 1, _attribute("real")),
)
