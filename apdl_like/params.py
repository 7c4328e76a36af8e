"""Parameters: scalars, character values and arrays (`*DIM`), as APDL keeps them.

A parameter is a float, a character value (str) or a numpy array of shape (I, J, K):
float for ARRAY, object (str) for CHAR.  Subscripts are 1-based; `NAME(i,j) = v1, v2, ...`
and `*VFILL,NAME(i,j),DATA,...` fill down the column from (i, j), as in APDL.  Character
values are written in single quotes (`'T (C) X='`).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

import numpy as np

from apdl_like.errors import ApdlError
from apdl_like.expressions import compile_expression, element_index, is_parameter_name
from apdl_like.parser import split_fields
from apdl_like.table_array import new_table

Value = float | str | np.ndarray
MAX_ARRAY_SIZE = 10_000_000

_TARGET = re.compile(r"\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\((.*)\))?\s*\Z", re.S)


def is_text(text: str) -> bool:
    """A quoted character value, `'...'`."""
    t = text.strip()
    return len(t) >= 2 and t[0] == "'" and t[-1] == "'"


def value_of(text: str, params: Mapping[str, Value], funcs: Mapping[str, object]) -> float | str:
    """A field's value: the text of a quoted character value, else a number."""
    if is_text(text):
        return text.strip()[1:-1]
    return compile_expression(text)(params, funcs)  # type: ignore[arg-type]


def split_target(text: str) -> tuple[str, list[str]]:
    """`NAME(i,j)` -> ("NAME", ["i", "j"]); `NAME` -> ("NAME", [])."""
    m = _TARGET.match(text)
    if m is None:
        raise ApdlError(f"{text!r} is not a parameter name or array element")
    name = m.group(1).upper()
    if not is_parameter_name(name):
        raise ApdlError(f"{name!r} is not a valid parameter name (≤ 32 characters, letter or _ "
                        "first, not a function name)")
    subs = m.group(2)
    return name, ([s.strip() for s in split_fields(subs)] if subs and subs.strip() else [])


def subscripts(texts: Sequence[str], params: Mapping[str, Value],
               funcs: Mapping[str, object]) -> list[float]:
    return [compile_expression(t)(params, funcs) if t else 1.0  # type: ignore[arg-type]
            for t in texts]


def start_subscripts(texts: Sequence[str], params: Mapping[str, Value],
                     funcs: Mapping[str, object]) -> list[float]:
    """The subscripts of `NAME(i,j)` as an array's starting element: row 1 for a bare NAME."""
    return subscripts(texts, params, funcs) if texts else [1.0]


def numeric_array(params: Mapping[str, Value], name: str, field: int) -> np.ndarray:
    """The *DIM numeric array NAME named in field `field` (*VGET, VGET, *VOPER, *VSCFUN)."""
    array = params.get(name)
    if not isinstance(array, np.ndarray) or array.dtype == object:
        raise ApdlError(f"field {field}: {name} is not a numeric array (define it with *DIM "
                        "first)")
    return array


def store(params: dict[str, Value], name: str, subs: list[float],
          values: Sequence[float | str]) -> None:
    """Scalar assignment, or values down the column of an array from (i, j, k)."""
    if not subs:
        if len(values) != 1:
            raise ApdlError(f"{name} is not an array: one value only")
        params[name] = values[0]
        return
    array = params.get(name)
    if not isinstance(array, np.ndarray):
        raise ApdlError(f"{name} is not an array (define it with *DIM first)")
    start = element_index(name, array, subs)
    if start[0] + len(values) > array.shape[0]:
        raise ApdlError(f"{len(values)} values from row {start[0] + 1} overrun {name}, which "
                        f"has {array.shape[0]} rows")
    for k, v in enumerate(values):
        index = (start[0] + k, *start[1:])
        if array.dtype == object:
            if not isinstance(v, str):
                raise ApdlError(f"{name} is a character array: values must be quoted text")
            array[index] = v
        else:
            if isinstance(v, str):
                raise ApdlError(f"{name} is a numeric array: {v!r} is text")
            array[index] = v


def dimension(params: dict[str, Value], name: str, kind: str, shape: tuple[int, int, int],
              variables: tuple[str, str, str] = ("", "", "")) -> None:
    """*DIM: a new array of zeros (ARRAY, TABLE) or blanks (CHAR, STRING); `variables` are a
    TABLE's primary variables (Var1..Var3)."""
    if any(n < 1 for n in shape) or shape[0] * shape[1] * shape[2] > MAX_ARRAY_SIZE:
        raise ApdlError(f"array dimensions {shape} out of range (1.., at most "
                        f"{MAX_ARRAY_SIZE} elements)")
    if kind in ("ARRAY", ""):
        params[name] = np.zeros(shape)
    elif kind in ("CHAR", "STRING"):
        params[name] = np.full(shape, "", dtype=object)
    elif kind == "TABLE":
        params[name] = new_table(shape, variables)
    else:
        raise ApdlError(f"field 2: array type must be ARRAY, TABLE, CHAR or STRING, got "
                        f"{kind!r}")


def column(params: Mapping[str, Value], name: str, subs: list[float]) -> list[float | str]:
    """The elements from NAME(i, j, k) down its column (for *VWRITE)."""
    array = params.get(name)
    if not isinstance(array, np.ndarray):
        if name not in params:
            raise ApdlError(f"undefined parameter {name}")
        return [params[name]]  # type: ignore[list-item]
    start = element_index(name, array, subs)
    return [array[(i, *start[1:])] for i in range(start[0], array.shape[0])]
