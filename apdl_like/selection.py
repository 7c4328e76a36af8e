"""Selection logic on boolean masks (APDL NSEL/ESEL semantics)."""

from __future__ import annotations

import numpy as np

from apdl_like.errors import ApdlError

MODES = ("S", "R", "A", "U", "ALL", "NONE", "INVE")


def combine(mode: str, current: np.ndarray, picked: np.ndarray) -> np.ndarray:
    """New selection from the current one and the entities a criterion picked."""
    if mode == "S":
        return picked.copy()
    if mode == "R":
        return current & picked
    if mode == "A":
        return current | picked
    if mode == "U":
        return current & ~picked
    if mode == "ALL":
        return np.ones_like(current)
    if mode == "NONE":
        return np.zeros_like(current)
    if mode == "INVE":
        return ~current
    raise ApdlError(f"field 1: selection type must be one of {', '.join(MODES)}, got {mode!r}")


def range_tolerance(vmin: float, vmax: float) -> float:
    """APDL's LOC tolerance: 0.5 % of the range; 1e-8·|v| (or 1e-6 at zero) for one value."""
    if vmax != vmin:
        return 0.005 * abs(vmax - vmin)
    return 1e-8 * abs(vmin) if vmin != 0.0 else 1e-6


def in_range(values: np.ndarray, vmin: float, vmax: float) -> np.ndarray:
    lo, hi = min(vmin, vmax), max(vmin, vmax)
    tol = range_tolerance(vmin, vmax)
    return (values >= lo - tol) & (values <= hi + tol)


def number_range(ids: np.ndarray, vmin: float, vmax: float, vinc: float) -> np.ndarray:
    """Entities numbered vmin, vmin+vinc, ... ≤ vmax."""
    if vinc <= 0:
        raise ApdlError("increment must be positive")
    lo, hi = min(vmin, vmax), max(vmin, vmax)
    picked = (ids >= lo - 1e-9) & (ids <= hi + 1e-9)
    if vinc != 1:
        picked &= np.abs(np.mod(ids - lo, vinc)) < 1e-9
    return picked
