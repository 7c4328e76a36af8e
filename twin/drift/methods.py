"""The drift-model methods: name → feature groups, fit and predict (a small registry).

Every fit takes the feature matrix X (n, m), the targets Y (n, p), the rows' times, time
blocks and a seed, and returns a dict of float64 arrays (what the model file stores).  Every
predict returns the mean (n, p) and, for a method with its own uncertainty, the
predictive standard deviation (n, p), else None (the model then uses conformal widths).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from twin.drift.bayesian import fit_bayesian, predict_bayesian
from twin.drift.folds import blocked_folds, thin_rows
from twin.drift.linear import fit_least_squares, fit_ridge, predict_linear
from twin.drift.network import fit_bp, predict_network
from twin.drift.stacking import fit_stacking, predict_stacking
from twin.errors import InputError

Params = dict[str, np.ndarray]
Progress = Callable[[str], None] | None


@dataclass(frozen=True)
class FitRows:
    """The training rows a method sees: features, targets, times, blocks, seed.

    `blocks` labels the time blocks of the rows (files, or parts of one file); methods
    that tune themselves (ridge penalty, stacking) leave one block out at a time.
    """

    X: np.ndarray
    Y: np.ndarray
    time_s: np.ndarray
    blocks: np.ndarray
    seed: int
    progress: Progress = None


@dataclass(frozen=True)
class Method:
    name: str
    description: str
    groups: tuple[str, ...]
    fit: Callable[[FitRows], Params]
    predict: Callable[[Params, np.ndarray], tuple[np.ndarray, np.ndarray | None]]


def _thinned(rows: FitRows) -> tuple[np.ndarray, np.ndarray]:
    keep = thin_rows(rows.time_s)
    return rows.X[keep], rows.Y[keep]


def _deterministic(predict: Callable[[Params, np.ndarray], np.ndarray],
                   ) -> Callable[[Params, np.ndarray], tuple[np.ndarray, None]]:
    def wrapped(params: Params, X: np.ndarray) -> tuple[np.ndarray, None]:
        return predict(params, X), None

    return wrapped


DYNAMIC = ("rise", "lag", "speed")

METHODS: dict[str, Method] = {m.name: m for m in (
    Method("mlr", "multiple linear regression on the temperature rises (baseline)", ("rise",),
           lambda r: fit_least_squares(r.X, r.Y), _deterministic(predict_linear)),
    Method("ridge_lagged", "ridge on the rises and their 10/30/90-min lags (published "
           "baseline)", ("rise", "lag"),
           lambda r: fit_ridge(r.X, r.Y, blocked_folds(len(r.X), r.blocks)),
           _deterministic(predict_linear)),
    Method("ridge_dynamic", "ridge on the rises, their lags and the speed history", DYNAMIC,
           lambda r: fit_ridge(r.X, r.Y, blocked_folds(len(r.X), r.blocks)),
           _deterministic(predict_linear)),
    Method("bp", "BP network (tanh, L-BFGS, weight decay) on the dynamic features", DYNAMIC,
           lambda r: fit_bp(*_thinned(r), r.seed), _deterministic(predict_network)),
    Method("bayes", "Bayesian-regularised network (MacKay evidence), posterior interval",
           DYNAMIC, lambda r: fit_bayesian(*_thinned(r), r.seed), predict_bayesian),
    Method("stack", "stacking of ridge, BP and RBF networks, linear meta-learner", DYNAMIC,
           lambda r: fit_stacking(r.X, r.Y, r.time_s, r.seed, r.blocks, r.progress),
           _deterministic(predict_stacking)),
)}


def method_named(name: str) -> Method:
    if name not in METHODS:
        raise InputError(f"unknown method {name!r}; choose one of {', '.join(METHODS)}",
                         column="--method")
    return METHODS[name]
