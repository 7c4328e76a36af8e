"""Time-blocked folds (never shuffled) and row thinning for network fits.

Validation leaves one block out: with several files each file is a block (a run); one
file is cut into `n_blocks` contiguous blocks of rows.  Training on the other blocks
includes later data, as in "train on three step tests, test on the fourth"; the features
of a test row still use only inputs up to that row.
"""

from __future__ import annotations

import numpy as np

N_BLOCKS = 4
NETWORK_MIN_INTERVAL_S = 60.0
"""Networks are fitted on rows at least this far apart (1-min resampling, as in
REFERENCE §2): 15-s rows are strongly autocorrelated, so thinning costs little information,
quarters the fit time and keeps the evidence framework from counting near-copies."""


def block_labels(n_rows: int, segment_ids: np.ndarray | None = None,
                 n_blocks: int = N_BLOCKS) -> np.ndarray:
    """Block of every row: its file when there are several, else one of `n_blocks`."""
    if segment_ids is not None and np.unique(segment_ids).size >= 2:
        # labels in order of first appearance, 0, 1, …
        _, first, labels = np.unique(segment_ids, return_index=True, return_inverse=True)
        labels = np.argsort(np.argsort(first))[labels]
        return labels.astype(np.int64)
    labels = np.empty(n_rows, dtype=np.int64)
    for b, rows in enumerate(np.array_split(np.arange(n_rows), min(n_blocks, n_rows))):
        labels[rows] = b
    return labels


def blocked_folds(n_rows: int, segment_ids: np.ndarray | None = None,
                  n_blocks: int = N_BLOCKS) -> list[tuple[np.ndarray, np.ndarray]]:
    """Leave-one-block-out (train, test) row indices."""
    labels = block_labels(n_rows, segment_ids, n_blocks)
    rows = np.arange(n_rows)
    return [(rows[labels != b], rows[labels == b]) for b in np.unique(labels)]


def thin_rows(time_s: np.ndarray, min_interval_s: float = NETWORK_MIN_INTERVAL_S) -> np.ndarray:
    """Indices of rows at least `min_interval_s` apart (a step back in time starts anew)."""
    keep = []
    last = -np.inf
    for i, t in enumerate(np.asarray(time_s, dtype=float)):
        if t - last >= min_interval_s or t < last:
            keep.append(i)
            last = t
    return np.asarray(keep, dtype=np.int64)
