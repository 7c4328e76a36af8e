"""Bayesian-regularised network (MacKay's evidence framework; REFERENCE.md §4).

The network of `twin.drift.network` is trained on

    F(w) = Σ_j β_j·E_D,j + α·E_W,   E_D,j = ½Σ_i (f_j(x_i) − y_ij)²,   E_W = ½Σ w²

(targets in standard scores, one noise precision β_j per target).  After each
minimisation α and β are re-estimated from the Gauss–Newton Hessian
H = Σ_j β_j·J_jᵀJ_j + α·I at the minimum:

    γ_j = β_j·tr(J_jᵀJ_j·H⁻¹)      (well-determined parameters "used" by target j)
    α ← Σγ_j / (2·E_W),    β_j ← (N − γ_j) / (2·E_D,j)

which for one target is MacKay's γ = P − α·tr(H⁻¹).  The prediction carries the
posterior: σ_j²(x) = 1/β_j + g_jᵀH⁻¹g_j with g_j = ∂f_j/∂w (Laplace approximation,
linearised network), and the 90 % interval is f ± 1.645·σ.

Hidden neurons: z = √(u + v) + p (REFERENCE §4; u inputs, v outputs), p = `HIDDEN_EXTRA`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.linalg import solve_triangular

from twin.drift.network import (
    flat_weights,
    forward_scaled,
    initial_weights,
    minimise_weights,
    output_jacobian,
    scaled_problem,
)
from twin.drift.scaling import standardize

HIDDEN_EXTRA = 2
REESTIMATES = 6
MAX_ITER = 150
"""L-BFGS iterations of the first minimisation; later ones start from the previous
minimum (α, β move little after the first updates) and take `REFIT_ITER`."""
REFIT_ITER = 40


def hidden_size(n_inputs: int, n_outputs: int) -> int:
    """z = √(u + v) + p of REFERENCE §4."""
    return int(round(np.sqrt(n_inputs + n_outputs))) + HIDDEN_EXTRA


def evidence_update(
    gauss_newton: Sequence[np.ndarray], E_D: np.ndarray, E_W: float, n: int,
    alpha: float, beta: np.ndarray,
) -> tuple[float, np.ndarray, np.ndarray]:
    """One MacKay re-estimation: (α, β_j, γ_j) from the blocks G_j = J_jᵀJ_j at the minimum.

    `n` is the number of data rows (each target has one value per row).
    """
    beta = np.asarray(beta, dtype=float)
    H = alpha * np.eye(gauss_newton[0].shape[0])
    for b, G in zip(beta, gauss_newton, strict=True):
        H += b * G
    H_inv = np.linalg.inv(H)
    gamma = np.array([b * np.sum(G * H_inv) for b, G in zip(beta, gauss_newton, strict=True)])
    # floors keep a perfect fit (E → 0) or tiny data from sending α or β to infinity
    alpha_new = float(gamma.sum() / (2.0 * max(E_W, 1e-12)))
    beta_new = np.maximum(n - gamma, 1e-3) / (2.0 * np.maximum(np.asarray(E_D, float), 1e-12))
    return alpha_new, beta_new, gamma


def _gauss_newton_blocks(params: dict[str, np.ndarray], Z: np.ndarray) -> list[np.ndarray]:
    """J_jᵀJ_j per output; only the hidden layer and output j's own weights are non-zero."""
    p = params["output_weight"].shape[0]
    blocks = []
    size = flat_weights(params).size
    for j in range(p):
        J, used = output_jacobian(params, Z, j, compact=True)
        G = np.zeros((size, size))
        G[np.ix_(used, used)] = J.T @ J
        blocks.append(G)
    return blocks


def fit_bayesian(X: np.ndarray, Y: np.ndarray, seed: int, hidden: int | None = None,
                 reestimates: int = REESTIMATES) -> dict[str, np.ndarray]:
    """Train under the evidence framework; returns the weights, α, β and the posterior."""
    import torch

    scaling, Z, Ys = scaled_problem(X, Y)
    n, m = Z.shape
    p = Ys.shape[1]
    h = hidden or hidden_size(m, p)
    weights = initial_weights(m, h, p, seed)
    alpha, beta = 0.01, np.ones(p)
    for k in range(reestimates):
        beta_t = torch.from_numpy(beta.copy())
        a = alpha

        def loss_of(residual: torch.Tensor, w: Sequence[torch.Tensor],
                    beta_t: torch.Tensor = beta_t, a: float = a) -> torch.Tensor:
            # F/n: the same minimum, better conditioned for L-BFGS
            data = 0.5 * ((residual**2).sum(dim=0) * beta_t).sum()
            prior = 0.5 * a * sum((t**2).sum() for t in w)
            return (data + prior) / n

        weights = minimise_weights(Z, Ys, weights, loss_of, MAX_ITER if k == 0 else REFIT_ITER,
                                   seed)
        params = {**scaling, **weights}
        residual = forward_residual(params, Z, Ys)
        E_D = 0.5 * np.sum(residual**2, axis=0)
        E_W = 0.5 * float(np.sum(flat_weights(weights) ** 2))
        alpha, beta, gamma = evidence_update(_gauss_newton_blocks(params, Z), E_D, E_W, n,
                                             alpha, beta)
    params = {**scaling, **weights}
    blocks = _gauss_newton_blocks(params, Z)
    H = alpha * np.eye(blocks[0].shape[0]) + sum(b * G for b, G in zip(beta, blocks,
                                                                        strict=True))
    L = np.linalg.cholesky(H)
    return {**params, "alpha": np.array([alpha]), "beta": beta, "gamma": gamma,
            "posterior_factor": solve_triangular(L, np.eye(L.shape[0]), lower=True)}


def forward_residual(params: dict[str, np.ndarray], Z: np.ndarray, Ys: np.ndarray) -> np.ndarray:
    return forward_scaled(params, Z) - Ys


def predict_bayesian(params: dict[str, np.ndarray], X: np.ndarray,
                     chunk: int = 4096) -> tuple[np.ndarray, np.ndarray]:
    """Mean (n, p) and predictive standard deviation (n, p) in the targets' units."""
    Z = standardize(X, params["x_offset"], params["x_scale"])
    mean = forward_scaled(params, Z)
    p = mean.shape[1]
    var = np.empty_like(mean)
    # L⁻¹ with H = L·Lᵀ: gᵀH⁻¹g = |L⁻¹g|².  The product costs n·P² and dominates
    # prediction; single precision halves it and keeps σ to ~5 significant digits.
    Rt = params["posterior_factor"].T.astype(np.float32)
    for start in range(0, Z.shape[0], chunk):
        rows = slice(start, start + chunk)
        for j in range(p):
            J, used = output_jacobian(params, Z[rows], j, compact=True)
            G = J.astype(np.float32) @ Rt[used]
            var[rows, j] = (np.einsum("ij,ij->i", G, G, dtype=np.float64)
                            + 1.0 / params["beta"][j])
    scale = params["y_scale"]
    return mean * scale + params["y_offset"], np.sqrt(var) * scale
