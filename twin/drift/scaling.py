"""Standard scores of features and targets, fitted on training rows only."""

from __future__ import annotations

import numpy as np


def fit_standard(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(offset, scale) of every column; a constant column gets scale 1 (it stays constant)."""
    x = np.asarray(x, dtype=float)
    offset = x.mean(axis=0)
    scale = x.std(axis=0)
    scale = np.where(scale > 1e-12 * np.maximum(1.0, np.abs(offset)), scale, 1.0)
    return offset, scale


def standardize(x: np.ndarray, offset: np.ndarray, scale: np.ndarray) -> np.ndarray:
    return (np.asarray(x, dtype=float) - offset) / scale
