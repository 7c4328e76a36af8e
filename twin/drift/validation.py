"""Time-blocked validation of the methods, and the choice of the default one.

Each method is fitted on all blocks but one and predicts the left-out block (never
shuffled); the out-of-fold predictions give RMSE per target and block, and their
residuals calibrate the 90 % interval (`twin.drift.intervals`), each block's with the
other blocks only.  The default method is the one with the lowest out-of-fold RMSE,
averaged over the targets.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from twin.drift.folds import blocked_folds
from twin.drift.intervals import Z90, apply_interval, coverage_pct, interval_rule
from twin.drift.methods import METHODS, FitRows


@dataclass(frozen=True)
class MethodValidation:
    """Out-of-fold results of one method."""

    name: str
    predicted: np.ndarray          # (n, p) out-of-fold mean
    std: np.ndarray | None         # (n, p) out-of-fold predictive std (posterior methods)
    rmse_um: np.ndarray            # (n_blocks, p)
    interval: dict                 # the 90 % interval rule fitted on all residuals
    coverage_pct: list[float]      # per target, interval calibrated without the block
    posterior_coverage_pct: list[float] | None  # per target, uncalibrated posterior
    coverage_per_block_pct: np.ndarray  # (n_blocks, p): the pooled share hides a block
    # whose band misses most of it behind blocks covered whole
    outside_range_pct_per_block: list[float]  # rows beyond the others' operating range

    pooled_rmse_um: np.ndarray     # (p,) over every out-of-fold row
    lo: np.ndarray                 # (n, p) the interval calibrated without the row's block
    hi: np.ndarray

    @property
    def mean_rmse_um(self) -> float:
        """Mean over the targets of the out-of-fold RMSE (the figure methods are ranked by)."""
        return float(np.mean(self.pooled_rmse_um))

    def to_json(self, targets: Sequence[str]) -> dict:
        return {"rmse_um_per_block": {t: self.rmse_um[:, j].tolist()
                                      for j, t in enumerate(targets)},
                "rmse_um": {t: float(self.pooled_rmse_um[j]) for j, t in enumerate(targets)},
                "mean_rmse_um": self.mean_rmse_um,
                "coverage_90_pct": dict(zip(targets, self.coverage_pct, strict=True)),
                "coverage_90_pct_per_block": {t: self.coverage_per_block_pct[:, j].tolist()
                                              for j, t in enumerate(targets)},
                "outside_range_pct_per_block": self.outside_range_pct_per_block,
                "posterior_coverage_90_pct": None if self.posterior_coverage_pct is None
                else dict(zip(targets, self.posterior_coverage_pct, strict=True))}


def validate_method(
    name: str, X: np.ndarray, Y: np.ndarray, time_s: np.ndarray,
    blocks: np.ndarray, seed: int,
    progress: Callable[[str], None] | None = None,
    fold_X: Sequence[np.ndarray] | None = None,
    excess: np.ndarray | None = None,
) -> MethodValidation:
    """Leave-one-block-out predictions of one method (`blocks` from `block_labels`).

    `fold_X`, one feature matrix of every row per fold (in `blocked_folds` order), when
    the features depend on the fold: sensors chosen by their grade on that fold's
    training rows, so the left-out block's drift has no say in which sensors predict it.
    `excess`, per row, how far its operating point lies outside its fold's training rows'
    (`twin.drift.extrapolation.fold_excess`): its band widens with it.
    """
    method = METHODS[name]
    folds = blocked_folds(len(X), blocks)
    if fold_X is not None and len(fold_X) != len(folds):
        raise ValueError(f"{len(fold_X)} feature matrices for {len(folds)} folds")
    predicted = np.full(Y.shape, np.nan)
    std = None
    rmse = np.empty((len(folds), Y.shape[1]))
    for k, (train, test) in enumerate(folds):
        Xk = X if fold_X is None else fold_X[k]
        rows = FitRows(Xk[train], Y[train], time_s[train], blocks[train], seed)
        params = method.fit(rows)
        mean, sd = method.predict(params, Xk[test])
        predicted[test] = mean
        if sd is not None:
            std = np.full(Y.shape, np.nan) if std is None else std
            std[test] = sd
        rmse[k] = np.sqrt(np.mean((mean - Y[test]) ** 2, axis=0))
        if progress:
            progress(f"validation: {name}, block {k + 1}/{len(folds)}")
    labels = np.empty(len(X), dtype=np.int64)
    for k, (_, test) in enumerate(folds):
        labels[test] = k
    # coverage of every block with the interval calibrated on the other blocks only
    lo, hi = np.empty_like(predicted), np.empty_like(predicted)
    excess = np.zeros(len(X)) if excess is None else np.asarray(excess, dtype=float)
    for k in range(len(folds)):
        calibration, scored = labels != k, labels == k
        rule = interval_rule(predicted[calibration],
                             None if std is None else std[calibration], Y[calibration],
                             labels[calibration])
        sd = None if std is None else std[scored]
        lo[scored], hi[scored] = apply_interval(rule, predicted[scored], sd, excess[scored])
    coverage = [coverage_pct(Y[:, j], lo[:, j], hi[:, j]) for j in range(Y.shape[1])]
    per_block = np.array([[coverage_pct(Y[test, j], lo[test, j], hi[test, j])
                           for j in range(Y.shape[1])] for _, test in folds])
    posterior = None
    if std is not None:
        posterior = [coverage_pct(Y[:, j], predicted[:, j] - Z90 * std[:, j],
                                  predicted[:, j] + Z90 * std[:, j]) for j in range(Y.shape[1])]
    pooled = np.sqrt(np.mean((predicted - Y) ** 2, axis=0))
    outside = [100.0 * float(np.mean(excess[test] > 0)) for _, test in folds]
    return MethodValidation(name, predicted, std, rmse,
                            interval_rule(predicted, std, Y, labels),
                            coverage, posterior, per_block, outside, pooled, lo, hi)


def choose_default(results: Sequence[MethodValidation]) -> str:
    """The method with the lowest mean out-of-fold RMSE over the targets (first on a tie)."""
    return min(results, key=lambda r: r.mean_rmse_um).name
