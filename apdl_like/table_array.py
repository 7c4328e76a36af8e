"""`*DIM,Par,TABLE,I,J,K`: MAPDL's table parameter, looked up by value with linear
interpolation.

Storage is an array of shape (I+1, J+1, K+1) indexed exactly as APDL subscripts the table:
row 0 holds the column index values (`Par(0,j)`), column 0 the row index values
(`Par(i,0)`), `Par(0,0,k)` the index value of plane k, and `Par(i,j,k)` (i, j, k ≥ 1) the
entries.  `Par(x, y, z)` in an expression interpolates linearly between the index values
bracketing x, y and z (the index values of plane 1 serve every plane) and holds the end
value outside them, as MAPDL does.  A table of one column interpolates on x only.
"""

from __future__ import annotations

import numpy as np

from apdl_like.errors import ApdlError


class TableArray(np.ndarray):
    """A TABLE parameter (an ndarray subclass, so copies and SAVE keep what it is)."""


def new_table(shape: tuple[int, int, int]) -> TableArray:
    """Zeros, index values included (MAPDL fills them before the deck assigns them)."""
    i, j, k = shape
    return np.zeros((i + 1, j + 1, k + 1)).view(TableArray)


def table_index(name: str, table: TableArray, subscripts: list[float]) -> tuple[int, int, int]:
    """The storage index of `Par(i, j, k)` in an assignment (i, j may be 0; k from 1)."""
    lows = (0, 0, 1)
    out = []
    for axis, size in enumerate(table.shape):
        sub = subscripts[axis] if axis < len(subscripts) else 1.0
        i = int(round(sub))
        if abs(sub - i) > 1e-9 or not lows[axis] <= i <= size - 1:
            raise ApdlError(f"subscript {axis + 1} of table {name} is {sub:g}, outside "
                            f"{lows[axis]}..{size - 1}")
        out.append(i)
    return out[0], out[1], out[2]


def _bracket(index_values: np.ndarray, x: float) -> list[tuple[int, float]]:
    """(1-based position, weight) pairs interpolating at x between ascending index values;
    the end value outside them."""
    n = index_values.size
    if n == 1 or x <= index_values[0]:
        return [(1, 1.0)]
    if x >= index_values[-1]:
        return [(n, 1.0)]
    hi = int(np.searchsorted(index_values, x, side="right"))
    lo = hi - 1
    w = (x - index_values[lo]) / (index_values[hi] - index_values[lo])
    return [(lo + 1, 1.0 - w), (hi + 1, w)]


def table_value(name: str, table: TableArray, args: list[float]) -> float:
    """`Par(x[, y[, z]])`: the entries interpolated at the given index values."""
    x, y, z = (args + [0.0, 0.0, 0.0])[:3]
    rows = table[1:, 0, 1]
    cols = table[0, 1:, 1]
    planes = table[0, 0, 1:]
    for axis, values in (("row", rows), ("column", cols), ("plane", planes)):
        if values.size > 1 and np.any(np.diff(values) <= 0.0):
            raise ApdlError(f"table {name}: its {axis} index values must increase")
    total = 0.0
    for i, wi in _bracket(rows, x):
        for j, wj in _bracket(cols, y):
            for k, wk in _bracket(planes, z):
                total += wi * wj * wk * float(table[i, j, k])
    return total
