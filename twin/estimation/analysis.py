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


def etkf_weights(
    obs_mean: np.ndarray,
    obs_anomalies: np.ndarray,
    observed: np.ndarray,
    obs_sd: np.ndarray,
    inflation: float = 1.0,
    prior_weights: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The analysis in ensemble space: weights w̄ (N,) and the symmetric transform W (N, N),
    so that x̄ₐ = x̄ + X w̄ and Xₐ = X W (module doc).

    obs_mean (m,) ȳ, obs_anomalies (m, N) Y, observed (m,) y, obs_sd (m,) > 0, all of the
    ensemble forecast from the prior mean moved by `prior_weights` w₀ (default 0: the plain
    ETKF).  With w₀ this is one Gauss–Newton step on the cost in ensemble space

        J(w) = (N − 1)/(2ρ) |w|² + ½ |y − ȳ(w)|²_R⁻¹
        w̄ = P̃ Yᵀ R⁻¹ (y − ȳ(w₀) + Y w₀)

    (Sakov, Oliver & Bertino 2012, "An iterative EnKF for strongly nonlinear systems",
    Mon. Wea. Rev. 140; the `estimator` iterates its first analysis this way).  The
    weights stay relative to the prior mean, not to w₀.  Observations that are not finite
    are left out; with none left w̄ = 0 and W = √ρ I (the prior, inflated).
    """
    if not (inflation >= 1.0):
        raise ValueError(f"inflation must be ≥ 1, got {inflation}")
    Y = np.asarray(obs_anomalies, float)
    N = Y.shape[1]
    ok = np.isfinite(observed) & np.isfinite(obs_mean) & np.isfinite(obs_sd)
    if not ok.any():
        return np.zeros(N), np.sqrt(inflation) * np.eye(N)
    Y = Y[ok]
    r_inv = 1.0 / np.asarray(obs_sd, float)[ok] ** 2
    C = Y.T * r_inv  # (N, m) = Yᵀ R⁻¹
    P_inv = (N - 1) / inflation * np.eye(N) + C @ Y
    vals, vecs = np.linalg.eigh(0.5 * (P_inv + P_inv.T))
    P = (vecs / vals) @ vecs.T
    innovation = np.asarray(observed, float)[ok] - np.asarray(obs_mean, float)[ok]
    if prior_weights is not None:
        innovation = innovation + Y @ np.asarray(prior_weights, float)
    w = P @ (C @ innovation)
    W = (vecs * np.sqrt((N - 1) / vals)) @ vecs.T
    return w, W


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
    w, W = etkf_weights(obs_mean, obs_anomalies, observed, obs_sd, inflation)
    return np.asarray(mean, float) + X @ w, X @ W
