"""`*DIM,Par,TABLE,I,J,K,Var1,Var2,Var3`: MAPDL's table parameter, looked up by value with
linear interpolation.

Storage is an array of shape (I+1, J+1, K+1) indexed exactly as APDL subscripts the table:
row 0 holds the column index values (`Par(0,j)`), column 0 the row index values
(`Par(i,0)`), `Par(0,0,k)` the index value of plane k, and `Par(i,j,k)` (i, j, k ≥ 1) the
entries.  `Par(x, y, z)` in an expression interpolates linearly between the index values
bracketing x, y and z (the index values of plane 1 serve every plane) and holds the end
value outside them, as MAPDL does.  A table of one column interpolates on x only.

Var1..Var3 name the primary variable of the rows, columns and planes (TIME, X, Y, ...):
what a load given as `%Par%` looks the table up by (`apdl_like.tabular_loads`).
"""

from __future__ import annotations

import numpy as np

from apdl_like.errors import ApdlError

NO_VARIABLES = ("", "", "")


class TableArray(np.ndarray):
    """A TABLE parameter (an ndarray subclass, so copies and SAVE keep what it is, and its
    primary variables: `variables`, upper case, "" where *DIM named none)."""

    variables: tuple[str, str, str]

    def __array_finalize__(self, obj: object) -> None:
        self.variables = getattr(obj, "variables", NO_VARIABLES)


def new_table(shape: tuple[int, int, int],
              variables: tuple[str, str, str] = NO_VARIABLES) -> TableArray:
    """Zeros, index values included (MAPDL fills them before the deck assigns them)."""
    i, j, k = shape
    table = np.zeros((i + 1, j + 1, k + 1)).view(TableArray)
    table.variables = variables
    return table


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


def _bracket(index_values: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                               np.ndarray]:
    """(lower, upper 1-based positions, weight of the upper) interpolating at each x between
    ascending index values; the end value outside them."""
    n = index_values.size
    if n == 1:
        one = np.ones(x.shape, np.intp)
        return one, one, np.zeros(x.shape)
    hi = np.clip(np.searchsorted(index_values, x, side="right"), 1, n - 1)
    lo = hi - 1
    w = np.clip((x - index_values[lo]) / (index_values[hi] - index_values[lo]), 0.0, 1.0)
    return lo + 1, hi + 1, w


def table_values(name: str, table: TableArray, x: np.ndarray, y: np.ndarray | float = 0.0,
                 z: np.ndarray | float = 0.0) -> np.ndarray:
    """The entries interpolated at the index values (x[n], y[n], z[n]), elementwise."""
    rows = table[1:, 0, 1]
    cols = table[0, 1:, 1]
    planes = table[0, 0, 1:]
    for axis, values in (("row", rows), ("column", cols), ("plane", planes)):
        if values.size > 1 and np.any(np.diff(values) <= 0.0):
            raise ApdlError(f"table {name}: its {axis} index values must increase")
    x, y, z = np.broadcast_arrays(*(np.asarray(v, float) for v in (x, y, z)))
    brackets = [_bracket(values, v) for values, v in ((rows, x), (cols, y), (planes, z))]
    total = np.zeros(x.shape)
    data = np.asarray(table)
    for i, wi in ((brackets[0][0], 1.0 - brackets[0][2]), (brackets[0][1], brackets[0][2])):
        for j, wj in ((brackets[1][0], 1.0 - brackets[1][2]), (brackets[1][1], brackets[1][2])):
            for k, wk in ((brackets[2][0], 1.0 - brackets[2][2]),
                          (brackets[2][1], brackets[2][2])):
                total += wi * wj * wk * data[i, j, k]
    return total


def table_value(name: str, table: TableArray, args: list[float]) -> float:
    """`Par(x[, y[, z]])`: the entries interpolated at the given index values."""
    x, y, z = (args + [0.0, 0.0, 0.0])[:3]
    return float(table_values(name, table, np.array(x), y, z))
