"""Linear drift models: least squares (the baseline) and ridge with a blocked-CV penalty.

Parameters are plain arrays (`weight` (p, m), `bias` (p,)) applied to standardised
features; `predict_linear` is shared by both.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from twin.drift.scaling import fit_standard, standardize

RIDGE_ALPHAS: tuple[float, ...] = (1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0)
"""Ridge penalties tried (on standardised features; n ≈ 10⁴ rows)."""


def fit_least_squares(X: np.ndarray, Y: np.ndarray) -> dict[str, np.ndarray]:
    """Ordinary least squares of every target column on the features (with intercept)."""
    offset, scale = fit_standard(X)
    Z = standardize(X, offset, scale)
    A = np.hstack([Z, np.ones((Z.shape[0], 1))])
    coef, *_ = np.linalg.lstsq(A, Y, rcond=None)
    return {"x_offset": offset, "x_scale": scale, "weight": coef[:-1].T.copy(),
            "bias": coef[-1].copy()}


def _ridge_solve(Z: np.ndarray, Y: np.ndarray, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    from sklearn.linear_model import Ridge

    model = Ridge(alpha=alpha).fit(Z, Y)
    return np.atleast_2d(model.coef_), np.atleast_1d(model.intercept_)


def fit_ridge(X: np.ndarray, Y: np.ndarray, folds: Sequence[tuple[np.ndarray, np.ndarray]],
              alphas: Sequence[float] = RIDGE_ALPHAS) -> dict[str, np.ndarray]:
    """Ridge regression, the penalty chosen per target by the given (blocked) folds."""
    offset, scale = fit_standard(X)
    Z = standardize(X, offset, scale)
    p = Y.shape[1]
    if folds:
        errors = np.zeros((len(alphas), p))
        for train, test in folds:
            for a, alpha in enumerate(alphas):
                w, b = _ridge_solve(Z[train], Y[train], alpha)
                errors[a] += np.mean((Z[test] @ w.T + b - Y[test]) ** 2, axis=0)
        best = np.asarray(alphas)[np.argmin(errors, axis=0)]
    else:
        best = np.full(p, float(np.median(alphas)))
    weight = np.empty((p, Z.shape[1]))
    bias = np.empty(p)
    for j in range(p):
        w, b = _ridge_solve(Z, Y[:, j], float(best[j]))
        weight[j], bias[j] = w[0], b[0]
    return {"x_offset": offset, "x_scale": scale, "weight": weight, "bias": bias,
            "alpha": best}


def predict_linear(params: dict[str, np.ndarray], X: np.ndarray) -> np.ndarray:
    Z = standardize(X, params["x_offset"], params["x_scale"])
    return Z @ params["weight"].T + params["bias"]
