"""Radial-basis-function network: k-means centres, Gaussian bases, ridge output layer.

One of the stacking ensemble's base learners (REFERENCE.md §2).  Centres come from
scikit-learn's k-means on the standardised features (seeded); the width is the median
distance between centres; the output weights are a ridge fit on the basis values.
"""

from __future__ import annotations

import numpy as np

from twin.drift.scaling import fit_standard, standardize

N_CENTRES = 32
RIDGE_ALPHA = 1e-2


def rbf_basis(Z: np.ndarray, centres: np.ndarray, width: float) -> np.ndarray:
    d2 = (np.sum(Z**2, axis=1)[:, None] - 2.0 * Z @ centres.T
          + np.sum(centres**2, axis=1)[None, :])
    return np.exp(-np.maximum(d2, 0.0) / (2.0 * width**2))


def fit_rbf(X: np.ndarray, Y: np.ndarray, seed: int,
            n_centres: int = N_CENTRES) -> dict[str, np.ndarray]:
    from scipy.spatial.distance import pdist
    from sklearn.cluster import KMeans
    from sklearn.linear_model import Ridge

    offset, scale = fit_standard(X)
    Z = standardize(X, offset, scale)
    k = min(n_centres, Z.shape[0])
    centres = KMeans(n_clusters=k, n_init=1, random_state=seed).fit(Z).cluster_centers_
    width = float(np.median(pdist(centres))) if k > 1 else 1.0
    ridge = Ridge(alpha=RIDGE_ALPHA).fit(rbf_basis(Z, centres, width), Y)
    return {"x_offset": offset, "x_scale": scale, "centres": centres,
            "width": np.array([width]), "weight": np.atleast_2d(ridge.coef_),
            "bias": np.atleast_1d(ridge.intercept_)}


def predict_rbf(params: dict[str, np.ndarray], X: np.ndarray) -> np.ndarray:
    Z = standardize(X, params["x_offset"], params["x_scale"])
    Phi = rbf_basis(Z, params["centres"], float(params["width"][0]))
    return Phi @ params["weight"].T + params["bias"]
