"""One-hidden-layer tanh networks with a linear skip: numpy evaluation, Jacobian, training.

    f(z) = V·tanh(W·z + b) + S·z + c        (z: standardised inputs, f: standardised drift)

The skip term S·z lets the network extrapolate like a linear model where the tanh units
saturate — operating points outside the training range (another speed) are the rule for
a drift model, and a pure tanh network flattens out there.

Parameters are plain float64 arrays (so a model file holds tensors only):
`x_offset`, `x_scale`, `y_offset`, `y_scale` (standard scores of inputs and targets),
`hidden_weight` W (h, m), `hidden_bias` b (h,), `output_weight` V (p, h), `output_bias`
c (p,), `skip_weight` S (p, m).
The BP network of REFERENCE §3 is trained here by full-batch L-BFGS on the mean squared
error plus a small weight decay; `twin.drift.bayesian` trains the same network under
MacKay's evidence framework.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from twin.drift.scaling import fit_standard, standardize

if TYPE_CHECKING:
    import torch

BP_HIDDEN = 12
BP_WEIGHT_DECAY = 1e-3
"""Weight decay of the BP network: λ·Σw²/2 added to the mean squared error (scaled units)."""
BP_MAX_ITER = 300

WEIGHT_NAMES = ("hidden_weight", "hidden_bias", "output_weight", "output_bias", "skip_weight")


def hidden_activations(params: dict[str, np.ndarray], Z: np.ndarray) -> np.ndarray:
    return np.tanh(Z @ params["hidden_weight"].T + params["hidden_bias"])


def forward_scaled(params: dict[str, np.ndarray], Z: np.ndarray) -> np.ndarray:
    """Network output in standard-score units for standardised inputs Z (n, m)."""
    return (hidden_activations(params, Z) @ params["output_weight"].T + params["output_bias"]
            + Z @ params["skip_weight"].T)


def predict_network(params: dict[str, np.ndarray], X: np.ndarray) -> np.ndarray:
    """Drift (n, p) in the targets' units for raw features X (n, m)."""
    Z = standardize(X, params["x_offset"], params["x_scale"])
    return forward_scaled(params, Z) * params["y_scale"] + params["y_offset"]


def flat_weights(params: dict[str, np.ndarray]) -> np.ndarray:
    return np.concatenate([params[k].ravel() for k in WEIGHT_NAMES])


def output_jacobian(params: dict[str, np.ndarray], Z: np.ndarray, output: int,
                    compact: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """∂f_output/∂w (n, P) in scaled units; w ordered as `flat_weights`.

    `compact` returns (J restricted to the weights output j depends on — the hidden layer
    and its own output and skip weights —, their indices in w): the other columns are 0.
    """
    a = hidden_activations(params, Z)
    v = params["output_weight"][output]
    n, h = a.shape
    m = Z.shape[1]
    p = params["output_weight"].shape[0]
    dz = (1.0 - a**2) * v                         # ∂f/∂(pre-activation), (n, h)
    own_v = h * m + h + output * h
    own_c = h * m + h + p * h + output
    own_s = h * m + h + p * h + p + output * m
    cols = np.concatenate([np.arange(h * m + h), np.arange(own_v, own_v + h), [own_c],
                           np.arange(own_s, own_s + m)])
    J = np.empty((n, cols.size))
    J[:, : h * m] = (dz[:, :, None] * Z[:, None, :]).reshape(n, h * m)
    J[:, h * m : h * m + h] = dz
    J[:, h * m + h : h * m + 2 * h] = a
    J[:, h * m + 2 * h] = 1.0
    J[:, h * m + 2 * h + 1 :] = Z
    if compact:
        return J, cols
    full = np.zeros((n, h * m + h + p * h + p + p * m))
    full[:, cols] = J
    return full


def initial_weights(m: int, h: int, p: int, seed: int) -> dict[str, np.ndarray]:
    """Seeded start: Glorot-uniform hidden layer, a small output layer (m inputs, p outputs)."""
    rng = np.random.default_rng(seed)
    limit = np.sqrt(6.0 / (m + h))
    return {"hidden_weight": rng.uniform(-limit, limit, (h, m)), "hidden_bias": np.zeros(h),
            "output_weight": rng.uniform(-0.1, 0.1, (p, h)), "output_bias": np.zeros(p),
            "skip_weight": np.zeros((p, m))}


def minimise_weights(
    Z: np.ndarray, Ys: np.ndarray, start: dict[str, np.ndarray],
    loss_of: Callable, max_iter: int, seed: int,
) -> dict[str, np.ndarray]:
    """Minimise `loss_of(residuals (n, p), weights list)` over the weights with L-BFGS."""
    import torch

    from twin.correction.network import deterministic_torch

    with deterministic_torch(seed):
        z = torch.from_numpy(np.ascontiguousarray(Z))
        y = torch.from_numpy(np.ascontiguousarray(Ys))
        w = [torch.tensor(start[k], dtype=torch.float64, requires_grad=True)
             for k in WEIGHT_NAMES]
        optimizer = torch.optim.LBFGS(w, lr=1.0, max_iter=max_iter, history_size=20,
                                      tolerance_grad=1e-9, tolerance_change=1e-12,
                                      line_search_fn="strong_wolfe")

        def closure() -> torch.Tensor:
            optimizer.zero_grad()
            out = torch.tanh(z @ w[0].T + w[1]) @ w[2].T + w[3] + z @ w[4].T
            loss = loss_of(out - y, w)
            loss.backward()
            return loss

        optimizer.step(closure)
        return {k: t.detach().numpy().copy() for k, t in zip(WEIGHT_NAMES, w, strict=True)}


def scaled_problem(X: np.ndarray, Y: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray,
                                                          np.ndarray]:
    """(scaling params, Z, Ys): standard scores of the training rows."""
    x_offset, x_scale = fit_standard(X)
    y_offset, y_scale = fit_standard(Y)
    scaling = {"x_offset": x_offset, "x_scale": x_scale, "y_offset": y_offset,
               "y_scale": y_scale}
    return scaling, standardize(X, x_offset, x_scale), standardize(Y, y_offset, y_scale)


def fit_bp(X: np.ndarray, Y: np.ndarray, seed: int, hidden: int = BP_HIDDEN,
           weight_decay: float = BP_WEIGHT_DECAY,
           max_iter: int = BP_MAX_ITER) -> dict[str, np.ndarray]:
    """BP network: MSE + weight decay, full-batch L-BFGS from a seeded start."""
    scaling, Z, Ys = scaled_problem(X, Y)
    start = initial_weights(Z.shape[1], hidden, Ys.shape[1], seed)

    def loss_of(residual: torch.Tensor, w: Sequence[torch.Tensor]) -> torch.Tensor:
        return (residual**2).mean() + 0.5 * weight_decay * sum((t**2).sum() for t in w)

    return {**scaling, **minimise_weights(Z, Ys, start, loss_of, max_iter, seed)}

