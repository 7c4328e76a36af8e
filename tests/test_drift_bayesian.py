"""Evidence framework against the closed-form linear case; network Jacobian; intervals."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from twin.drift.bayesian import evidence_update
from twin.drift.intervals import conformal_half_width
from twin.drift.network import (
    WEIGHT_NAMES,
    flat_weights,
    forward_scaled,
    initial_weights,
    output_jacobian,
)


def _posterior(X, y, alpha, beta):
    A = alpha * np.eye(X.shape[1]) + beta * X.T @ X
    m = beta * np.linalg.solve(A, X.T @ y)
    return A, m


def _log_evidence(log_ab, X, y):
    """ln p(y | α, β) of Bayesian linear regression (Bishop, PRML eq. 3.86)."""
    alpha, beta = np.exp(log_ab)
    n, p = X.shape
    A, m = _posterior(X, y, alpha, beta)
    E = 0.5 * beta * np.sum((y - X @ m) ** 2) + 0.5 * alpha * m @ m
    return (0.5 * p * np.log(alpha) + 0.5 * n * np.log(beta) - E
            - 0.5 * np.linalg.slogdet(A)[1] - 0.5 * n * np.log(2 * np.pi))


def test_evidence_updates_reach_the_closed_form_evidence_maximum():
    rng = np.random.default_rng(7)
    n, p = 120, 6
    X = rng.normal(size=(n, p))
    y = X @ rng.normal(0, 1.5, p) + rng.normal(0, 0.4, n)
    alpha, beta = 1.0, np.array([1.0])
    for _ in range(200):
        _, m = _posterior(X, y, alpha, beta[0])
        E_D = np.array([0.5 * np.sum((y - X @ m) ** 2)])
        alpha, beta, gamma = evidence_update([X.T @ X], E_D, 0.5 * m @ m, n, alpha, beta)
    best = minimize(lambda v: -_log_evidence(v, X, y), x0=[0.0, 0.0], method="Nelder-Mead",
                    options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 4000})
    alpha_ref, beta_ref = np.exp(best.x)
    assert alpha == pytest.approx(alpha_ref, rel=1e-4)
    assert beta[0] == pytest.approx(beta_ref, rel=1e-4)
    assert 0 < gamma[0] < p
    assert beta[0] == pytest.approx(1 / 0.4**2, rel=0.3)      # the noise it was made with


def test_network_jacobian_matches_finite_differences():
    rng = np.random.default_rng(1)
    Z = rng.normal(size=(9, 4))
    params = initial_weights(4, 3, 2, seed=0)
    params["skip_weight"] = rng.normal(size=(2, 4))
    params["output_bias"] = rng.normal(size=2)
    w = flat_weights(params)

    def f(v):
        out, i = {}, 0
        for k in WEIGHT_NAMES:
            out[k] = v[i : i + params[k].size].reshape(params[k].shape)
            i += params[k].size
        return forward_scaled(out, Z)

    for j in range(2):
        numeric = np.array([(f(w + 1e-6 * e)[:, j] - f(w - 1e-6 * e)[:, j]) / 2e-6
                            for e in np.eye(w.size)]).T
        np.testing.assert_allclose(output_jacobian(params, Z, j), numeric, atol=1e-8)


def test_conformal_half_width_is_the_finite_sample_quantile():
    residuals = np.arange(1.0, 20.0)[:, None] * np.array([1.0, -2.0])   # 19 rows
    # ⌈(19 + 1)·0.9⌉ = 18th smallest |r|
    np.testing.assert_array_equal(conformal_half_width(residuals), [18.0, 36.0])
