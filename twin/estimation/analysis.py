"""The measurement update: an ensemble transform Kalman filter (ETKF) step.

Hunt, Kostelich & Szunyogh (2007), "Efficient data assimilation for spatiotemporal chaos:
a local ensemble transform Kalman filter", Physica D 230, eqs. (20)–(25); Evensen (2009).
With prior anomalies X (d, N), predicted-observation anomalies Y (m, N), innovation
y − ȳ and diagonal observation error R:

    P̃ = [(N − 1) I / ρ + Yᵀ R⁻¹ Y]⁻¹            (N × N, ρ multiplicative inflation)
    w̄ = P̃ Yᵀ R⁻¹ (y − ȳ),      x̄ₐ = x̄ + X w̄
    Xₐ = X [(N − 1) P̃]^½                       (symmetric square root: stays centred)

For a linear-Gaussian model whose ensemble spans the prior covariance P = X Xᵀ/(N − 1)
exactly this is the Kalman update (mean and covariance); tests check it against the
closed form.  It is deterministic (no perturbed observations), so a replay is reproducible.

Y may be a time series over the past window (4-D): the anomalies of the state at the
window end and of the observations inside it come from the same members, so their
cross-covariance carries the update to the window end.
"""

from __future__ import annotations

import numpy as np


def etkf_update(
    mean: np.ndarray,
    anomalies: np.ndarray,
    obs_mean: np.ndarray,
    obs_anomalies: np.ndarray,
    observed: np.ndarray,
    obs_sd: np.ndarray,
    inflation: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Analysis (mean (d,), anomalies (d, N)); see the module doc.

    obs_mean (m,), obs_anomalies (m, N), observed (m,), obs_sd (m,) > 0.  Observations that
    are not finite are left out; with none left the prior comes back unchanged (inflated).
    """
    X = np.asarray(anomalies, float)
    N = X.shape[1]
    ok = np.isfinite(observed) & np.isfinite(obs_mean) & np.isfinite(obs_sd)
    if not (inflation >= 1.0):
        raise ValueError(f"inflation must be ≥ 1, got {inflation}")
    if not ok.any():
        return np.asarray(mean, float).copy(), X * np.sqrt(inflation)
    Y = np.asarray(obs_anomalies, float)[ok]
    r_inv = 1.0 / np.asarray(obs_sd, float)[ok] ** 2
    C = Y.T * r_inv  # (N, m) = Yᵀ R⁻¹
    P_inv = (N - 1) / inflation * np.eye(N) + C @ Y
    vals, vecs = np.linalg.eigh(0.5 * (P_inv + P_inv.T))
    P = (vecs / vals) @ vecs.T
    w = P @ (C @ (np.asarray(observed, float)[ok] - np.asarray(obs_mean, float)[ok]))
    W = (vecs * np.sqrt((N - 1) / vals)) @ vecs.T
    return np.asarray(mean, float) + X @ w, X @ W
